/* plume: result curves and moduli in HDF5 (docs/design.md "Data and files"), written atomically.
 *
 * Every public function here silences HDF5's automatic error-stack printing for its own duration
 * (and restores the caller's handler), so failures surface only as a plume_status and a message
 * naming the file and the missing object. The handler is process-global HDF5 state: two threads
 * calling into HDF5 at once would race on it, as they would on the (non thread-safe) serial HDF5
 * library itself. */
#include "curves.h"

#include <hdf5.h>

#include "h5_atomic.h"
#include "h5util.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* Names of the five datasets of a curve group, in plume_curve field order. */
static const char *const curve_fields[5] = {"strain", "stress", "wbar", "iterations", "seconds"};
static const char *const curve_units[5] = {"1", "Pa", "1", "1", "s"}; /* the datasets' "units" */

static double **curve_field(plume_curve *c, int i)
{
    switch (i) {
    case 0: return &c->strain;
    case 1: return &c->stress;
    case 2: return &c->wbar;
    case 3: return &c->iterations;
    default: return &c->seconds;
    }
}

static const double *curve_cfield(const plume_curve *c, int i)
{
    return *curve_field((plume_curve *)c, i); /* read-only use of the same switch */
}


/* -------------------------------------------------------------------------- helpers --- */

/* A group or attribute name component: non-empty, no '/', not "." (which HDF5 reads as "here"). */
static int bad_component(const char *s)
{
    return !s || !*s || strchr(s, '/') || strcmp(s, ".") == 0;
}

/* Sets `err` and returns 1 unless scale and scenario are usable group names. */
static int bad_names(const char *path, const char *scale, const char *scenario, plume_err *err)
{
    if (bad_component(scale) || bad_component(scenario)) {
        plume_err_set(err, PLUME_EINVAL,
                      "curves file '%s': scale '%s' and scenario '%s' must be non-empty names without '/'",
                      path, scale ? scale : "(null)", scenario ? scenario : "(null)");
        return 1;
    }
    if (strlen(scale) + strlen(scenario) > 512) {
        plume_err_set(err, PLUME_EINVAL, "curves file '%s': scale/scenario names too long", path);
        return 1;
    }
    return 0;
}


/* 1 if every prefix of the absolute `objpath` exists as a link in `fid`, 0 if one is missing,
 * -1 on error. Checking prefixes one by one keeps H5Lexists well defined on every HDF5 version. */
static int path_exists(hid_t fid, const char *objpath)
{
    char buf[1024];
    size_t len = strlen(objpath);
    if (len >= sizeof buf)
        return -1;
    memcpy(buf, objpath, len + 1);
    for (size_t i = 1; i <= len; i++) {
        if (buf[i] != '/' && buf[i] != '\0')
            continue;
        char save = buf[i];
        buf[i] = '\0';
        htri_t e = H5Lexists(fid, buf, H5P_DEFAULT);
        buf[i] = save;
        if (e < 0)
            return -1;
        if (e == 0)
            return 0;
    }
    return 1;
}

/* Opens an existing HDF5 file read-only with messages for the missing / non-HDF5 cases. */
static plume_status open_for_read(const char *path, const char *what, hid_t *fid, plume_err *err)
{
    struct stat st;
    *fid = H5I_INVALID_HID;
    if (stat(path, &st) != 0)
        return plume_err_set(err, PLUME_EIO, "%s '%s': cannot open: %s", what, path, strerror(errno));
    if (!S_ISREG(st.st_mode))
        return plume_err_set(err, PLUME_EIO, "%s '%s': not a regular file", what, path);
    if (!h5_is_hdf5(path))
        return plume_err_set(err, PLUME_EFORMAT, "%s '%s': is not an HDF5 file", what, path);
    *fid = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (*fid < 0) {
        h5_detail d;
        return plume_err_set(err, PLUME_EIO, "%s '%s': cannot open (HDF5: %s)", what, path,
                             h5_cause(&d));
    }
    return PLUME_OK;
}





/* ------------------------------------------------------------------------- curves ---- */

typedef struct {
    const char *gpath;             /* the curve's group, /curves/... */
    int nf;                        /* datasets, each of n points */
    const char *const *names, *const *units;
    const double *const *data;
    plume_index n;
    const plume_param *params;
    int nparams;
    const plume_sparam *sparams;
    int nsparams;
} curve_ctx;

/* The unit of a curve parameter the apps write (a pure number, count or flag: "1"). */
static const char *param_units(const char *name)
{
    static const char *const pa[] = {"E_b", "E_xx", "E_yy", "G_xy", "E", "kappa", "initial_slope", NULL};
    static const char *const m[] = {"d_B", "lx", "ly", "thickness", "h", "edge", "thickness_barb", "thickness_barbule",
                                    "element_edge", "refinement_edge", NULL};
    static const char *const nm[] = {"D", "D_long", "D_trans", "D_coupling", "D_twist", "D_16", "D_26", NULL};
    for (int k = 0; pa[k]; k++)
        if (strcmp(name, pa[k]) == 0)
            return "Pa";
    for (int k = 0; m[k]; k++)
        if (strcmp(name, m[k]) == 0)
            return "m";
    if (strcmp(name, "angle_deg") == 0)
        return "deg";
    /* the plane-stress tensors, C11 .. C33 and separation_C11 .. separation_C33 */
    const char *cn = strncmp(name, "separation_", 11) == 0 ? name + 11 : name;
    if (cn[0] == 'C' && cn[1] >= '1' && cn[1] <= '3' && cn[2] >= '1' && cn[2] <= '3' && cn[3] == '\0')
        return "Pa";
    if (strcmp(name, "separation_strength") == 0)
        return "N/m";
    if (strcmp(name, "separation_energy") == 0)
        return "J/m^2";
    if (strcmp(name, "separation_stiffness") == 0)
        return "N/m^2";
    if (strcmp(name, "separation_opening") == 0 || strcmp(name, "separation_capture") == 0)
        return "m";
    if (strcmp(name, "seconds_total") == 0)
        return "s";
    for (int k = 0; nm[k]; k++)
        if (strcmp(name, nm[k]) == 0)
            return "N m";
    return "1";
}

