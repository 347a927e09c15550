/* plume: VTK XML unstructured grids with zlib-compressed appended data, and .pvd collections. */
#include "vtu.h"
#include "input_file.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <zlib.h>

/* VTK's zlib blocks: 32 KiB of uncompressed data each (the size vtkXMLWriter uses). */
#define VTU_BLOCK 32768

static int host_little_endian(void)
{
    const uint16_t one = 1;
    unsigned char b;
    memcpy(&b, &one, 1);
    return b == 1;
}

/* ------------------------------------------------------------------------------------------ */
/* writing */

/* One appended array: the compression header [nblocks, block, last block, compressed sizes...]
 * (UInt64) followed by the compressed blocks. */
typedef struct {
    unsigned char *bytes;
    size_t len;
} packed;

static plume_status pack(const void *raw, size_t n, packed *out)
{
    size_t nblocks = (n + VTU_BLOCK - 1) / VTU_BLOCK, hdr = (3 + nblocks) * sizeof(uint64_t);
    size_t cap = hdr + nblocks * compressBound(VTU_BLOCK);
    out->bytes = malloc(cap + 1);
    out->len = 0;
    if (!out->bytes)
        return PLUME_ENOMEM;
    uint64_t h[3] = {nblocks, VTU_BLOCK, n % VTU_BLOCK};
    memcpy(out->bytes, h, sizeof h);
    size_t pos = hdr;
    for (size_t b = 0; b < nblocks; b++) {
        size_t len = b + 1 < nblocks || n % VTU_BLOCK == 0 ? VTU_BLOCK : n % VTU_BLOCK;
        uLongf clen = (uLongf)(cap - pos);
        /* level 1: doubles of a simulation barely compress further, and frames are written often */
        if (compress2(out->bytes + pos, &clen, (const Bytef *)raw + b * VTU_BLOCK, (uLong)len, 1) != Z_OK) {
            free(out->bytes);
            out->bytes = NULL;
            return PLUME_EDEP;
        }
        uint64_t c = clen;
        memcpy(out->bytes + (3 + b) * sizeof(uint64_t), &c, sizeof c);
        pos += clen;
    }
    out->len = pos;
    return PLUME_OK;
}

static void put_escaped(FILE *f, const char *s)
{
    for (; *s; s++) {
        switch (*s) {
        case '&': fputs("&amp;", f); break;
        case '<': fputs("&lt;", f); break;
        case '>': fputs("&gt;", f); break;
        case '"': fputs("&quot;", f); break;
        default: fputc(*s, f);
        }
    }
}

/* writes the DataArray tag of appended array k at offset *off, and advances it */
static void array_tag(FILE *f, const char *indent, const char *type, const char *name, int ncomp, const packed *p,
                      size_t *off)
{
    fprintf(f, "%s<DataArray type=\"%s\"", indent, type);
    if (name) {
        fputs(" Name=\"", f);
        put_escaped(f, name);
        fputc('"', f);
    }
    if (ncomp > 1)
        fprintf(f, " NumberOfComponents=\"%d\"", ncomp);
    fprintf(f, " format=\"appended\" offset=\"%zu\"/>\n", *off);
    *off += p->len;
}

static plume_status check_grid(const plume_vtu_grid *g, plume_err *err)
{
    if (g->npoints < 0 || g->ncells < 0 || (g->npoints > 0 && !g->points) || (g->ncells > 0 && !g->cells))
        return plume_err_set(err, PLUME_EINVAL, "vtu: invalid grid (points or cells missing)");
    if (g->cell_type != PLUME_VTU_LINE && g->cell_type != PLUME_VTU_TRIANGLE)
        return plume_err_set(err, PLUME_EINVAL, "vtu: cell type %d is not a line (3) or a triangle (5)", g->cell_type);
    int nodes = g->cell_type == PLUME_VTU_LINE ? 2 : 3;
    for (plume_index k = 0; k < nodes * g->ncells; k++)
        if (g->cells[k] < 0 || g->cells[k] >= g->npoints)
            return plume_err_set(err, PLUME_EINVAL, "vtu: cell %ld names vertex %ld, outside [0, %ld)", (long)(k / nodes),
                                 (long)g->cells[k], (long)g->npoints);
    for (int s = 0; s < 2; s++) {
        int n = s ? g->ncell_fields : g->npoint_fields;
        const plume_vtu_field *fl = s ? g->cell_fields : g->point_fields;
        if (n > 0 && !fl)
            return plume_err_set(err, PLUME_EINVAL, "vtu: %d %s fields but no array of them", n, s ? "cell" : "point");
        for (int i = 0; i < n; i++) {
            if (!fl[i].name || !*fl[i].name || fl[i].ncomp < 1 || fl[i].ncomp > 9 ||
                (!fl[i].values && (s ? g->ncells : g->npoints) > 0))
                return plume_err_set(err, PLUME_EINVAL, "vtu: %s field %d: a name, 1-9 components and values are needed",
                                     s ? "cell" : "point", i);
        }
    }
    return PLUME_OK;
}

