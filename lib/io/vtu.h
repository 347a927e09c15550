/** \file
 * plume: ParaView-ready output — VTK XML unstructured grids (.vtu, binary appended data, zlib
 * compressed) and the .pvd collection that gives a series its simulation times. A reader of the
 * same files serves the round-trip tests and anyone who wants the data back in C. */
#ifndef PLUME_VTU_H
#define PLUME_VTU_H

#include "../core/export.h"
#include "../core/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/** VTK cell types plume writes */
enum { PLUME_VTU_LINE = 3, PLUME_VTU_TRIANGLE = 5 };

/** A named array of n tuples of ncomp doubles (values[n * ncomp], tuple-major), borrowed. With
 * is_int != 0 the values are written as Int32 (they must be integers). */
typedef struct {
    const char *name;
    int ncomp;
    int is_int;
    const double *values;
} plume_vtu_field;

/** One grid to write, all borrowed: points[3 np]; ncells cells of one type (PLUME_VTU_LINE: 2
 * vertices, PLUME_VTU_TRIANGLE: 3) in cells[nodes * ncells]; fields on points (np tuples) and on
 * cells (ncells tuples); time is written as the field data "TimeValue". */
typedef struct {
    plume_index npoints;
    const double *points;
    int cell_type;
    plume_index ncells;
    const plume_index *cells;
    int npoint_fields, ncell_fields;
    const plume_vtu_field *point_fields, *cell_fields;
    double time;
} plume_vtu_grid;

/** Writes `path` (to "<path>.tmp.<pid>", then renamed: a reader never sees half a file).
 * PLUME_EINVAL for a bad grid (message naming what), PLUME_EIO naming the file, PLUME_ENOMEM. */
PLUME_API plume_status plume_vtu_write(const char *path, const plume_vtu_grid *g, plume_err *err);

/** A grid read back; everything owned (plume_vtu_data_free). Integer arrays come back as doubles. */
typedef struct {
    char *name;
    int ncomp;
    plume_index ntuples;
    double *values;
} plume_vtu_array;

typedef struct {
    plume_index npoints, ncells;
    double *points;            /**< [3 npoints] */
    plume_index *connectivity; /**< [nconnectivity] (the cells use offsets[ncells - 1] of them) */
    plume_index nconnectivity;
    plume_index *offsets;      /**< [ncells] end of each cell in connectivity */
    unsigned char *types;      /**< [ncells] VTK cell types */
    int npoint_arrays, ncell_arrays;
    plume_vtu_array *point_arrays, *cell_arrays;
    int has_time;
    double time;               /**< the "TimeValue" field data */
} plume_vtu_data;

/** Reads a .vtu with appended raw data, zlib-compressed or not, UInt32 or UInt64 headers (what
 * plume and ParaView write). PLUME_EIO (cannot open), PLUME_EFORMAT naming the file and what is
 * wrong, PLUME_ENOMEM. */
PLUME_API plume_status plume_vtu_read(const char *path, plume_vtu_data *out, plume_err *err);
PLUME_API void plume_vtu_data_free(plume_vtu_data *d);

/** The array called name among a grid's point (on_points != 0) or cell arrays, or NULL. */
PLUME_API const plume_vtu_array *plume_vtu_find(const plume_vtu_data *d, int on_points, const char *name);

/** A .pvd collection being written: (time, part, file) entries, the file path relative to the
 * .pvd's folder. Every plume_pvd_add rewrites the whole file atomically, so a run that stops
 * leaves a collection of the frames written so far. */
typedef struct plume_pvd plume_pvd;

/** Starts an empty collection at path (nothing is written until the first add). */
PLUME_API plume_status plume_pvd_create(const char *path, plume_pvd **out, plume_err *err);
PLUME_API void plume_pvd_destroy(plume_pvd **p);
PLUME_API plume_status plume_pvd_add(plume_pvd *p, double time, int part, const char *file, plume_err *err);

/** Reads a .pvd's entries (what plume_pvd_add wrote): n entries, times[n], parts[n], files[n]
 * (owned: plume_pvd_entries_free). PLUME_EIO / PLUME_EFORMAT naming the file. */
typedef struct {
    int n;
    double *times;
    int *parts;
    char **files;
} plume_pvd_entries;

PLUME_API plume_status plume_pvd_read(const char *path, plume_pvd_entries *out, plume_err *err);
PLUME_API void plume_pvd_entries_free(plume_pvd_entries *e);

#ifdef __cplusplus
}
#endif
#endif