static plume_status fill_curve(hid_t fid, const char *path, const void *vctx, plume_err *err)
{
    const curve_ctx *c = vctx;
    plume_status s = PLUME_OK;
    hid_t lcpl = H5I_INVALID_HID, g = H5I_INVALID_HID;
    h5_detail d;
    const char *gpath = c->gpath;

    int e = path_exists(fid, gpath);
    if (e < 0 || (e == 1 && H5Ldelete(fid, gpath, H5P_DEFAULT) < 0)) {
        s = plume_err_set(err, PLUME_EIO, "curves file '%s': cannot replace %s (HDF5: %s)", path,
                          gpath, h5_cause(&d));
        goto cleanup;
    }
    lcpl = H5Pcreate(H5P_LINK_CREATE);
    if (lcpl < 0 || H5Pset_create_intermediate_group(lcpl, 1) < 0 ||
        (g = H5Gcreate2(fid, gpath, lcpl, H5P_DEFAULT, H5P_DEFAULT)) < 0) {
        s = plume_err_set(err, PLUME_EIO, "curves file '%s': cannot create group %s (HDF5: %s)",
                          path, gpath, h5_cause(&d));
        goto cleanup;
    }
    for (int i = 0; i < c->nf; i++) {
        if (h5_write_dataset(g, c->names[i], c->data[i], c->n, c->units[i]) < 0) {
            s = plume_err_set(err, PLUME_EIO, "curves file '%s': cannot write dataset %s/%s (HDF5: %s)",
                              path, gpath, c->names[i], h5_cause(&d));
            goto cleanup;
        }
    }
    for (int i = 0; i < c->nparams; i++) {
        if (h5_write_attr_double(g, c->params[i].name, c->params[i].value) < 0) {
            s = plume_err_set(err, PLUME_EIO, "curves file '%s': cannot write attribute %s of %s (HDF5: %s)",
                              path, c->params[i].name, gpath, h5_cause(&d));
            goto cleanup;
        }
    }
    if (c->nparams > 0) { /* the numeric parameters' units, in one string beside them */
        char units[2048] = "";
        size_t len = 0;
        for (int i = 0; i < c->nparams && len < sizeof units; i++)
            len += (size_t)snprintf(units + len, sizeof units - len, "%s%s: %s", i ? "; " : "", c->params[i].name,
                                    param_units(c->params[i].name));
        if (h5_write_attr_string(g, "units", units) < 0) {
            s = plume_err_set(err, PLUME_EIO, "curves file '%s': cannot write attribute units of %s (HDF5: %s)", path,
                              gpath, h5_cause(&d));
            goto cleanup;
        }
    }
    for (int i = 0; i < c->nsparams; i++) {
        if (h5_write_attr_string(g, c->sparams[i].name, c->sparams[i].value) < 0) {
            s = plume_err_set(err, PLUME_EIO, "curves file '%s': cannot write attribute %s of %s (HDF5: %s)",
                              path, c->sparams[i].name, gpath, h5_cause(&d));
            goto cleanup;
        }
    }
cleanup:
    if (g >= 0)
        H5Gclose(g);
    if (lcpl >= 0)
        H5Pclose(lcpl);
    return s;
}

/* Checks the parameter lists and writes the datasets data[0..nf) of n points under gpath. */
static plume_status write_fields(const char *path, const char *gpath, int nf, const char *const *names,
                                 const char *const *units, const double *const *data, plume_index n,
                                 const plume_param *params, int nparams, const plume_sparam *sparams, int nsparams,
                                 plume_err *err)
{
    if (nparams < 0 || nsparams < 0 || (nparams > 0 && !params) || (nsparams > 0 && !sparams))
        return plume_err_set(err, PLUME_EINVAL, "curves file '%s': bad parameter list", path);
    /* Attribute names must be unique across both lists: HDF5 would refuse the second one. */
    for (int i = 0; i < nparams + nsparams; i++) {
        const char *a = i < nparams ? params[i].name : sparams[i - nparams].name;
        if (!a || !*a)
            return plume_err_set(err, PLUME_EINVAL, "curves file '%s': parameter %d has no name", path, i);
        if (strcmp(a, "units") == 0)
            return plume_err_set(err, PLUME_EINVAL,
                                 "curves file '%s': \"units\" is reserved (it lists the parameters' units)", path);
        if (i >= nparams && !sparams[i - nparams].value)
            return plume_err_set(err, PLUME_EINVAL, "curves file '%s': string parameter %s has no value",
                                 path, a);
        for (int j = 0; j < i; j++) {
            const char *b = j < nparams ? params[j].name : sparams[j - nparams].name;
            if (strcmp(a, b) == 0)
                return plume_err_set(err, PLUME_EINVAL, "curves file '%s': parameter %s given twice",
                                     path, a);
        }
    }

    curve_ctx ctx = {gpath, nf, names, units, data, n, params, nparams, sparams, nsparams};
    h5_quiet q;
    quiet_begin(&q);
    plume_status s = plume_h5_atomic_write(path, "curves file", fill_curve, &ctx, err);
    quiet_end(&q);
    return s;
}