/* The size of the scratch buffer that holds any one array of g before it is packed. */
static size_t largest_raw_array(const plume_vtu_grid *g, int nodes)
{
    size_t maxraw = (size_t)(nodes * g->ncells + 1) * sizeof(int64_t);
    if ((size_t)(3 * g->npoints + 1) * sizeof(double) > maxraw)
        maxraw = (size_t)(3 * g->npoints + 1) * sizeof(double);
    for (int s = 0; s < 2; s++)
        for (int i = 0; i < (s ? g->ncell_fields : g->npoint_fields); i++) {
            const plume_vtu_field *fl = s ? &g->cell_fields[i] : &g->point_fields[i];
            size_t need = (size_t)((s ? g->ncells : g->npoints) * fl->ncomp + 1) * sizeof(double);
            maxraw = need > maxraw ? need : maxraw;
        }
    return maxraw;
}

/* Every array of g compressed into pk, in the order their tags appear: time, point fields, cell
 * fields, points, connectivity, offsets, types (raw: scratch room for the largest). */
static plume_status pack_arrays(const plume_vtu_grid *g, int nodes, unsigned char *raw, packed *pk)
{
    int a = 0;
    plume_status st;
    if ((st = pack(&g->time, sizeof g->time, &pk[a++])) != PLUME_OK)
        return st;
    for (int s = 0; s < 2; s++) {
        plume_index n = s ? g->ncells : g->npoints;
        for (int i = 0; i < (s ? g->ncell_fields : g->npoint_fields); i++) {
            const plume_vtu_field *fl = s ? &g->cell_fields[i] : &g->point_fields[i];
            size_t cnt = (size_t)n * (size_t)fl->ncomp;
            if (fl->is_int) {
                int32_t *v = (int32_t *)raw;
                for (size_t k = 0; k < cnt; k++)
                    v[k] = (int32_t)fl->values[k];
                st = pack(raw, cnt * sizeof *v, &pk[a++]);
            } else {
                st = pack(fl->values, cnt * sizeof(double), &pk[a++]);
            }
            if (st != PLUME_OK)
                return st;
        }
    }
    if ((st = pack(g->points, (size_t)(3 * g->npoints) * sizeof(double), &pk[a++])) != PLUME_OK)
        return st;
    int64_t *iv = (int64_t *)raw;
    for (plume_index k = 0; k < nodes * g->ncells; k++)
        iv[k] = g->cells[k];
    if ((st = pack(raw, (size_t)(nodes * g->ncells) * sizeof *iv, &pk[a++])) != PLUME_OK)
        return st;
    for (plume_index c = 0; c < g->ncells; c++)
        iv[c] = (int64_t)nodes * (c + 1);
    if ((st = pack(raw, (size_t)g->ncells * sizeof *iv, &pk[a++])) != PLUME_OK)
        return st;
    memset(raw, g->cell_type, (size_t)g->ncells);
    return pack(raw, (size_t)g->ncells, &pk[a++]);
}

/* The XML of g with its narr packed arrays pk appended. */
static void put_vtu(FILE *f, const plume_vtu_grid *g, const packed *pk, int narr)
{
    fprintf(f, "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"%s\" "
               "header_type=\"UInt64\" compressor=\"vtkZLibDataCompressor\">\n  <UnstructuredGrid>\n",
            host_little_endian() ? "LittleEndian" : "BigEndian");
    size_t off = 0;
    int a = 0;
    fputs("    <FieldData>\n", f);
    fputs("      <DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\"", f);
    fprintf(f, " format=\"appended\" offset=\"%zu\"/>\n    </FieldData>\n", off);
    off += pk[a++].len;
    fprintf(f, "    <Piece NumberOfPoints=\"%ld\" NumberOfCells=\"%ld\">\n", (long)g->npoints, (long)g->ncells);
    for (int s = 0; s < 2; s++) {
        int n = s ? g->ncell_fields : g->npoint_fields;
        const plume_vtu_field *fl = s ? g->cell_fields : g->point_fields;
        fputs(s ? "      <CellData>\n" : "      <PointData>\n", f);
        for (int i = 0; i < n; i++)
            array_tag(f, "        ", fl[i].is_int ? "Int32" : "Float64", fl[i].name, fl[i].ncomp, &pk[a++], &off);
        fputs(s ? "      </CellData>\n" : "      </PointData>\n", f);
    }
    fputs("      <Points>\n", f);
    array_tag(f, "        ", "Float64", "Points", 3, &pk[a++], &off);
    fputs("      </Points>\n      <Cells>\n", f);
    array_tag(f, "        ", "Int64", "connectivity", 1, &pk[a++], &off);
    array_tag(f, "        ", "Int64", "offsets", 1, &pk[a++], &off);
    array_tag(f, "        ", "UInt8", "types", 1, &pk[a++], &off);
    fputs("      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n  <AppendedData encoding=\"raw\">\n   _", f);
    for (int k = 0; k < narr; k++)
        fwrite(pk[k].bytes, 1, pk[k].len, f);
    fputs("\n  </AppendedData>\n</VTKFile>\n", f);
}

