/* plume: the scene runner's output (macro/scene/run.h): the frames of a run (a ParaView series, frames.h5,
 * PNG renders) and a restart from a frames file. */
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../../lib/io/fs.h"
#include "../../lib/io/render.h"
#include "../shell/midedge_term.h"
#include "internal/run.h"

void plume_run_measures_reset(plume_run *r)
{
    const plume_scene *s = r->scene;
    plume_frame_measures *fm = &r->fm;
    memset(fm, 0, sizeof *fm);
    fm->contact_pairs = fm->intersecting_pairs = s->has_contact ? 0.0 : -1.0;
    fm->min_distance = s->has_contact ? 10.0 * s->contact.pair.dhat : -1.0;
}

/* Removes DIR/frame_<digits>.{vtu,vtk,png} and DIR/frame_barbs_<digits>.vtu left by an earlier
 * run, so a ParaView series or a folder of pictures never mixes two runs. Only names a run
 * writes (or wrote before .vtu) are touched. */
static void remove_stale_frames(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d)
        return;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        const char *n = e->d_name;
        if (strncmp(n, "frame_", 6) != 0)
            continue;
        const char *p = n + 6;
        if (strncmp(p, "barbs_", 6) == 0)
            p += 6;
        size_t digits = strspn(p, "0123456789");
        const char *ext = p + digits;
        if (digits < 5 || (strcmp(ext, ".vtk") != 0 && strcmp(ext, ".vtu") != 0 && strcmp(ext, ".png") != 0))
            continue;
        char path[4096 + 300];
        snprintf(path, sizeof path, "%s/%s", dir, n);
        unlink(path);
    }
    closedir(d);
}

/* Copies src to dst through "<dst>.tmp.<pid>" and a rename. */
static int copy_file(const char *src, const char *dst)
{
    char tmp[4300];
    if (snprintf(tmp, sizeof tmp, "%s.tmp.%ld", dst, (long)getpid()) >= (int)sizeof tmp)
        return errno = ENAMETOOLONG, -1;
    FILE *in = fopen(src, "rb"), *out = in ? fopen(tmp, "wb") : NULL;
    int ok = in && out;
    char buf[65536];
    size_t n;
    while (ok && (n = fread(buf, 1, sizeof buf, in)) > 0)
        ok = fwrite(buf, 1, n, out) == n;
    ok = ok && !ferror(in);
    if (in)
        fclose(in);
    if (out && fclose(out) != 0)
        ok = 0;
    if (ok && rename(tmp, dst) != 0)
        ok = 0;
    if (!ok && out)
        unlink(tmp);
    return ok ? 0 : -1;
}

static int same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    return stat(a, &sa) == 0 && stat(b, &sb) == 0 && sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

static int wants_render(const plume_run *r, long k)
{
    if (!r->render)
        return 0;
    for (int i = 0; i < r->scene->nrender; i++)
        if (r->scene->render[i] == k)
            return 1;
    return 0;
}

/* The scene's render_field per triangle into v[nt]: a field of macro/fields.h, its values at x.
 * Returns the colour-bar label (NULL: no field, colour by material or by object; "": an error). */
static const char *render_values(const plume_run *r, const double *x, double *v, plume_err *err)
{
    const plume_scene *s = r->scene;
    if (strcmp(s->render_field, "material") == 0 || strcmp(s->render_field, "object") == 0)
        return NULL; /* coloured by material, or by category (render_frame) */
    plume_field_values fv;
    if (plume_fields_compute(r->fields, x, &fv, err) != PLUME_OK)
        return "";
    if (strncmp(s->render_field, "curvature_", 10) == 0 && !fv.curvature) {
        plume_err_set(err, PLUME_EINVAL,
                      "scene: render_field \"%s\" is the midedge operator's curvature: it needs \"bending_model\": "
                      "\"midedge\" (the scene's is \"%s\"; \"mean_curvature\" works with every model)",
                      s->render_field, plume_scene_bending_name(s->bending_model));
        return "";
    }
    if (plume_field_values_select(&fv, s->render_field, v, err) != PLUME_OK)
        return "";
    return plume_field_label(s->render_field);
}