plume_status plume_curve_write(const char *path, const char *scale, const char *scenario,
                               const plume_curve *curve, const plume_param *params, int nparams,
                               const plume_sparam *sparams, int nsparams, plume_err *err)
{
    if (!path || !*path)
        return plume_err_set(err, PLUME_EINVAL, "curves file: empty path");
    if (bad_names(path, scale, scenario, err))
        return PLUME_EINVAL;
    if (!curve || curve->n < 0)
        return plume_err_set(err, PLUME_EINVAL, "curves file '%s': no curve or negative point count", path);
    const double *data[5];
    for (int i = 0; i < 5; i++)
        if (!(data[i] = curve_cfield(curve, i)) && curve->n > 0)
            return plume_err_set(err, PLUME_EINVAL, "curves file '%s': curve %s/%s has no %s array",
                                 path, scale, scenario, curve_fields[i]);
    char gpath[640];
    snprintf(gpath, sizeof gpath, "/curves/%s/%s", scale, scenario);
    return write_fields(path, gpath, 5, curve_fields, curve_units, data, curve->n, params, nparams, sparams,
                        nsparams, err);
}

void plume_curve_free(plume_curve *curve)
{
    if (!curve)
        return;
    for (int i = 0; i < 5; i++)
        free(*curve_field(curve, i));
    memset(curve, 0, sizeof *curve);
}

/* plume_curve_write_states: one 2-D dataset of states in an existing curve group */
typedef struct {
    const char *gpath, *name;
    long rows, cols;
    const int *v;
} states_ctx;

static plume_status fill_states(hid_t fid, const char *path, const void *vctx, plume_err *err)
{
    const states_ctx *c = vctx;
    h5_detail d;
    if (H5Lexists(fid, "/curves", H5P_DEFAULT) <= 0 || H5Lexists(fid, c->gpath, H5P_DEFAULT) <= 0)
        return plume_err_set(err, PLUME_EFORMAT, "curves file '%s': no group %s (write its curve first)", path, c->gpath);
    hid_t g = H5Gopen2(fid, c->gpath, H5P_DEFAULT), sp = H5I_INVALID_HID, ds = H5I_INVALID_HID;
    plume_status s = PLUME_OK;
    if (g < 0 || (H5Lexists(g, c->name, H5P_DEFAULT) > 0 && H5Ldelete(g, c->name, H5P_DEFAULT) < 0)) {
        s = plume_err_set(err, PLUME_EIO, "curves file '%s': cannot replace %s/%s (HDF5: %s)", path, c->gpath, c->name,
                          h5_cause(&d));
        goto cleanup;
    }
    const hsize_t dims[2] = {(hsize_t)c->rows, (hsize_t)c->cols};
    if ((sp = H5Screate_simple(2, dims, NULL)) < 0 ||
        (ds = H5Dcreate2(g, c->name, H5T_STD_I8LE, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT)) < 0 ||
        (c->rows * c->cols > 0 && H5Dwrite(ds, H5T_NATIVE_INT, H5S_ALL, H5S_ALL, H5P_DEFAULT, c->v) < 0) ||
        h5_write_attr_string(ds, "units", "1") < 0)
        s = plume_err_set(err, PLUME_EIO, "curves file '%s': cannot write %s/%s (HDF5: %s)", path, c->gpath, c->name,
                          h5_cause(&d));
cleanup:
    if (ds >= 0)
        H5Dclose(ds);
    if (sp >= 0)
        H5Sclose(sp);
    if (g >= 0)
        H5Gclose(g);
    return s;
}

plume_status plume_curve_write_states(const char *path, const char *scale, const char *scenario, const char *name,
                                      long rows, long cols, const int *states, plume_err *err)
{
    if (!path || !*path || !scale || !*scale || !scenario || !*scenario || !name || !*name || strchr(scale, '/') ||
        strchr(scenario, '/') || strchr(name, '/') || rows < 0 || cols < 0 || (rows * cols > 0 && !states))
        return plume_err_set(err, PLUME_EINVAL, "curves file: states need a path, a scale, a scenario and a name "
                             "without '/', and rows x cols values");
    char gpath[640];
    snprintf(gpath, sizeof gpath, "/curves/%s/%s", scale, scenario);
    states_ctx ctx = {gpath, name, rows, cols, states};
    h5_quiet q;
    quiet_begin(&q);
    plume_status s = plume_h5_atomic_write(path, "curves file", fill_states, &ctx, err);
    quiet_end(&q);
    return s;
}

/* Reads the datasets names[0..nf) of group gpath, all of one length *n, into out[i] (malloc'ed;
 * on failure the ones read stay in out[] for the caller to free). */