plume_status plume_vtu_write(const char *path, const plume_vtu_grid *g, plume_err *err)
{
    if (!path || !*path || !g)
        return plume_err_set(err, PLUME_EINVAL, "vtu: invalid arguments (path, grid)");
    plume_status st = check_grid(g, err);
    if (st != PLUME_OK)
        return st;
    const int nodes = g->cell_type == PLUME_VTU_LINE ? 2 : 3;
    const int narr = 5 + g->npoint_fields + g->ncell_fields; /* time, fields, points, 3 cell arrays */
    packed *pk = calloc((size_t)narr, sizeof *pk);
    unsigned char *raw = malloc(largest_raw_array(g, nodes));
    char *tmp = malloc(strlen(path) + 32);
    FILE *f = NULL;
    if (!pk || !raw || !tmp) {
        st = plume_err_set(err, PLUME_ENOMEM, "vtu '%s': out of memory", path);
        goto cleanup;
    }
    if ((st = pack_arrays(g, nodes, raw, pk)) != PLUME_OK) {
        st = plume_err_set(err, st, "vtu '%s': %s while compressing", path,
                           st == PLUME_ENOMEM ? "out of memory" : "zlib failed");
        goto cleanup;
    }
    /* written under a temporary name, then renamed over path: a reader never sees half a file */
    snprintf(tmp, strlen(path) + 32, "%s.tmp.%ld", path, (long)getpid());
    if (!(f = fopen(tmp, "wb"))) {
        st = plume_err_set(err, PLUME_EIO, "vtu '%s': cannot create '%s': %s", path, tmp, strerror(errno));
        goto cleanup;
    }
    put_vtu(f, g, pk, narr);
    int bad = ferror(f);
    if (fclose(f) != 0 || bad)
        st = plume_err_set(err, PLUME_EIO, "vtu '%s': cannot write '%s': %s", path, tmp, strerror(errno));
    else if (rename(tmp, path) != 0)
        st = plume_err_set(err, PLUME_EIO, "vtu '%s': cannot rename '%s' over it: %s", path, tmp, strerror(errno));
    if (st != PLUME_OK)
        unlink(tmp);
cleanup:
    for (int k = 0; pk && k < narr; k++)
        free(pk[k].bytes);
    free(pk);
    free(raw);
    free(tmp);
    return st;
}

/* ------------------------------------------------------------------------------------------ */
/* reading */

typedef struct {
    const char *path;
    const unsigned char *buf, *data; /* the file; the appended data after its '_' */
    size_t len, data_len;
    int header64, compressed;
} reader;

/* the value of attribute `name` in the tag [tag, end) into out (size n); 0 if absent */
static int attr(const char *tag, const char *end, const char *name, char *out, size_t n)
{
    size_t ln = strlen(name);
    for (const char *p = tag; p + ln + 2 < end; p++) {
        if ((p == tag || p[-1] == ' ' || p[-1] == '\n' || p[-1] == '\t') && strncmp(p, name, ln) == 0 &&
            p[ln] == '=' && p[ln + 1] == '"') {
            const char *v = p + ln + 2, *q = memchr(v, '"', (size_t)(end - v));
            if (!q || (size_t)(q - v) >= n)
                return 0;
            memcpy(out, v, (size_t)(q - v));
            out[q - v] = '\0';
            return 1;
        }
    }
    return 0;
}

static size_t type_size(const char *t)
{
    if (!strcmp(t, "Float64") || !strcmp(t, "Int64") || !strcmp(t, "UInt64"))
        return 8;
    if (!strcmp(t, "Float32") || !strcmp(t, "Int32") || !strcmp(t, "UInt32"))
        return 4;
    if (!strcmp(t, "Int16") || !strcmp(t, "UInt16"))
        return 2;
    if (!strcmp(t, "Int8") || !strcmp(t, "UInt8"))
        return 1;
    return 0;
}

static double element(const unsigned char *p, const char *t)
{
    if (!strcmp(t, "Float64")) { double v; memcpy(&v, p, 8); return v; }
    if (!strcmp(t, "Float32")) { float v; memcpy(&v, p, 4); return v; }
    if (!strcmp(t, "Int64")) { int64_t v; memcpy(&v, p, 8); return (double)v; }
    if (!strcmp(t, "UInt64")) { uint64_t v; memcpy(&v, p, 8); return (double)v; }
    if (!strcmp(t, "Int32")) { int32_t v; memcpy(&v, p, 4); return v; }
    if (!strcmp(t, "UInt32")) { uint32_t v; memcpy(&v, p, 4); return v; }
    if (!strcmp(t, "Int16")) { int16_t v; memcpy(&v, p, 2); return v; }
    if (!strcmp(t, "UInt16")) { uint16_t v; memcpy(&v, p, 2); return v; }
    if (!strcmp(t, "Int8")) return (double)(int8_t)*p;
    return (double)*p;
}

static uint64_t header_word(const reader *r, size_t at)
{
    if (r->header64) {
        uint64_t v;
        memcpy(&v, r->data + at * 8, 8);
        return v;
    }
    uint32_t v;
    memcpy(&v, r->data + at * 4, 4);
    return v;
}