/* Each triangle's scene object (the whole mesh's triangles; NULL when out of memory) */
static int *object_categories(const plume_scene *s)
{
    int *c = malloc((size_t)(s->mesh->nt + 1) * sizeof *c);
    if (!c)
        return NULL;
    for (plume_index t = 0; t < s->mesh->nt; t++)
        c[t] = 0;
    for (int i = 0; i < s->nobjects; i++)
        for (plume_index t = s->objects[i].t0; t < s->objects[i].t0 + s->objects[i].nt; t++)
            c[t] = i;
    return c;
}

/* The PNG of frame k (DIR/frame_NNNNN.png), coloured as the scene asks. */
static plume_status render_frame(const plume_run *r, const double *x, double t, long k, plume_err *err)
{
    plume_err why = {{0}};
    const plume_mesh *m = r->scene->mesh;
    plume_render_opts ro;
    plume_render_opts_default(&ro);
    ro.rot_x = r->scene->camera[0];
    ro.rot_z = r->scene->camera[1];
    char title[512], path[4400];
    snprintf(title, sizeof title, "%s   t = %.4f s   frame %ld", r->stem, t, k);
    ro.title = title;
    double *values = malloc((size_t)m->nt * sizeof *values);
    if (!values)
        return plume_err_set(err, PLUME_ENOMEM, "render: out of memory");
    const char *label = render_values(r, x, values, &why);
    if (label && !*label) {
        free(values);
        return plume_err_set(err, PLUME_EINVAL, "render: %s", why.msg);
    }
    int *object = NULL;
    if (label)
        ro.field = values, ro.field_label = label;
    else if (strcmp(r->scene->render_field, "object") == 0 && (object = object_categories(r->scene)) != NULL)
        ro.category = object; /* one of 12 colours per scene object, cycled: neighbours told apart */
    snprintf(path, sizeof path, "%s/frame_%05ld.png", r->output_dir, k);
    plume_status st = plume_render_png(path, m, x, &ro, err);
    free(values);
    free(object);
    return st;
}

/* The state beyond the vertices that a restart needs, as arrays of a frame: midedge bending's edge
 * unknowns (the problem's x after the vertices, as the stepper left it) and the frames they are
 * measured in. Returns their count (0: none). */
static int state_arrays(plume_run *r, plume_frame_array a[2])
{
    plume_midedge_term *t = plume_problem_term_ctx(r->p, PLUME_MIDEDGE_TERM_NAME);
    if (!t)
        return 0;
    const plume_index ne = plume_midedge_term_nedge(t);
    a[0] = (plume_frame_array){"edge_angles", plume_problem_x(r->p) + plume_midedge_term_first(t), ne,
                               "m (edge rest length times angle, rad)"};
    a[1] = (plume_frame_array){"edge_frames", plume_midedge_term_frames(t), 3 * ne, "1"};
    return 2;
}

/* Every array of a frame beyond x, v and lambda: state_arrays, then the split lines' links
 * (run_splits.c); -1 when memory runs out. */
static int frame_arrays(plume_run *r, plume_frame_array a[3])
{
    int n = state_arrays(r, a);
    const int ns = plume_run_splits_array(r, a + n);
    return ns < 0 ? -1 : n + ns;
}

/* A restart's state beyond the vertices (state_arrays) from frame `last` of the file: the frames
 * set back and the edge unknowns into the problem's x, where plume_dynamics_set_state takes them. */