static plume_status read_fields(const char *path, const char *gpath, int nf, const char *const *names, double **out,
                                plume_index *np, plume_err *err)
{
    plume_status s = PLUME_OK;
    hid_t fid = H5I_INVALID_HID, g = H5I_INVALID_HID, ds = H5I_INVALID_HID, sp = H5I_INVALID_HID,
          ty = H5I_INVALID_HID;
    h5_detail d;
    h5_quiet q;
    quiet_begin(&q);

    s = open_for_read(path, "curves file", &fid, err);
    if (s != PLUME_OK)
        goto cleanup;
    int e = path_exists(fid, gpath);
    if (e != 1) {
        s = plume_err_set(err, PLUME_EFORMAT, "curves file '%s': no %s group", path, gpath);
        goto cleanup;
    }
    g = H5Gopen2(fid, gpath, H5P_DEFAULT);
    if (g < 0) {
        s = plume_err_set(err, PLUME_EFORMAT, "curves file '%s': %s is not a group", path, gpath);
        goto cleanup;
    }
    hsize_t n = 0;
    for (int i = 0; i < nf; i++) {
        const char *f = names[i];
        htri_t has = H5Lexists(g, f, H5P_DEFAULT);
        if (has <= 0 || (ds = H5Dopen2(g, f, H5P_DEFAULT)) < 0) {
            s = plume_err_set(err, PLUME_EFORMAT, "curves file '%s': dataset %s/%s missing", path,
                              gpath, f);
            goto cleanup;
        }
        sp = H5Dget_space(ds);
        ty = H5Dget_type(ds);
        hsize_t dims[1] = {0};
        H5T_class_t cls = ty < 0 ? H5T_NO_CLASS : H5Tget_class(ty);
        if (sp < 0 || H5Sget_simple_extent_ndims(sp) != 1 || H5Sget_simple_extent_dims(sp, dims, NULL) != 1 ||
            (cls != H5T_FLOAT && cls != H5T_INTEGER)) {
            s = plume_err_set(err, PLUME_EFORMAT,
                              "curves file '%s': dataset %s/%s is not a 1-D numeric array", path,
                              gpath, f);
            goto cleanup;
        }
        if (i == 0)
            n = dims[0];
        else if (dims[0] != n) {
            s = plume_err_set(err, PLUME_EFORMAT,
                              "curves file '%s': dataset %s/%s has %llu points but %s has %llu",
                              path, gpath, f, (unsigned long long)dims[0], names[0], (unsigned long long)n);
            goto cleanup;
        }
        double *v = malloc((n ? (size_t)n : 1) * sizeof *v);
        if (!v) {
            s = plume_err_set(err, PLUME_ENOMEM, "curves file '%s': out of memory for %llu points",
                              path, (unsigned long long)n);
            goto cleanup;
        }
        out[i] = v;
        if (n > 0 && H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v) < 0) {
            s = plume_err_set(err, PLUME_EIO, "curves file '%s': cannot read dataset %s/%s (HDF5: %s)",
                              path, gpath, f, h5_cause(&d));
            goto cleanup;
        }
        H5Tclose(ty);
        H5Sclose(sp);
        H5Dclose(ds);
        ty = sp = ds = H5I_INVALID_HID;
    }
    *np = (plume_index)n;

cleanup:
    if (ty >= 0)
        H5Tclose(ty);
    if (sp >= 0)
        H5Sclose(sp);
    if (ds >= 0)
        H5Dclose(ds);
    if (g >= 0)
        H5Gclose(g);
    if (fid >= 0)
        H5Fclose(fid);
    quiet_end(&q);
    return s;
}

plume_status plume_curve_read(const char *path, const char *scale, const char *scenario,
                              plume_curve *curve, plume_err *err)
{
    if (!curve)
        return plume_err_set(err, PLUME_EINVAL, "curves file: no output curve");
    memset(curve, 0, sizeof *curve);
    if (!path || !*path)
        return plume_err_set(err, PLUME_EINVAL, "curves file: empty path");
    if (bad_names(path, scale, scenario, err))
        return PLUME_EINVAL;
    char gpath[640];
    snprintf(gpath, sizeof gpath, "/curves/%s/%s", scale, scenario);
    double *v[5] = {NULL};
    plume_status s = read_fields(path, gpath, 5, curve_fields, v, &curve->n, err);
    for (int i = 0; i < 5; i++)
        *curve_field(curve, i) = v[i];
    if (s != PLUME_OK)
        plume_curve_free(curve);
    return s;
}

/* ----------------------------------------------------------------- bending curves ---- */

static const char *const bend_fields[8] = {"curvature", "moment", "k_xx", "k_yy", "twist", "energy", "iterations",
                                           "seconds"};
static const char *const bend_units[8] = {"1/m", "N", "1/m", "1/m", "1/m", "J", "1", "s"};

static double **bend_field(plume_bend_curve *c, int i)
{
    double **f[8] = {&c->curvature, &c->moment, &c->k_xx, &c->k_yy, &c->twist, &c->energy, &c->iterations,
                     &c->seconds};
    return f[i];
}