/* The raw bytes of the appended array at `offset` into *out (malloc'ed), *n bytes. */
static plume_status read_block(const reader *r, size_t offset, unsigned char **out, size_t *n, plume_err *err)
{
    const size_t w = r->header64 ? 8 : 4;
    *out = NULL;
    if (offset > r->data_len || r->data_len - offset < w) /* offset + w could wrap */
        return plume_err_set(err, PLUME_EFORMAT, "vtu '%s': an array's offset %zu lies past the appended data", r->path, offset);
    reader sub = *r;
    sub.data = r->data + offset;
    sub.data_len = r->data_len - offset;
    if (!r->compressed) {
        size_t len = (size_t)header_word(&sub, 0);
        if (len > sub.data_len - w)
            return plume_err_set(err, PLUME_EFORMAT, "vtu '%s': an array at offset %zu is cut short", r->path, offset);
        *out = malloc(len + 1);
        if (!*out)
            return PLUME_ENOMEM;
        memcpy(*out, sub.data + w, len);
        *n = len;
        return PLUME_OK;
    }
    if (3 * w > sub.data_len)
        return plume_err_set(err, PLUME_EFORMAT, "vtu '%s': a compression header at offset %zu is cut short", r->path, offset);
    uint64_t nb64 = header_word(&sub, 0), bs64 = header_word(&sub, 1), last64 = header_word(&sub, 2);
    /* zlib expands a block at most ~1032 times: sizes beyond that, or past the data, are lies */
    const uint64_t max_block = (uint64_t)1 << 31;
    if (nb64 > sub.data_len / w || (3 + nb64) * w > sub.data_len || (nb64 > 0 && bs64 == 0) || bs64 > max_block ||
        last64 > bs64)
        return plume_err_set(err, PLUME_EFORMAT, "vtu '%s': a bad compression header at offset %zu", r->path, offset);
    size_t nb = (size_t)nb64, bs = (size_t)bs64, last = (size_t)last64;
    size_t total = nb == 0 ? 0 : (nb - 1) * bs + (last ? last : bs);
    if (total / 1100 > sub.data_len)
        return plume_err_set(err, PLUME_EFORMAT, "vtu '%s': the array at offset %zu claims %zu bytes from %zu compressed",
                             r->path, offset, total, sub.data_len);
    *out = malloc(total + 1);
    if (!*out)
        return PLUME_ENOMEM;
    size_t pos = (3 + nb) * w;
    for (size_t b = 0; b < nb; b++) {
        size_t clen = (size_t)header_word(&sub, 3 + b), want = b + 1 < nb ? bs : (last ? last : bs);
        uLongf got = (uLongf)want;
        if (clen > sub.data_len - pos ||
            uncompress(*out + b * bs, &got, sub.data + pos, (uLong)clen) != Z_OK || got != want) {
            free(*out);
            *out = NULL;
            return plume_err_set(err, PLUME_EFORMAT, "vtu '%s': block %zu of the array at offset %zu does not decompress",
                                 r->path, b, offset);
        }
        pos += clen;
    }
    *n = total;
    return PLUME_OK;
}

void plume_vtu_data_free(plume_vtu_data *d)
{
    if (!d)
        return;
    for (int s = 0; s < 2; s++) {
        plume_vtu_array *a = s ? d->cell_arrays : d->point_arrays;
        int n = s ? d->ncell_arrays : d->npoint_arrays;
        for (int i = 0; a && i < n; i++) {
            free(a[i].name);
            free(a[i].values);
        }
        free(a);
    }
    free(d->points);
    free(d->connectivity);
    free(d->offsets);
    free(d->types);
    memset(d, 0, sizeof *d);
}

const plume_vtu_array *plume_vtu_find(const plume_vtu_data *d, int on_points, const char *name)
{
    if (!d || !name)
        return NULL;
    int n = on_points ? d->npoint_arrays : d->ncell_arrays;
    const plume_vtu_array *a = on_points ? d->point_arrays : d->cell_arrays;
    for (int i = 0; i < n; i++)
        if (a[i].name && strcmp(a[i].name, name) == 0)
            return &a[i];
    return NULL;
}

enum { SEC_NONE, SEC_POINTDATA, SEC_CELLDATA, SEC_POINTS, SEC_CELLS, SEC_FIELD };

/* one DataArray tag [tag, end) of section sec: decoded into d */
/* A DataArray's values as doubles (*v, *cnt of them, malloc'ed), its name and components, from its
 * tag's attributes and its appended block. */
static plume_status decode_array(const reader *r, const char *tag, const char *end, char name[256], int *ncomp,
                                 double **v, size_t *cnt, plume_err *err)
{
    char type[32], sval[64], fmt[32], ncs[32];
    if (!attr(tag, end, "type", type, sizeof type) || !type_size(type))
        return plume_err_set(err, PLUME_EFORMAT, "vtu '%s': a DataArray without a known type", r->path);
    attr(tag, end, "Name", name, 256);
    if (!attr(tag, end, "format", fmt, sizeof fmt) || strcmp(fmt, "appended") != 0)
        return plume_err_set(err, PLUME_EFORMAT, "vtu '%s': array '%s' is not in appended format (only appended is read)",
                             r->path, name);
    if (!attr(tag, end, "offset", sval, sizeof sval))
        return plume_err_set(err, PLUME_EFORMAT, "vtu '%s': array '%s' has no offset", r->path, name);
    *ncomp = attr(tag, end, "NumberOfComponents", ncs, sizeof ncs) ? atoi(ncs) : 1;
    if (*ncomp < 1)
        return plume_err_set(err, PLUME_EFORMAT, "vtu '%s': array '%s' has %d components", r->path, name, *ncomp);
    unsigned char *bytes;
    size_t n = 0, es = type_size(type);
    plume_status st = read_block(r, (size_t)strtoull(sval, NULL, 10), &bytes, &n, err);
    if (st != PLUME_OK)
        return st;
    *cnt = n / es;
    if (n % es != 0) {
        free(bytes);
        return plume_err_set(err, PLUME_EFORMAT, "vtu '%s': array '%s' holds %zu bytes, not whole %s values", r->path, name,
                             n, type);
    }
    *v = malloc((*cnt + 1) * sizeof **v);
    if (!*v) {
        free(bytes);
        return PLUME_ENOMEM;
    }
    for (size_t k = 0; k < *cnt; k++)
        (*v)[k] = element(bytes + k * es, type);
    free(bytes);
    return PLUME_OK;
}

