/* plume (private, not installed): a factorisation analysed in the order of a base pattern. */
#ifndef PLUME_INTERNAL_CHOLESKY_LIKE_H
#define PLUME_INTERNAL_CHOLESKY_LIKE_H

#include "../cholesky.h"

/* plume_chol_create for an LL^T pattern that contains a base pattern (a problem's fixed stencils:
 * base_colptr, base_rowind, same n; NULL: none): the pattern is analysed in the order AMD or METIS
 * find for the base pattern, taken from `like` (a factorisation made with the same base; NULL:
 * found here), while its factor has at most 1.2 times the base pattern's entries, and ordered
 * afresh otherwise. The order depends on the base and the pattern alone, never on the patterns
 * before (a restarted run factorises as the uninterrupted one); a pattern that differs from the
 * base by a few contact pairs is analysed without AMD and METIS. LDL^T: as plume_chol_create. */
plume_status plume_chol_create_like(plume_index n, const plume_index *colptr, const plume_index *rowind, int ldl,
                                    const plume_index *base_colptr, const plume_index *base_rowind,
                                    const plume_chol *like, plume_chol **out, plume_err *err);

#endif