static plume_status restore_state_arrays(plume_run *r, const char *file, long last, plume_err *err)
{
    plume_frame_array a[2];
    if (state_arrays(r, a) == 0)
        return PLUME_OK;
    plume_midedge_term *t = plume_problem_term_ctx(r->p, PLUME_MIDEDGE_TERM_NAME);
    double *frames = malloc((size_t)(a[1].n + 1) * sizeof *frames);
    if (!frames)
        return plume_err_set(err, PLUME_ENOMEM, "restart: out of memory");
    plume_status st = plume_frames_read_array(file, last, a[1].name, frames, a[1].n, err);
    if (st == PLUME_OK) /* a[0] points into the problem's x: read in place */
        st = plume_frames_read_array(file, last, a[0].name, (double *)a[0].v, a[0].n, err);
    if (st == PLUME_OK)
        st = plume_midedge_term_set_frames(t, frames, err);
    free(frames);
    return st;
}

/* Every state array of a restart: the midedge unknowns, the split lines' links */
static plume_status restore_frame_arrays(plume_run *r, const char *file, long last, plume_err *err)
{
    plume_status st = restore_state_arrays(r, file, last, err);
    return st == PLUME_OK ? plume_run_splits_restore(r, file, last, err) : st;
}

plume_status plume_run_write_frame(plume_run *r, long k, long step, plume_err *err)
{
    const plume_mesh *m = r->scene->mesh;
    const double *x = plume_dynamics_positions(r->d);
    double t = plume_dynamics_time(r->d);
    plume_status st;
    if ((st = plume_fields_series_frame(r->fields, k, t, x, err)) != PLUME_OK)
        return st;
    const double *lambda = plume_dynamics_multipliers(r->d, NULL);
    plume_frame_array a[3];
    const int na = frame_arrays(r, a);
    if (na < 0)
        return plume_err_set(err, PLUME_ENOMEM, "frame %ld: out of memory", k);
    if ((st = plume_frames_append_arrays(r->frames_path, m->nv, r->ncons, t, step, x, plume_dynamics_velocities(r->d),
                                         lambda, &r->fm, a, na, err)) != PLUME_OK)
        return st;
    if (wants_render(r, k) && (st = render_frame(r, x, t, k, err)) != PLUME_OK)
        return st;
    return PLUME_OK;
}

/* restart: the state of the frames file's last frame, the file copied to frames_path if it is
 * another, the series continued */
static plume_status restart_run(plume_run *r, plume_err *err)
{
    plume_err why = {{0}};
    const plume_mesh *mesh = r->scene->mesh;
    plume_frames_info info;
    plume_frame last = {0};
    plume_status st;
    if ((st = plume_frames_info_read(r->restart, &info, &why)) != PLUME_OK ||
        (st = plume_frames_read(r->restart, -1, &last, &why)) != PLUME_OK) {
        plume_err_set(err, st, "restart: %s", why.msg);
        goto done;
    }
    r->rep.restart_dt = info.dt;
    if (info.nv != mesh->nv || info.ncons != r->ncons) {
        st = plume_err_set(err, PLUME_EINVAL,
                           "restart: '%s' holds frames of %ld vertices and %ld constraints, but the scene '%s' has %ld "
                           "and %ld (another scene or mesh?)",
                           r->restart, (long)info.nv, (long)info.ncons, r->scene->path, (long)mesh->nv, (long)r->ncons);
        goto done;
    }
    if ((st = restore_frame_arrays(r, r->restart, last.index, &why)) != PLUME_OK ||
        (st = plume_dynamics_set_state(r->d, last.t, last.x, last.v, last.lambda, &why)) != PLUME_OK) {
        plume_err_set(err, st, "restart: the last frame of '%s': %s", r->restart, why.msg);
        goto done;
    }
    r->rep.step = last.step;
    r->rep.next_frame = last.index + 1;
    if (!r->output_dir)
        goto done;
    if (!same_file(r->restart, r->frames_path) && copy_file(r->restart, r->frames_path) != 0) {
        st = plume_err_set(err, PLUME_EIO, "cannot copy '%s' to '%s': %s", r->restart, r->frames_path, strerror(errno));
        goto done;
    }
    st = plume_fields_series_start(r->fields, r->output_dir, "frames.pvd", "frame", last.t, err);
done:
    plume_frame_free(&last);
    return st;
}