/* A Cells array (types, connectivity, offsets) into d, as integers; v is freed. */
static plume_status store_cells(const reader *r, const char *name, double *v, size_t cnt, plume_vtu_data *d,
                                plume_err *err)
{
    plume_index *iv = NULL;
    if (strcmp(name, "types") == 0 || strcmp(name, "connectivity") == 0 || strcmp(name, "offsets") == 0) {
        /* these become integers: a value out of range or fractional is refused (a cast of 2.6e10
         * to a cell type was undefined behaviour: found by fuzzing) */
        const double max = name[0] == 't' ? 255.0 : 9007199254740992.0; /* a byte; 2^53 */
        for (size_t k = 0; k < cnt; k++)
            if (!(v[k] >= 0.0 && v[k] <= max) || v[k] != floor(v[k])) {
                const double bad = v[k];
                free(v);
                return plume_err_set(err, PLUME_EFORMAT, "vtu '%s': %s[%zu] = %g is not an integer in [0, %.0f]",
                                     r->path, name, k, bad, max);
            }
    }
    if (strcmp(name, "types") == 0) {
        free(d->types);
        d->types = malloc(cnt + 1);
        for (size_t k = 0; d->types && k < cnt; k++)
            d->types[k] = (unsigned char)v[k];
    } else if (strcmp(name, "connectivity") == 0 || strcmp(name, "offsets") == 0) {
        iv = malloc((cnt + 1) * sizeof *iv);
        for (size_t k = 0; iv && k < cnt; k++)
            iv[k] = (plume_index)v[k];
        if (name[0] == 'c')
            free(d->connectivity), d->connectivity = iv, d->nconnectivity = (plume_index)cnt;
        else
            free(d->offsets), d->offsets = iv;
    }
    if ((strcmp(name, "offsets") == 0 || strcmp(name, "types") == 0) && cnt != (size_t)d->ncells) {
        free(v);
        return plume_err_set(err, PLUME_EFORMAT, "vtu '%s': %zu %s for %ld cells", r->path, cnt, name,
                             (long)d->ncells);
    }
    free(v);
    return PLUME_OK;
}

/* A PointData or CellData array appended to d's list (v is kept by it, or freed on failure). */
static plume_status store_data_array(const reader *r, const char *name, int ncomp, int on_points, double *v,
                                     size_t cnt, plume_vtu_data *d, plume_err *err)
{
    plume_index nt = on_points ? d->npoints : d->ncells;
    if (cnt != (size_t)nt * (size_t)ncomp) {
        free(v);
        return plume_err_set(err, PLUME_EFORMAT, "vtu '%s': array '%s' holds %zu values, not %ld x %d", r->path, name, cnt,
                             (long)nt, ncomp);
    }
    plume_vtu_array **arr = on_points ? &d->point_arrays : &d->cell_arrays;
    int *na = on_points ? &d->npoint_arrays : &d->ncell_arrays;
    plume_vtu_array *grown = realloc(*arr, (size_t)(*na + 1) * sizeof **arr);
    if (!grown) {
        free(v);
        return PLUME_ENOMEM;
    }
    *arr = grown;
    grown[*na].name = strdup(name);
    grown[*na].ncomp = ncomp;
    grown[*na].ntuples = nt;
    grown[*na].values = v;
    (*na)++;
    return grown[*na - 1].name ? PLUME_OK : PLUME_ENOMEM;
}

static plume_status read_array(const reader *r, const char *tag, const char *end, int sec, plume_vtu_data *d,
                               plume_err *err)
{
    char name[256] = "";
    int ncomp = 1;
    double *v = NULL;
    size_t cnt = 0;
    plume_status st = decode_array(r, tag, end, name, &ncomp, &v, &cnt, err);
    if (st != PLUME_OK)
        return st;
    if (sec == SEC_FIELD) {
        if (strcmp(name, "TimeValue") == 0 && cnt >= 1)
            d->has_time = 1, d->time = v[0];
        free(v);
        return PLUME_OK;
    }
    if (sec == SEC_POINTS) {
        if (ncomp != 3 || cnt != (size_t)(3 * d->npoints)) {
            free(v);
            return plume_err_set(err, PLUME_EFORMAT, "vtu '%s': Points hold %zu values for %ld points", r->path, cnt,
                                 (long)d->npoints);
        }
        free(d->points); /* a second Points array replaces the first */
        d->points = v;
        return PLUME_OK;
    }
    if (sec == SEC_CELLS)
        return store_cells(r, name, v, cnt, d, err);
    return store_data_array(r, name, ncomp, sec == SEC_POINTDATA, v, cnt, d, err);
}

