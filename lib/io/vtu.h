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

/** VTK cell types plume writes (VTK's own numbers). */
enum {
    PLUME_VTU_LINE = 3,    /**< a two-vertex line (VTK_LINE) */
    PLUME_VTU_TRIANGLE = 5 /**< a three-vertex triangle (VTK_TRIANGLE) */
};

/** A named array of n tuples of ncomp doubles (values[n * ncomp], tuple-major), borrowed. With
 * is_int != 0 the values are written as Int32 (they must be integers). */
typedef struct {
    const char *name;     /**< the array's name in ParaView */
    int ncomp;            /**< components per tuple (1 scalar, 3 vector, ...) */
    int is_int;           /**< != 0: written as Int32 */
    const double *values; /**< [n * ncomp] tuple-major */
} plume_vtu_field;

/** One grid to write, all borrowed: points[3 np]; ncells cells of one type (PLUME_VTU_LINE: 2
 * vertices, PLUME_VTU_TRIANGLE: 3) in cells[nodes * ncells]; fields on points (np tuples) and on
 * cells (ncells tuples); time is written as the field data "TimeValue". */
typedef struct {
    plume_index npoints;                  /**< np, the number of points */
    const double *points;                 /**< [3 np] coordinates (m) */
    int cell_type;                        /**< PLUME_VTU_LINE or PLUME_VTU_TRIANGLE */
    plume_index ncells;                   /**< number of cells */
    const plume_index *cells;             /**< [nodes * ncells] point ids of each cell */
    int npoint_fields;                    /**< entries of point_fields */
    int ncell_fields;                     /**< entries of cell_fields */
    const plume_vtu_field *point_fields;  /**< [npoint_fields], np tuples each */
    const plume_vtu_field *cell_fields;   /**< [ncell_fields], ncells tuples each */
    double time;                          /**< simulation time (s), the "TimeValue" field data */
} plume_vtu_grid;

/** Writes the grid to `path` through a temporary file (`path.tmp.PID`, renamed over it: a reader
 * never sees half a file).
 * PLUME_EINVAL for a bad grid (message naming what), PLUME_EIO naming the file, PLUME_ENOMEM. */
plume_status plume_vtu_write(const char *path, const plume_vtu_grid *g, plume_err *err);

/** A grid read back; everything owned (plume_vtu_data_free). Integer arrays come back as doubles. */
typedef struct {
    char *name;           /**< the array's name */
    int ncomp;            /**< components per tuple */
    plume_index ntuples;  /**< tuples (points or cells) */
    double *values;       /**< [ntuples * ncomp] tuple-major */
} plume_vtu_array;

/** A .vtu read by plume_vtu_read; every array owned, freed by plume_vtu_data_free. */
typedef struct {
    plume_index npoints;       /**< number of points */
    plume_index ncells;        /**< number of cells */
    double *points;            /**< [3 npoints] */
    plume_index *connectivity; /**< [nconnectivity] (the cells use offsets[ncells - 1] of them) */
    plume_index nconnectivity; /**< entries of connectivity */
    plume_index *offsets;      /**< [ncells] end of each cell in connectivity */
    unsigned char *types;      /**< [ncells] VTK cell types */
    int npoint_arrays;         /**< entries of point_arrays */
    int ncell_arrays;          /**< entries of cell_arrays */
    plume_vtu_array *point_arrays; /**< [npoint_arrays] the PointData arrays */
    plume_vtu_array *cell_arrays;  /**< [ncell_arrays] the CellData arrays */
    int has_time;              /**< 1 when the file carries a "TimeValue" */
    double time;               /**< the "TimeValue" field data */
} plume_vtu_data;

/** Reads a .vtu with appended raw data, zlib-compressed or not, UInt32 or UInt64 headers (what
 * plume and ParaView write). PLUME_EIO (cannot open), PLUME_EFORMAT naming the file and what is
 * wrong, PLUME_ENOMEM. */
plume_status plume_vtu_read(const char *path, plume_vtu_data *out, plume_err *err);
/** Frees everything plume_vtu_read allocated in d; NULL-safe. */
void plume_vtu_data_free(plume_vtu_data *d);

/** The array called name among a grid's point (on_points != 0) or cell arrays, or NULL. */
const plume_vtu_array *plume_vtu_find(const plume_vtu_data *d, int on_points, const char *name);

/** A .pvd collection being written: (time, part, file) entries, the file path relative to the
 * .pvd's folder. Every plume_pvd_add rewrites the whole file atomically, so a run that stops
 * leaves a collection of the frames written so far. */
typedef struct plume_pvd plume_pvd;

/** Starts an empty collection at path (nothing is written until the first add). */
plume_status plume_pvd_create(const char *path, plume_pvd **out, plume_err *err);
/** Frees the collection (the .pvd file stays as the last add wrote it); sets *p = NULL; NULL-safe. */
void plume_pvd_destroy(plume_pvd **p);
/** Adds the entry (time, part, file) and rewrites the .pvd with every entry so far (to a temporary
 * file renamed over it). PLUME_EINVAL for an empty file name, part < 0 or a non-finite time;
 * PLUME_EIO naming the file; PLUME_ENOMEM. */
plume_status plume_pvd_add(plume_pvd *p, double time, int part, const char *file, plume_err *err);

/** Reads a .pvd's entries (what plume_pvd_add wrote): n entries, times[n], parts[n], files[n]
 * (owned: plume_pvd_entries_free). PLUME_EIO / PLUME_EFORMAT naming the file. */
typedef struct {
    int n;          /**< number of entries */
    double *times;  /**< [n] simulation times (s) */
    int *parts;     /**< [n] part numbers */
    char **files;   /**< [n] .vtu paths as written, relative to the .pvd's folder */
} plume_pvd_entries;

/** Reads the entries of a .pvd into out, allocating its arrays (plume_pvd_entries_free).
 * PLUME_EIO when the file cannot be opened, PLUME_EFORMAT naming the file and line. */
plume_status plume_pvd_read(const char *path, plume_pvd_entries *out, plume_err *err);
/** Frees the arrays of e and zeroes it; NULL-safe. */
void plume_pvd_entries_free(plume_pvd_entries *e);

#ifdef __cplusplus
}
#endif
#endif