/* The scene file by an absolute path, as a frames file records it: a reader (a restart, the glTF
 * export, plume.read_frames) then finds it from any directory. */
static void absolute_scene(const plume_run *r, char *out, size_t n)
{
    char cwd[4096];
    if (r->scene->path[0] != '/' && getcwd(cwd, sizeof cwd))
        snprintf(out, n, "%s/%s", cwd, r->scene->path);
    else
        snprintf(out, n, "%s", r->scene->path);
}

plume_status plume_run_output_start(plume_run *r, plume_err *err)
{
    plume_status st;
    char scene[4096 + 1024];
    if (r->output_dir) {
        if (plume_make_dirs(r->output_dir) != 0)
            return plume_err_set(err, PLUME_EIO, "output_dir '%s': cannot create the directory: %s", r->output_dir,
                                 strerror(errno));
        if ((st = plume_scene_fields_of(r->scene, r->p, &r->fields, err)) != PLUME_OK ||
            (st = plume_run_gltf_prepare(r, err)) != PLUME_OK)
            return st;
        /* split lines: each frame's links as lines (frame_splits_NNNNN.vtu), their state and energy */
        if (plume_run_split_hooks(r) && (st = plume_fields_add_links(r->fields, r->p, "splits", err)) != PLUME_OK)
            return st;
    }
    if (r->restart)
        return restart_run(r, err);
    r->rep.frames = 1; /* the initial state, frame 0 */
    r->rep.next_frame = 1;
    if (!r->output_dir)
        return PLUME_OK;
    remove_stale_frames(r->output_dir);
    absolute_scene(r, scene, sizeof scene);
    if ((st = plume_fields_series_start(r->fields, r->output_dir, "frames.pvd", "frame", -1.0, err)) != PLUME_OK ||
        (st = plume_frames_create(r->frames_path, r->scene->mesh->nv, r->ncons, r->scene->dt, scene, err)) !=
            PLUME_OK ||
        (st = plume_scene_materials_record(r->scene, r->frames_path, err)) != PLUME_OK)
        return st;
    return plume_run_write_frame(r, 0, 0, err);
}

plume_status plume_run_write_state(plume_run *r, const char *path, int create, plume_err *err)
{
    if (!r || !path || !*path)
        return plume_err_set(err, PLUME_EINVAL, "plume_run_write_state: a run and a path are required");
    if (!r->d)
        return plume_err_set(err, PLUME_EINVAL, "plume_run_write_state: a static scene's run has no frames file");
    const plume_mesh *m = r->scene->mesh;
    plume_status st;
    if (create) {
        char scene[4096 + 1024], dir[4096];
        absolute_scene(r, scene, sizeof scene);
        if (strlen(path) >= sizeof dir)
            return plume_err_set(err, PLUME_EINVAL, "frames file '%.64s...': the path is longer than %d bytes", path,
                                 (int)sizeof dir - 1);
        snprintf(dir, sizeof dir, "%s", path);
        char *slash = strrchr(dir, '/');
        if (slash && slash != dir) {
            *slash = '\0';
            if (plume_make_dirs(dir) != 0)
                return plume_err_set(err, PLUME_EIO, "frames file '%s': cannot create the directory '%s': %s", path, dir,
                                     strerror(errno));
        }
        if ((st = plume_frames_create(path, m->nv, r->ncons, r->scene->dt, scene, err)) != PLUME_OK ||
            (st = plume_scene_materials_record(r->scene, path, err)) != PLUME_OK) /* as the runner records them */
            return st;
    }
    plume_frame_array a[3];
    const int na = frame_arrays(r, a);
    if (na < 0)
        return plume_err_set(err, PLUME_ENOMEM, "frames file '%s': out of memory", path);
    return plume_frames_append_arrays(path, m->nv, r->ncons, plume_dynamics_time(r->d), r->rep.step,
                                      plume_dynamics_positions(r->d), plume_dynamics_velocities(r->d),
                                      plume_dynamics_multipliers(r->d, NULL), NULL, a, na, err);
}