/* The whole file f (closed here) into *buf (malloc'ed, NUL-terminated), *len bytes. */
static plume_status read_whole(const char *path, FILE *f, unsigned char **buf_out, size_t *len_out, plume_err *err)
{
    unsigned char *buf = NULL;
    size_t len = 0, cap = 0;
    for (;;) {
        if (len + 65536 + 1 > cap) {
            cap = 2 * cap + 65536 + 1;
            unsigned char *nb = realloc(buf, cap);
            if (!nb) {
                free(buf);
                fclose(f);
                return PLUME_ENOMEM;
            }
            buf = nb;
        }
        size_t got = fread(buf + len, 1, 65536, f);
        len += got;
        if (got == 0)
            break;
    }
    int rerr = ferror(f);
    fclose(f);
    if (rerr) {
        free(buf);
        return plume_err_set(err, PLUME_EIO, "vtu '%s': read error", path);
    }
    buf[len] = '\0';
    *buf_out = buf, *len_out = len;
    return PLUME_OK;
}

/* The <VTKFile> element (ending at *vfe) of an UnstructuredGrid in this machine's byte order, its
 * header width and compressor into r, and where the appended data (app) starts. */
static plume_status read_vtkfile(reader *r, const char *xml_end, const char *app, const char **vfe_out, plume_err *err)
{
    const char *s = (const char *)r->buf, *path = r->path;
    char v[64];
    const char *vf = strstr(s, "<VTKFile");
    if (!vf || vf > xml_end)
        return plume_err_set(err, PLUME_EFORMAT, "vtu '%s': no <VTKFile> element", path);
    const char *vfe = strchr(vf, '>');
    if (!attr(vf, vfe, "type", v, sizeof v) || strcmp(v, "UnstructuredGrid") != 0)
        return plume_err_set(err, PLUME_EFORMAT, "vtu '%s': not an UnstructuredGrid file", path);
    if (attr(vf, vfe, "byte_order", v, sizeof v) && (strcmp(v, "LittleEndian") == 0) != host_little_endian())
        return plume_err_set(err, PLUME_EFORMAT, "vtu '%s': byte order %s differs from this machine's", path, v);
    r->header64 = attr(vf, vfe, "header_type", v, sizeof v) && strcmp(v, "UInt64") == 0;
    r->compressed = attr(vf, vfe, "compressor", v, sizeof v);
    if (r->compressed && strcmp(v, "vtkZLibDataCompressor") != 0)
        return plume_err_set(err, PLUME_EFORMAT, "vtu '%s': compressor %s (only zlib is read)", path, v);
    if (!app)
        return plume_err_set(err, PLUME_EFORMAT, "vtu '%s': no <AppendedData> (only appended data is read)", path);
    const char *us = strchr(app, '_');
    if (!us)
        return plume_err_set(err, PLUME_EFORMAT, "vtu '%s': <AppendedData> without its '_' marker", path);
    r->data = (const unsigned char *)us + 1;
    r->data_len = r->len - (size_t)(r->data - r->buf);
    *vfe_out = vfe;
    return PLUME_OK;
}

/* The tags from `from` to xml_end: the one Piece's counts and every DataArray of a section. */
static plume_status read_tags(const reader *r, const char *from, const char *xml_end, plume_vtu_data *out,
                              plume_err *err)
{
    const char *path = r->path;
    plume_status st = PLUME_OK;
    int sec = SEC_NONE, pieces = 0;
    for (const char *p = strchr(from, '<'); p && p < xml_end && st == PLUME_OK; p = strchr(p + 1, '<')) {
        const char *e = strchr(p, '>');
        if (!e || e > xml_end) {
            st = plume_err_set(err, PLUME_EFORMAT, "vtu '%s': a tag is not closed", path);
            break;
        }
        static const struct { const char *tag; int sec; } secs[] = {
            {"PointData", SEC_POINTDATA}, {"CellData", SEC_CELLDATA}, {"Points", SEC_POINTS}, {"Cells", SEC_CELLS},
            {"FieldData", SEC_FIELD}};
        int closing = p[1] == '/';
        const char *nm = p + 1 + closing;
        for (size_t k = 0; k < sizeof secs / sizeof *secs; k++) {
            size_t l = strlen(secs[k].tag);
            if (strncmp(nm, secs[k].tag, l) == 0 && (nm[l] == '>' || nm[l] == ' ' || nm[l] == '/' || nm[l] == '\n'))
                sec = closing || e[-1] == '/' ? SEC_NONE : secs[k].sec;
        }
        if (!closing && strncmp(nm, "Piece", 5) == 0 && (nm[5] == ' ' || nm[5] == '>')) {
            if (++pieces > 1) {
                st = plume_err_set(err, PLUME_EFORMAT, "vtu '%s': more than one Piece (only one is read)", path);
                break;
            }
            char a1[32], a2[32];
            if (!attr(p, e, "NumberOfPoints", a1, sizeof a1) || !attr(p, e, "NumberOfCells", a2, sizeof a2)) {
                st = plume_err_set(err, PLUME_EFORMAT, "vtu '%s': Piece without NumberOfPoints/NumberOfCells", path);
                break;
            }
            out->npoints = atol(a1), out->ncells = atol(a2);
            if (out->npoints < 0 || out->ncells < 0)
                st = plume_err_set(err, PLUME_EFORMAT, "vtu '%s': negative point or cell count", path);
        } else if (!closing && strncmp(nm, "DataArray", 9) == 0 && sec != SEC_NONE) {
            st = read_array(r, p, e, sec, out, err);
        }
    }
    if (st == PLUME_OK && !pieces)
        st = plume_err_set(err, PLUME_EFORMAT, "vtu '%s': no Piece", path);
    return st;
}