plume_status plume_bend_curve_write(const char *path, const char *scale, const char *scenario,
                                    const plume_bend_curve *curve, const plume_param *params, int nparams,
                                    const plume_sparam *sparams, int nsparams, plume_err *err)
{
    if (!path || !*path)
        return plume_err_set(err, PLUME_EINVAL, "curves file: empty path");
    if (bad_names(path, scale, scenario, err))
        return PLUME_EINVAL;
    if (!curve || curve->n < 0)
        return plume_err_set(err, PLUME_EINVAL, "curves file '%s': no curve or negative point count", path);
    const double *data[8];
    for (int i = 0; i < 8; i++)
        if (!(data[i] = *bend_field((plume_bend_curve *)curve, i)) && curve->n > 0)
            return plume_err_set(err, PLUME_EINVAL, "curves file '%s': bending curve %s/%s has no %s array", path,
                                 scale, scenario, bend_fields[i]);
    char gpath[640];
    snprintf(gpath, sizeof gpath, "/curves/bending/%s/%s", scale, scenario);
    return write_fields(path, gpath, 8, bend_fields, bend_units, data, curve->n, params, nparams, sparams, nsparams,
                        err);
}

plume_status plume_bend_curve_read(const char *path, const char *scale, const char *scenario, plume_bend_curve *curve,
                                   plume_err *err)
{
    if (!curve)
        return plume_err_set(err, PLUME_EINVAL, "curves file: no output curve");
    memset(curve, 0, sizeof *curve);
    if (!path || !*path)
        return plume_err_set(err, PLUME_EINVAL, "curves file: empty path");
    if (bad_names(path, scale, scenario, err))
        return PLUME_EINVAL;
    char gpath[640];
    snprintf(gpath, sizeof gpath, "/curves/bending/%s/%s", scale, scenario);
    double *v[8] = {NULL};
    plume_status s = read_fields(path, gpath, 8, bend_fields, v, &curve->n, err);
    for (int i = 0; i < 8; i++)
        *bend_field(curve, i) = v[i];
    if (s != PLUME_OK)
        plume_bend_curve_free(curve);
    return s;
}

void plume_bend_curve_free(plume_bend_curve *curve)
{
    if (!curve)
        return;
    for (int i = 0; i < 8; i++)
        free(*bend_field(curve, i));
    memset(curve, 0, sizeof *curve);
}

/* The bending curves' group of a scale: "/curves/bending/<scale>" in buf (size 640). */
static int bend_scale_path(const char *path, const char *scale, char *buf, plume_err *err)
{
    if (!path || !*path) {
        plume_err_set(err, PLUME_EINVAL, "curves file: empty path");
        return 1;
    }
    if (bad_names(path, scale, "x", err))
        return 1;
    snprintf(buf, 640, "/curves/bending/%s", scale);
    return 0;
}

plume_status plume_bend_curve_names(const char *path, const char *scale, char ***names, int *n, plume_err *err)
{
    if (!names || !n)
        return plume_err_set(err, PLUME_EINVAL, "curves file: no output given");
    *names = NULL, *n = 0;
    char gpath[640];
    if (bend_scale_path(path, scale, gpath, err))
        return PLUME_EINVAL;
    plume_status s = PLUME_OK;
    hid_t fid = H5I_INVALID_HID, g = H5I_INVALID_HID;
    h5_detail d;
    h5_quiet q;
    quiet_begin(&q);
    char **out = NULL;
    int count = 0;
    if ((s = open_for_read(path, "curves file", &fid, err)) != PLUME_OK)
        goto cleanup;
    H5G_info_t info;
    if (path_exists(fid, gpath) != 1 || (g = H5Gopen2(fid, gpath, H5P_DEFAULT)) < 0 || H5Gget_info(g, &info) < 0 ||
        info.nlinks == 0) {
        s = plume_err_set(err, PLUME_EFORMAT, "curves file '%s': no bending curves (no %s group or an empty one; "
                          "plume_bend_curve_write writes them)", path, gpath);
        goto cleanup;
    }
    if (info.nlinks > 100000) {
        s = plume_err_set(err, PLUME_EFORMAT, "curves file '%s': %s has %llu entries", path, gpath,
                          (unsigned long long)info.nlinks);
        goto cleanup;
    }
    out = calloc((size_t)info.nlinks, sizeof *out);
    if (!out) {
        s = plume_err_set(err, PLUME_ENOMEM, "curves file '%s': out of memory", path);
        goto cleanup;
    }
    for (hsize_t i = 0; i < info.nlinks; i++) {
        ssize_t len = H5Lget_name_by_idx(g, ".", H5_INDEX_NAME, H5_ITER_INC, i, NULL, 0, H5P_DEFAULT);
        if (len < 0) {
            s = plume_err_set(err, PLUME_EIO, "curves file '%s': cannot list %s (HDF5: %s)", path, gpath, h5_cause(&d));
            goto cleanup;
        }
        if (!(out[count] = malloc((size_t)len + 1))) {
            s = plume_err_set(err, PLUME_ENOMEM, "curves file '%s': out of memory", path);
            goto cleanup;
        }
        H5Lget_name_by_idx(g, ".", H5_INDEX_NAME, H5_ITER_INC, i, out[count], (size_t)len + 1, H5P_DEFAULT);
        count++;
    }
    *names = out, *n = count;
    out = NULL;
cleanup:
    if (out)
        plume_bend_curve_names_free(out, count);
    if (g >= 0)
        H5Gclose(g);
    if (fid >= 0)
        H5Fclose(fid);
    quiet_end(&q);
    return s;
}

