/** \file
 * plume: traction-sample geometries from JSON (supplementary Table 1 ships in data/samples.json). */
#ifndef PLUME_SAMPLE_H
#define PLUME_SAMPLE_H

#include "../core/export.h"
#include "../core/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/** One traction sample's geometry, as read from the samples file (SI units). */
typedef struct {
    char id[32];        /**< e.g., "L01" (longitudinal) or "T07" (transverse) */
    char scenario[32];  /**< "longitudinal" | "transverse" | "tilted" */
    double lx;          /**< width across the pull (m; the file's lx_mm) */
    double ly;          /**< length along the pull, between the grips (m; the file's ly_mm) */
    double h;           /**< thickness (m; the file's h_um) */
} plume_sample;

/** Finds sample `id` in a JSON file of the form
 *
 *     {"samples": [{"id": "L01", "scenario": "longitudinal", "lx_mm": 9, "ly_mm": 18, "h_um": 73}, ...]}
 * Errors (PLUME_EIO unreadable, PLUME_EFORMAT malformed JSON with line and column, missing or
 * non-numeric key, PLUME_EINVAL non-positive/NaN dimension, unknown id) name the file. */
PLUME_API plume_status plume_sample_load(const char *path, const char *id, plume_sample *out, plume_err *err);

/** Number of samples in the file (every entry validated as by plume_sample_load). */
PLUME_API plume_status plume_sample_count(const char *path, int *count, plume_err *err);

/** Sample number `index` (0-based, file order) of the file; PLUME_EINVAL if out of range. With
 * plume_sample_count this enumerates a file without knowing its ids. */
PLUME_API plume_status plume_sample_at(const char *path, int index, plume_sample *out, plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
