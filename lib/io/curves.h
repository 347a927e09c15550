/** \file
 * plume: result curves and moduli in HDF5 (layout of docs/design.md), written atomically. */
#ifndef PLUME_CURVES_H
#define PLUME_CURVES_H

#include "../../include/plume/curves.h"

#include "../core/export.h"
#include "../core/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The plane-stress tensor (Pa, row-major 3x3) a moduli file's /moduli holds as the attributes
 * prefix + C11, C12, C13, C22, C23, C33 (prefix "": the bonded cell's, apps/homogenize -o;
 * "separation_": the hooked cell's, with a separation law). Errors as plume_moduli_read_param
 * (PLUME_EFORMAT naming the missing attribute). */
plume_status plume_moduli_read_tensor(const char *path, const char *prefix, double C[9], plume_err *err);

/** 1 when path is a readable HDF5 file whose /moduli has the attribute `name`, else 0 (an
 * optional attribute: the read that follows names any other fault). */
int plume_moduli_has_param(const char *path, const char *name);

#ifdef __cplusplus
}
#endif
#endif
