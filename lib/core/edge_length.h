/** \file
 * plume: edge-length (inextensibility) constraints g = |x_i - x_j|^2 - L_ij^2 = 0 (docs/design.md). */
#ifndef PLUME_EDGE_LENGTH_H
#define PLUME_EDGE_LENGTH_H

#include "../../include/plume/problem.h"

#include "export.h"
#include "term.h"

#ifdef __cplusplus
extern "C" {
#endif

#ifdef __cplusplus
}
#endif
#endif
