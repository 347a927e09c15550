/* plume: validation of the feather mesher's input curves (macro/internal/feather_geom.h). */
#include <stdlib.h>

#include "internal/feather_geom.h"

typedef struct {
    double xmin, xmax;
    plume_index i;
} sweep_item;

static int cmp_sweep(const void *a, const void *b)
{
    double x = ((const sweep_item *)a)->xmin, y = ((const sweep_item *)b)->xmin;
    return (x > y) - (x < y);
}

/* Points, finiteness, coincident neighbours and self-intersection (sweep over x) of one curve. */
plume_status plume_feather_check_curve(const char *name, const plume_polyline *c, int closed, plume_index min_points,
                                       plume_err *err)
{
    if (c->n < min_points || !c->p)
        return plume_err_set(err, PLUME_EINVAL, "%s: %ld point(s): at least %ld are needed", name, (long)c->n,
                             (long)min_points);
    const double *p = c->p;
    plume_index n = c->n;
    for (plume_index i = 0; i < n; i++)
        if (!isfinite(p[2 * i]) || !isfinite(p[2 * i + 1]))
            return plume_err_set(err, PLUME_EINVAL, "%s: point %ld (%g, %g) is not finite", name, (long)i,
                                 p[2 * i], p[2 * i + 1]);
    plume_index ns = closed ? n : n - 1;
    double lo[2] = {p[0], p[1]}, hi[2] = {p[0], p[1]};
    for (plume_index i = 0; i < n; i++)
        for (int k = 0; k < 2; k++)
            lo[k] = fmin(lo[k], p[2 * i + k]), hi[k] = fmax(hi[k], p[2 * i + k]);
    double tiny = 1e-12 * norm2(hi[0] - lo[0], hi[1] - lo[1]); /* keeps spline parameters increasing */
    for (plume_index i = 0; i < ns; i++) {
        plume_index j = (i + 1) % n;
        if (!(norm2(p[2 * j] - p[2 * i], p[2 * j + 1] - p[2 * i + 1]) > tiny))
            return plume_err_set(err, PLUME_EINVAL, "%s: points %ld and %ld coincide at (%g, %g)", name, (long)i,
                                 (long)j, p[2 * i], p[2 * i + 1]);
    }
    /* adjacent segments only meet at their shared point unless the curve turns back on itself */
    for (plume_index i = closed ? 0 : 1; i < (closed ? n : n - 1); i++) {
        const double *a = p + 2 * ((i + n - 1) % n), *b = p + 2 * i, *d = p + 2 * ((i + 1) % n);
        if (orient(a, b, d) == 0 && (a[0] - b[0]) * (d[0] - b[0]) + (a[1] - b[1]) * (d[1] - b[1]) > 0)
            return plume_err_set(err, PLUME_EINVAL,
                                 "%s: self-intersecting: the curve turns back on itself at point %ld", name, (long)i);
    }
    sweep_item *it = malloc((size_t)ns * sizeof *it);
    if (!it)
        return PLUME_ENOMEM;
    for (plume_index i = 0; i < ns; i++) {
        const double *a = p + 2 * i, *b = p + 2 * ((i + 1) % n);
        it[i].xmin = fmin(a[0], b[0]), it[i].xmax = fmax(a[0], b[0]), it[i].i = i;
    }
    qsort(it, (size_t)ns, sizeof *it, cmp_sweep);
    plume_status st = PLUME_OK;
    for (plume_index k = 0; k < ns && st == PLUME_OK; k++)
        for (plume_index l = k + 1; l < ns && it[l].xmin <= it[k].xmax; l++) {
            plume_index i = it[k].i, j = it[l].i;
            plume_index lo = i < j ? i : j, hi = i < j ? j : i;
            if (hi - lo == 1 || (closed && lo == 0 && hi == n - 1))
                continue; /* neighbours: handled above */
            const double *a = p + 2 * i, *b = p + 2 * ((i + 1) % n), *cc = p + 2 * j, *d = p + 2 * ((j + 1) % n);
            if (segs_touch(a, b, cc, d)) {
                st = plume_err_set(err, PLUME_EINVAL,
                                   "%s: self-intersecting: segment %ld (points %ld-%ld) meets segment %ld (points "
                                   "%ld-%ld)",
                                   name, (long)lo, (long)lo, (long)((lo + 1) % n), (long)hi, (long)hi,
                                   (long)((hi + 1) % n));
                break;
            }
        }
    free(it);
    return st;
}