/* The grid read is whole: its Points and Cells arrays present, the offsets rising within the
 * connectivity, which names real points. */
static plume_status check_read_grid(const char *path, const plume_vtu_data *out, plume_err *err)
{
    plume_status st = PLUME_OK;
    if ((!out->points || !out->offsets || !out->types || !out->connectivity) && (out->npoints > 0 || out->ncells > 0))
        return plume_err_set(err, PLUME_EFORMAT, "vtu '%s': Points or Cells arrays are missing", path);
    if (out->ncells > 0) {
        plume_index prev = 0, nconn = out->offsets[out->ncells - 1];
        if (nconn > out->nconnectivity)
            st = plume_err_set(err, PLUME_EFORMAT, "vtu '%s': the cells end at %ld, past the %ld connectivity entries",
                               path, (long)nconn, (long)out->nconnectivity);
        for (plume_index c = 0; c < out->ncells && st == PLUME_OK; c++) {
            if (out->offsets[c] < prev)
                st = plume_err_set(err, PLUME_EFORMAT, "vtu '%s': cell offsets decrease at cell %ld", path, (long)c);
            prev = out->offsets[c];
        }
        for (plume_index k = 0; k < nconn && st == PLUME_OK; k++)
            if (out->connectivity[k] < 0 || out->connectivity[k] >= out->npoints)
                st = plume_err_set(err, PLUME_EFORMAT, "vtu '%s': connectivity names point %ld of %ld", path,
                                   (long)out->connectivity[k], (long)out->npoints);
    }
    return st;
}

plume_status plume_vtu_read(const char *path, plume_vtu_data *out, plume_err *err)
{
    if (!path || !out)
        return plume_err_set(err, PLUME_EINVAL, "vtu: invalid arguments");
    memset(out, 0, sizeof *out);
    FILE *f = plume_input_fopen(path, "rb", "vtu", err);
    if (!f)
        return PLUME_EIO;
    unsigned char *buf = NULL;
    size_t len = 0;
    plume_status st = read_whole(path, f, &buf, &len, err);
    if (st != PLUME_OK)
        return st;
    reader r = {path, buf, NULL, len, 0, 1, 0};
    const char *s = (const char *)buf;
    const char *app = strstr(s, "<AppendedData");
    const char *xml_end = app ? app : s + strlen(s), *vfe = NULL;
    if ((st = read_vtkfile(&r, xml_end, app, &vfe, err)) == PLUME_OK &&
        (st = read_tags(&r, vfe, xml_end, out, err)) == PLUME_OK)
        st = check_read_grid(path, out, err);
    free(buf);
    if (st != PLUME_OK)
        plume_vtu_data_free(out);
    return st;
}

/* ------------------------------------------------------------------------------------------ */
/* .pvd collections */

struct plume_pvd {
    char *path;
    int n, cap;
    double *times;
    int *parts;
    char **files;
};

plume_status plume_pvd_create(const char *path, plume_pvd **out, plume_err *err)
{
    if (!path || !*path || !out)
        return plume_err_set(err, PLUME_EINVAL, "pvd: invalid arguments");
    *out = calloc(1, sizeof **out);
    if (!*out || !((*out)->path = strdup(path))) {
        free(*out);
        *out = NULL;
        return plume_err_set(err, PLUME_ENOMEM, "pvd '%s': out of memory", path);
    }
    return PLUME_OK;
}

void plume_pvd_destroy(plume_pvd **pp)
{
    if (!pp || !*pp)
        return;
    plume_pvd *p = *pp;
    for (int i = 0; i < p->n; i++)
        free(p->files[i]);
    free(p->files);
    free(p->times);
    free(p->parts);
    free(p->path);
    free(p);
    *pp = NULL;
}