void plume_bend_curve_names_free(char **names, int n)
{
    for (int i = 0; names && i < n; i++)
        free(names[i]);
    free(names);
}

plume_status plume_bend_curve_param(const char *path, const char *scale, const char *scenario, const char *name,
                                    double *value, plume_err *err)
{
    if (!name || !value)
        return plume_err_set(err, PLUME_EINVAL, "curves file: no parameter or output given");
    if (!path || !*path)
        return plume_err_set(err, PLUME_EINVAL, "curves file: empty path");
    if (bad_names(path, scale, scenario, err))
        return PLUME_EINVAL;
    char gpath[640];
    snprintf(gpath, sizeof gpath, "/curves/bending/%s/%s", scale, scenario);
    plume_status s = PLUME_OK;
    hid_t fid = H5I_INVALID_HID, g = H5I_INVALID_HID, a = H5I_INVALID_HID, sp = H5I_INVALID_HID,
          ty = H5I_INVALID_HID;
    h5_detail d;
    h5_quiet q;
    quiet_begin(&q);
    if ((s = open_for_read(path, "curves file", &fid, err)) != PLUME_OK)
        goto cleanup;
    if (path_exists(fid, gpath) != 1 || (g = H5Gopen2(fid, gpath, H5P_DEFAULT)) < 0) {
        s = plume_err_set(err, PLUME_EFORMAT, "curves file '%s': no %s group", path, gpath);
        goto cleanup;
    }
    if (H5Aexists(g, name) <= 0 || (a = H5Aopen(g, name, H5P_DEFAULT)) < 0) {
        s = plume_err_set(err, PLUME_EFORMAT, "curves file '%s': %s has no attribute %s", path, gpath, name);
        goto cleanup;
    }
    sp = H5Aget_space(a);
    ty = H5Aget_type(a);
    H5T_class_t cls = ty < 0 ? H5T_NO_CLASS : H5Tget_class(ty);
    if (sp < 0 || H5Sget_simple_extent_npoints(sp) != 1 || (cls != H5T_FLOAT && cls != H5T_INTEGER)) {
        s = plume_err_set(err, PLUME_EFORMAT, "curves file '%s': attribute %s of %s is not a single number", path,
                          name, gpath);
        goto cleanup;
    }
    if (H5Aread(a, H5T_NATIVE_DOUBLE, value) < 0)
        s = plume_err_set(err, PLUME_EIO, "curves file '%s': cannot read attribute %s of %s (HDF5: %s)", path, name,
                          gpath, h5_cause(&d));
cleanup:
    if (ty >= 0)
        H5Tclose(ty);
    if (sp >= 0)
        H5Sclose(sp);
    if (a >= 0)
        H5Aclose(a);
    if (g >= 0)
        H5Gclose(g);
    if (fid >= 0)
        H5Fclose(fid);
    quiet_end(&q);
    return s;
}

/* ------------------------------------------------------------------------- moduli ---- */

static const char *const moduli_names[4] = {"E_xx", "E_yy", "nu_xy", "G_xy"};

static double *moduli_field(plume_ortho *m, int i)
{
    switch (i) {
    case 0: return &m->E_xx;
    case 1: return &m->E_yy;
    case 2: return &m->nu_xy;
    default: return &m->G_xy;
    }
}

/* Checks the moduli describe a usable orthotropic material; on failure fills `why` with the
 * offending attribute and value. Beyond finiteness and positivity, the plane-stress tensor of
 * docs/design.md is positive definite only if nu_xy nu_yx = nu_xy^2 E_yy / E_xx < 1. */
static int moduli_invalid(const plume_ortho *m, char *why, size_t len)
{
    plume_ortho c = *m;
    for (int i = 0; i < 4; i++) {
        double v = *moduli_field(&c, i);
        if (!isfinite(v) || (i != 2 && !(v > 0))) {
            snprintf(why, len, "%s must be %s (got %g)", moduli_names[i],
                     i == 2 ? "finite" : "finite and > 0", v);
            return 1;
        }
    }
    if (!(m->nu_xy * m->nu_xy * m->E_yy < m->E_xx)) {
        snprintf(why, len,
                 "nu_xy = %g with E_xx = %g, E_yy = %g makes the stiffness tensor indefinite "
                 "(need nu_xy^2 E_yy / E_xx < 1)",
                 m->nu_xy, m->E_xx, m->E_yy);
        return 1;
    }
    return 0;
}

typedef struct {
    const plume_ortho *m;
    const char *provenance;
    const plume_param *params;
    int nparams;
} moduli_ctx;

