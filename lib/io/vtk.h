/** \file
 * plume: a mesh state as a legacy VTK ASCII unstructured grid (docs/design.md "Data and files": frames
 * as VTK for ParaView). One file per frame; a numbered series (frame_00000.vtk, frame_00001.vtk,
 * ...) opens in ParaView as one time series. */
#ifndef PLUME_VTK_H
#define PLUME_VTK_H

#include "../core/export.h"
#include "../core/mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Writes `path`: points x (3 nv, or mesh->x when x is NULL; a planar mesh gets z = 0), the
 * triangles, cell data "material" (int) and "barb_direction" (the reference barb direction, as a
 * 3-vector with z = 0), point data "displacement" (x - (X, 0)), and the time t as the TIME field
 * ParaView reads. Written to "<path>.tmp.<pid>" and renamed, so a reader never sees half a file.
 * Errors: invalid arguments (PLUME_EINVAL), a file that cannot be written (PLUME_EIO, message
 * naming it). */
plume_status plume_vtk_write(const char *path, const plume_mesh *mesh, const double *x, double t, plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