plume_status plume_pvd_add(plume_pvd *p, double time, int part, const char *file, plume_err *err)
{
    if (!p || !file || !*file || part < 0 || !isfinite(time))
        return plume_err_set(err, PLUME_EINVAL, "pvd: invalid entry (file, part >= 0, finite time)");
    if (p->n == p->cap) {
        int cap = 2 * p->cap + 16;
        double *t = realloc(p->times, (size_t)cap * sizeof *t);
        if (t)
            p->times = t;
        int *pa = realloc(p->parts, (size_t)cap * sizeof *pa);
        if (pa)
            p->parts = pa;
        char **fl = realloc(p->files, (size_t)cap * sizeof *fl);
        if (fl)
            p->files = fl;
        if (!t || !pa || !fl)
            return plume_err_set(err, PLUME_ENOMEM, "pvd '%s': out of memory", p->path);
        p->cap = cap;
    }
    if (!(p->files[p->n] = strdup(file)))
        return plume_err_set(err, PLUME_ENOMEM, "pvd '%s': out of memory", p->path);
    p->times[p->n] = time;
    p->parts[p->n] = part;
    p->n++;
    size_t len = strlen(p->path) + 32;
    char *tmp = malloc(len);
    if (!tmp)
        return plume_err_set(err, PLUME_ENOMEM, "pvd '%s': out of memory", p->path);
    snprintf(tmp, len, "%s.tmp.%ld", p->path, (long)getpid());
    FILE *f = fopen(tmp, "w");
    plume_status st = PLUME_OK;
    if (!f) {
        st = plume_err_set(err, PLUME_EIO, "pvd '%s': cannot create '%s': %s", p->path, tmp, strerror(errno));
        free(tmp);
        return st;
    }
    fputs("<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"1.0\">\n  <Collection>\n", f);
    for (int i = 0; i < p->n; i++) {
        fprintf(f, "    <DataSet timestep=\"%.17g\" part=\"%d\" file=\"", p->times[i], p->parts[i]);
        put_escaped(f, p->files[i]);
        fputs("\"/>\n", f);
    }
    fputs("  </Collection>\n</VTKFile>\n", f);
    int bad = ferror(f);
    if (fclose(f) != 0 || bad)
        st = plume_err_set(err, PLUME_EIO, "pvd '%s': cannot write '%s': %s", p->path, tmp, strerror(errno));
    else if (rename(tmp, p->path) != 0)
        st = plume_err_set(err, PLUME_EIO, "pvd '%s': cannot rename '%s' over it: %s", p->path, tmp, strerror(errno));
    if (st != PLUME_OK)
        unlink(tmp);
    free(tmp);
    return st;
}

void plume_pvd_entries_free(plume_pvd_entries *e)
{
    if (!e)
        return;
    for (int i = 0; e->files && i < e->n; i++)
        free(e->files[i]);
    free(e->files);
    free(e->times);
    free(e->parts);
    memset(e, 0, sizeof *e);
}

/* undoes put_escaped in place */
static void unescape(char *s)
{
    static const struct { const char *ent; char c; } ents[] = {{"&amp;", '&'}, {"&lt;", '<'}, {"&gt;", '>'}, {"&quot;", '"'}};
    char *w = s;
    for (const char *r = s; *r;) {
        size_t k;
        for (k = 0; k < 4; k++)
            if (strncmp(r, ents[k].ent, strlen(ents[k].ent)) == 0)
                break;
        if (k < 4) {
            *w++ = ents[k].c;
            r += strlen(ents[k].ent);
        } else {
            *w++ = *r++;
        }
    }
    *w = '\0';
}

plume_status plume_pvd_read(const char *path, plume_pvd_entries *out, plume_err *err)
{
    if (!path || !out)
        return plume_err_set(err, PLUME_EINVAL, "pvd: invalid arguments");
    memset(out, 0, sizeof *out);
    FILE *f = plume_input_fopen(path, "r", "pvd", err);
    if (!f)
        return PLUME_EIO;
    char line[8192];
    int lineno = 0, cap = 0, collection = 0;
    plume_status st = PLUME_OK;
    while (st == PLUME_OK && fgets(line, sizeof line, f)) {
        lineno++;
        if (strstr(line, "type=\"Collection\""))
            collection = 1;
        char *ds = strstr(line, "<DataSet");
        if (!ds)
            continue;
        char *e = strchr(ds, '>');
        char ts[64], ps[32], file[4096];
        if (!e || !attr(ds, e, "timestep", ts, sizeof ts) || !attr(ds, e, "file", file, sizeof file)) {
            st = plume_err_set(err, PLUME_EFORMAT, "pvd '%s':%d: a DataSet needs timestep and file", path, lineno);
            break;
        }
        char *endp;
        double t = strtod(ts, &endp);
        if (endp == ts || *endp) {
            st = plume_err_set(err, PLUME_EFORMAT, "pvd '%s':%d: timestep '%s' is not a number", path, lineno, ts);
            break;
        }
        if (out->n == cap) {
            cap = 2 * cap + 16;
            double *tt = realloc(out->times, (size_t)cap * sizeof *tt);
            if (tt)
                out->times = tt;
            int *pp = realloc(out->parts, (size_t)cap * sizeof *pp);
            if (pp)
                out->parts = pp;
            char **ff = realloc(out->files, (size_t)cap * sizeof *ff);
            if (ff)
                out->files = ff;
            if (!tt || !pp || !ff) {
                st = PLUME_ENOMEM;
                break;
            }
        }
        unescape(file);
        if (!(out->files[out->n] = strdup(file))) {
            st = PLUME_ENOMEM;
            break;
        }
        out->times[out->n] = t;
        out->parts[out->n] = attr(ds, e, "part", ps, sizeof ps) ? atoi(ps) : 0;
        out->n++;
    }
    fclose(f);
    if (st == PLUME_OK && !collection)
        st = plume_err_set(err, PLUME_EFORMAT, "pvd '%s': not a VTK Collection file", path);
    if (st != PLUME_OK)
        plume_pvd_entries_free(out);
    return st;
}