static plume_status fill_moduli(hid_t fid, const char *path, const void *vctx, plume_err *err)
{
    const moduli_ctx *c = vctx;
    plume_status s = PLUME_OK;
    hid_t g = H5I_INVALID_HID;
    h5_detail d;
    htri_t e = H5Lexists(fid, "/moduli", H5P_DEFAULT);
    if (e < 0 || (e > 0 && H5Ldelete(fid, "/moduli", H5P_DEFAULT) < 0)) {
        s = plume_err_set(err, PLUME_EIO, "moduli file '%s': cannot replace /moduli (HDF5: %s)",
                          path, h5_cause(&d));
        goto cleanup;
    }
    g = H5Gcreate2(fid, "/moduli", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (g < 0) {
        s = plume_err_set(err, PLUME_EIO, "moduli file '%s': cannot create /moduli (HDF5: %s)",
                          path, h5_cause(&d));
        goto cleanup;
    }
    plume_ortho m = *c->m;
    for (int i = 0; i < 4; i++) {
        if (h5_write_attr_double(g, moduli_names[i], *moduli_field(&m, i)) < 0) {
            s = plume_err_set(err, PLUME_EIO, "moduli file '%s': cannot write attribute %s (HDF5: %s)",
                              path, moduli_names[i], h5_cause(&d));
            goto cleanup;
        }
    }
    /* attributes carry no attributes: the moduli's units in one string beside them, then those of
     * the extra attributes (bending moduli in N m, lengths in m, the rest pure numbers) */
    char units[2048] = "E_xx, E_yy, G_xy: Pa; nu_xy: 1";
    size_t len = strlen(units);
    for (int i = 0; i < c->nparams && len < sizeof units; i++)
        len += (size_t)snprintf(units + len, sizeof units - len, "; %s: %s", c->params[i].name,
                                param_units(c->params[i].name));
    if (h5_write_attr_string(g, "units", units) < 0 ||
        h5_write_attr_string(g, "provenance", c->provenance) < 0) {
        s = plume_err_set(err, PLUME_EIO, "moduli file '%s': cannot write attribute units or provenance (HDF5: %s)",
                          path, h5_cause(&d));
        goto cleanup;
    }
    for (int i = 0; i < c->nparams; i++)
        if (h5_write_attr_double(g, c->params[i].name, c->params[i].value) < 0) {
            s = plume_err_set(err, PLUME_EIO, "moduli file '%s': cannot write attribute %s (HDF5: %s)", path,
                              c->params[i].name, h5_cause(&d));
            goto cleanup;
        }
cleanup:
    if (g >= 0)
        H5Gclose(g);
    return s;
}

plume_status plume_moduli_write(const char *path, const plume_ortho *m, const char *provenance,
                                plume_err *err)
{
    return plume_moduli_write_params(path, m, provenance, NULL, 0, err);
}

plume_status plume_moduli_write_params(const char *path, const plume_ortho *m, const char *provenance,
                                       const plume_param *params, int nparams, plume_err *err)
{
    char why[256];
    if (!path || !*path)
        return plume_err_set(err, PLUME_EINVAL, "moduli file: empty path");
    if (!m)
        return plume_err_set(err, PLUME_EINVAL, "moduli file '%s': no moduli given", path);
    if (moduli_invalid(m, why, sizeof why))
        return plume_err_set(err, PLUME_EINVAL, "moduli file '%s': not written: %s", path, why);
    if (nparams < 0 || (nparams > 0 && !params))
        return plume_err_set(err, PLUME_EINVAL, "moduli file '%s': invalid extra attributes", path);
    for (int i = 0; i < nparams; i++)
        for (int k = 0; k < 4; k++)
            if (!params[i].name || strcmp(params[i].name, moduli_names[k]) == 0 || strcmp(params[i].name, "units") == 0 ||
                strcmp(params[i].name, "provenance") == 0)
                return plume_err_set(err, PLUME_EINVAL, "moduli file '%s': extra attribute %d has a reserved or no name",
                                     path, i);
    moduli_ctx ctx = {m, provenance ? provenance : "unspecified", params, nparams};
    h5_quiet q;
    quiet_begin(&q);
    plume_status s = plume_h5_atomic_write(path, "moduli file", fill_moduli, &ctx, err);
    quiet_end(&q);
    return s;
}

plume_status plume_moduli_read(const char *path, plume_ortho *m, plume_err *err)
{
    if (!path || !*path)
        return plume_err_set(err, PLUME_EINVAL, "moduli file: empty path");
    if (!m)
        return plume_err_set(err, PLUME_EINVAL, "moduli file '%s': no output given", path);

    plume_status s = PLUME_OK;
    hid_t fid = H5I_INVALID_HID, g = H5I_INVALID_HID, a = H5I_INVALID_HID, sp = H5I_INVALID_HID,
          ty = H5I_INVALID_HID;
    h5_detail d;
    plume_ortho r = {0, 0, 0, 0};
    char why[256];
    h5_quiet q;
    quiet_begin(&q);

    s = open_for_read(path, "moduli file", &fid, err);
    if (s != PLUME_OK)
        goto cleanup;
    if (H5Lexists(fid, "/moduli", H5P_DEFAULT) <= 0) {
        s = plume_err_set(err, PLUME_EFORMAT, "moduli file '%s': no /moduli group", path);
        goto cleanup;
    }
    g = H5Gopen2(fid, "/moduli", H5P_DEFAULT);
    if (g < 0) {
        s = plume_err_set(err, PLUME_EFORMAT, "moduli file '%s': /moduli is not a group", path);
        goto cleanup;
    }
    for (int i = 0; i < 4; i++) {
        const char *name = moduli_names[i];
        if (H5Aexists(g, name) <= 0 || (a = H5Aopen(g, name, H5P_DEFAULT)) < 0) {
            s = plume_err_set(err, PLUME_EFORMAT, "moduli file '%s': /moduli attribute %s missing",
                              path, name);
            goto cleanup;
        }
        sp = H5Aget_space(a);
        ty = H5Aget_type(a);
        H5T_class_t cls = ty < 0 ? H5T_NO_CLASS : H5Tget_class(ty);
        if (sp < 0 || H5Sget_simple_extent_npoints(sp) != 1 || (cls != H5T_FLOAT && cls != H5T_INTEGER)) {
            s = plume_err_set(err, PLUME_EFORMAT,
                              "moduli file '%s': /moduli attribute %s is not a single number", path,
                              name);
            goto cleanup;
        }
        if (H5Aread(a, H5T_NATIVE_DOUBLE, moduli_field(&r, i)) < 0) {
            s = plume_err_set(err, PLUME_EIO, "moduli file '%s': cannot read attribute %s (HDF5: %s)",
                              path, name, h5_cause(&d));
            goto cleanup;
        }
        H5Tclose(ty);
        H5Sclose(sp);
        H5Aclose(a);
        ty = sp = a = H5I_INVALID_HID;
    }
    if (moduli_invalid(&r, why, sizeof why)) {
        s = plume_err_set(err, PLUME_EINVAL, "moduli file '%s': %s", path, why);
        goto cleanup;
    }
    *m = r;

cleanup:
    if (ty >= 0)
        H5Tclose(ty);
    if (sp >= 0)
        H5Sclose(sp);
    if (a >= 0)
        H5Aclose(a);
    if (g >= 0)
        H5Gclose(g);
    if (fid >= 0)
        H5Fclose(fid);
    quiet_end(&q);
    return s;
}

plume_status plume_moduli_read_param(const char *path, const char *name, double *value, plume_err *err)
{
    if (!path || !*path)
        return plume_err_set(err, PLUME_EINVAL, "moduli file: empty path");
    if (!name || !value)
        return plume_err_set(err, PLUME_EINVAL, "moduli file '%s': no attribute or output given", path);
    plume_status s = PLUME_OK;
    hid_t fid = H5I_INVALID_HID, g = H5I_INVALID_HID, a = H5I_INVALID_HID, sp = H5I_INVALID_HID,
          ty = H5I_INVALID_HID;
    h5_detail d;
    h5_quiet q;
    quiet_begin(&q);
    if ((s = open_for_read(path, "moduli file", &fid, err)) != PLUME_OK)
        goto cleanup;
    if (H5Lexists(fid, "/moduli", H5P_DEFAULT) <= 0 || (g = H5Gopen2(fid, "/moduli", H5P_DEFAULT)) < 0) {
        s = plume_err_set(err, PLUME_EFORMAT, "moduli file '%s': no /moduli group", path);
        goto cleanup;
    }
    if (H5Aexists(g, name) <= 0 || (a = H5Aopen(g, name, H5P_DEFAULT)) < 0) {
        s = plume_err_set(err, PLUME_EFORMAT, "moduli file '%s': /moduli attribute %s missing", path, name);
        goto cleanup;
    }
    sp = H5Aget_space(a);
    ty = H5Aget_type(a);
    H5T_class_t cls = ty < 0 ? H5T_NO_CLASS : H5Tget_class(ty);
    if (sp < 0 || H5Sget_simple_extent_npoints(sp) != 1 || (cls != H5T_FLOAT && cls != H5T_INTEGER)) {
        s = plume_err_set(err, PLUME_EFORMAT, "moduli file '%s': /moduli attribute %s is not a single number", path, name);
        goto cleanup;
    }
    if (H5Aread(a, H5T_NATIVE_DOUBLE, value) < 0)
        s = plume_err_set(err, PLUME_EIO, "moduli file '%s': cannot read attribute %s (HDF5: %s)", path, name,
                          h5_cause(&d));
cleanup:
    if (ty >= 0)
        H5Tclose(ty);
    if (sp >= 0)
        H5Sclose(sp);
    if (a >= 0)
        H5Aclose(a);
    if (g >= 0)
        H5Gclose(g);
    if (fid >= 0)
        H5Fclose(fid);
    quiet_end(&q);
    return s;
}

int plume_moduli_has_param(const char *path, const char *name)
{
    if (!path || !name)
        return 0;
    h5_quiet q;
    quiet_begin(&q);
    int has = 0;
    hid_t fid = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (fid >= 0) {
        if (H5Lexists(fid, "/moduli", H5P_DEFAULT) > 0) {
            hid_t g = H5Gopen2(fid, "/moduli", H5P_DEFAULT);
            if (g >= 0) {
                has = H5Aexists(g, name) > 0;
                H5Gclose(g);
            }
        }
        H5Fclose(fid);
    }
    quiet_end(&q);
    return has;
}

plume_status plume_moduli_read_tensor(const char *path, const char *prefix, double C[9], plume_err *err)
{
    static const char *const names[6] = {"C11", "C12", "C13", "C22", "C23", "C33"};
    static const int at[6][2] = {{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}};
    if (!C)
        return plume_err_set(err, PLUME_EINVAL, "moduli file: no output given");
    for (int k = 0; k < 6; k++) {
        char name[64];
        snprintf(name, sizeof name, "%s%s", prefix ? prefix : "", names[k]);
        double v = 0.0;
        plume_status st = plume_moduli_read_param(path, name, &v, err);
        if (st != PLUME_OK)
            return st;
        C[3 * at[k][0] + at[k][1]] = C[3 * at[k][1] + at[k][0]] = v;
    }
    return PLUME_OK;
}
