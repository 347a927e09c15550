/** \file
 * plume: a microstructure layout from a JSON file or text (jansson). */
#ifndef PLUME_LAYOUT_JSON_H
#define PLUME_LAYOUT_JSON_H

#include "../lib/core/export.h"
#include "layout.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Reads keys into *l (which holds the defaults or earlier values; absent keys are kept):
 *   {"layout": "strips" | "barbules", "phi": 0.16, "d_B": 1e-3, "w_B": 1.6e-4, "E_b": 2.5e9,
 *    "nu_b": 0.3, "ratio": 1e-6, "nu_B": 0.3, "thickness": 1e-4, "thickness_barb": 1e-4,
 *    "thickness_barbule": 1e-5, "kappa": 0, "order": 2, "e_rel": 0, "barbule_width": 1e-4, "barbule_spacing": 8e-4, "barbule_angle": 60}
 * ("w_B" sets d_B = w_B / phi after every other key; "note", of any value, is a comment). Each key's
 * units, meaning and default: docs/layout-format.md. Errors name the file and the line for
 * malformed JSON (PLUME_EFORMAT), an unknown key (listing the keys) or a non-numeric value (PLUME_EFORMAT), an
 * unreadable file (PLUME_EIO). Values are not range-checked here (call plume_layout_check), except
 * the phase thicknesses: "thickness_barb" and "thickness_barbule" must be finite and > 0
 * (PLUME_EFORMAT naming the key; left out, a phase has the "thickness"). */
PLUME_API plume_status plume_layout_load_json(const char *path, plume_layout *l, plume_err *err);

/** The same keys from a JSON text (a binding's request); `where` names it in messages
 * ("request.layout"). */
PLUME_API plume_status plume_layout_apply_json(const char *text, const char *where, plume_layout *l, plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
