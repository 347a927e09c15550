/** \file
 * plume: one measured traction run for studies of cost, error and sensitivity (apps/study): the
 * macroscale vane or the resolved microscale specimen, a configuration in, stress and w-bar at the
 * last load step, wall time, iterations and the convergence outcome out. */
#ifndef PLUME_STUDY_H
#define PLUME_STUDY_H

#include "../include/plume/experiments.h"

#ifdef __cplusplus
extern "C" {
#endif

#ifdef __cplusplus
}
#endif
#endif
