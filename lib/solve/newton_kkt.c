/* The native solver's linear algebra (lib/solve/internal/newton_state.h): the KKT and eliminated
 * patterns, factorisation of the exact Hessian with Ipopt's inertia correction (or of the
 * projected one), solves of the eliminated system refined against the requested regularisation,
 * and the Newton and chord directions. The method is described in lib/solve/newton.c. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal/newton_state.h"

/* The factorised multiplier regularisation over the solved one (kkt_refine). Measured
 * (2026-11-26): refinement passes over a tilted traction run at 4e4 elements 49 / 30 / 19 / 16 for
 * 1e5 / 1e4 / 1e3 / 1e2, with the same iterations; the feather's iterations a step equal at 1e3
 * and 1e4 (6.2 and 5.5 at its two meshes), more at 1e2 (6.4, 6.1): its soft modes need the digits. */
#define DCF_OVER_DC 1e3

/* KKT pattern: columns < n are the Hessian's; column n + r holds the free dofs of constraint r
 * (rows sorted) and its diagonal. */
plume_status plume_newton_build_kkt_pattern(plume_newton *s)
{
    plume_index n = s->n, m = s->m;
    s->kcolptr = calloc((size_t)(n + m + 1), sizeof *s->kcolptr);
    s->krowind = malloc((size_t)(s->hp.nnz + s->jnnz + m + 1) * sizeof *s->krowind);
    s->jpos = malloc((size_t)(s->jnnz + 1) * sizeof *s->jpos);
    plume_index *order = malloc((size_t)(s->jnnz + 1) * sizeof *order);
    plume_index *cnt = calloc((size_t)(m + 1), sizeof *cnt);
    if (!s->kcolptr || !s->krowind || !s->jpos || !order || !cnt) {
        free(order);
        free(cnt);
        return PLUME_ENOMEM;
    }
    memcpy(s->kcolptr, s->hp.colptr, (size_t)(n + 1) * sizeof *s->kcolptr);
    memcpy(s->krowind, s->hp.rowind, (size_t)s->hp.nnz * sizeof *s->krowind);
    for (plume_index k = 0; k < s->jnnz; k++)
        cnt[s->jrow[k]]++;
    /* bucket the triplets by constraint row (counting sort), then sort each bucket by column */
    plume_index *start = calloc((size_t)(m + 1), sizeof *start);
    if (!start) {
        free(order);
        free(cnt);
        return PLUME_ENOMEM;
    }
    for (plume_index r = 0; r < m; r++)
        start[r + 1] = start[r] + cnt[r];
    memset(cnt, 0, (size_t)(m + 1) * sizeof *cnt);
    for (plume_index k = 0; k < s->jnnz; k++)
        order[start[s->jrow[k]] + cnt[s->jrow[k]]++] = k;
    plume_index pos = s->hp.nnz;
    for (plume_index r = 0; r < m; r++) {
        plume_index *b = order + start[r];
        for (plume_index i = 1; i < cnt[r]; i++) /* insertion sort: a row has a handful of entries */
            for (plume_index j = i; j > 0 && s->jcol[b[j - 1]] > s->jcol[b[j]]; j--) {
                plume_index t = b[j];
                b[j] = b[j - 1];
                b[j - 1] = t;
            }
        for (plume_index i = 0; i < cnt[r]; i++) {
            s->krowind[pos] = s->jcol[b[i]];
            s->jpos[b[i]] = pos++;
        }
        s->krowind[pos++] = n + r;
        s->kcolptr[n + r + 1] = pos;
    }
    free(start);
    free(order);
    free(cnt);
    return PLUME_OK;
}

static plume_index hessian_slot(const plume_sparsity *hp, plume_index r, plume_index c)
{
    if (r > c) {
        plume_index t = r;
        r = c;
        c = t;
    }
    plume_index lo = hp->colptr[c], hi = hp->colptr[c + 1] - 1;
    while (lo <= hi) {
        plume_index mid = lo + (hi - lo) / 2;
        if (hp->rowind[mid] == r)
            return mid;
        if (hp->rowind[mid] < r)
            lo = mid + 1;
        else
            hi = mid - 1;
    }
    return -1;
}

/* Eliminating the multipliers from the KKT system adds J_r^T J_r / dc for every constraint row
 * r: list every pair of Jacobian entries of one row with the Hessian slot it lands in (the
 * problem's Hessian pattern contains every constraint stencil, so the slot exists). */
plume_status plume_newton_build_elimination_pairs(plume_newton *s)
{
    plume_index m = s->m;
    plume_index *cnt = calloc((size_t)(m + 1), sizeof *cnt), *start = calloc((size_t)(m + 2), sizeof *start);
    plume_index *order = malloc((size_t)(s->jnnz + 1) * sizeof *order);
    plume_status st = PLUME_OK;
    if (!cnt || !start || !order) {
        st = PLUME_ENOMEM;
        goto done;
    }
    for (plume_index k = 0; k < s->jnnz; k++)
        cnt[s->jrow[k]]++;
    for (plume_index r = 0; r < m; r++)
        start[r + 1] = start[r] + cnt[r];
    plume_index np = 0;
    for (plume_index r = 0; r < m; r++)
        np += cnt[r] * (cnt[r] + 1) / 2;
    memset(cnt, 0, (size_t)(m + 1) * sizeof *cnt);
    for (plume_index k = 0; k < s->jnnz; k++)
        order[start[s->jrow[k]] + cnt[s->jrow[k]]++] = k;
    s->pair_a = malloc((size_t)(np + 1) * sizeof *s->pair_a);
    s->pair_b = malloc((size_t)(np + 1) * sizeof *s->pair_b);
    s->pair_pos = malloc((size_t)(np + 1) * sizeof *s->pair_pos);
    s->kwork = malloc((size_t)(s->n + 1) * sizeof *s->kwork);
    s->lwork = malloc((size_t)(m + 1) * sizeof *s->lwork);
    if (!s->pair_a || !s->pair_b || !s->pair_pos || !s->kwork || !s->lwork) {
        st = PLUME_ENOMEM;
        goto done;
    }
    s->npairs = 0;
    for (plume_index r = 0; r < m; r++)
        for (plume_index i = 0; i < cnt[r]; i++)
            for (plume_index j = i; j < cnt[r]; j++) {
                plume_index ka = order[start[r] + i], kb = order[start[r] + j];
                plume_index pos = hessian_slot(&s->hp, s->jcol[ka], s->jcol[kb]);
                if (pos < 0) {
                    st = PLUME_EINVAL;
                    goto done;
                }
                s->pair_a[s->npairs] = ka;
                s->pair_b[s->npairs] = kb;
                s->pair_pos[s->npairs++] = pos;
            }
done:
    free(cnt);
    free(start);
    free(order);
    return st;
}

/* Factorises the matrix of s->hval (the Hessian just assembled) with dw on its diagonal and the
 * constraints' block regularised by dc (one per constraint); s->hval is left as assembled. */
static plume_status factor_with(plume_newton *s, double dw, const double *dc)
{
    plume_status st;
    dw += s->tr_sigma; /* the trust region's regularisation, on top of any inertia shift */
    if (s->eliminate) {
        /* K = H + dw I + sum_r J_r^T J_r / dc on the Hessian's own pattern, in a copy: adding
         * the constraint part to H and subtracting it again would leave H with the round-off of
         * J^T J / dc, 1e5 times the largest stiffness (about 1e-2 on the feather at 11k elements,
         * above its soft directions' own stiffness) after every inertia-correction attempt, and the
         * refinement measures residuals against H */
        memcpy(s->kval, s->hval, (size_t)s->hp.nnz * sizeof *s->kval);
        for (plume_index k = 0; k < s->npairs; k++)
            s->kval[s->pair_pos[k]] += s->jval[s->pair_a[k]] * s->jval[s->pair_b[k]] / dc[s->jrow[s->pair_a[k]]];
        st = plume_chol_factor(s->chol, s->kval, dw);
    } else if (s->m > 0) {
        memcpy(s->kval, s->hval, (size_t)s->hp.nnz * sizeof *s->kval);
        for (plume_index c = 0; c < s->n; c++)
            s->kval[s->diagpos[c]] += dw;
        for (plume_index k = 0; k < s->jnnz; k++)
            s->kval[s->jpos[k]] = s->jval[k];
        for (plume_index r = 0; r < s->m; r++)
            s->kval[s->diagpos[s->n + r]] = -dc[r];
        st = plume_chol_factor(s->chol, s->kval, 0.0);
    } else {
        st = plume_chol_factor(s->chol, s->hval, dw);
    }
    return st;
}

/* The Hessian diagonal's typical size: the median of its binary exponents, as a power of two (no
 * workspace; a factor of 2 is all the precision a first shift needs). */
static double typical_diagonal(const plume_newton *s)
{
    enum { EXP_MIN = -1100, EXP_SPAN = 2200 };
    int count[EXP_SPAN] = {0};
    plume_index nonzero = 0;
    for (plume_index c = 0; c < s->n; c++) {
        double d = fabs(s->hval[s->hp.colptr[c + 1] - 1]);
        if (!(d > 0.0) || !isfinite(d))
            continue;
        int e;
        frexp(d, &e);
        count[e - EXP_MIN]++;
        nonzero++;
    }
    plume_index seen = 0;
    for (int k = 0; k < EXP_SPAN && nonzero > 0; k++)
        if ((seen += count[k]) * 2 >= nonzero)
            return ldexp(1.0, k + EXP_MIN);
    return 1.0;
}

/* Each constraint's regularisation: 1e-8 |J_r|^2 / h_r, h_r the largest Hessian diagonal among the
 * constraint's own dofs (dc, hmax and jmax, the whole matrix's, where a row has no entry or no
 * stiffness). Scaled by the whole matrix's largest diagonal (the rachis'), the eliminated barb
 * constraints of a vane put J^T J / dcf at 1e5 times the rachis' stiffness into vanes whose softest
 * directions are their inertia, and CHOLMOD refused matrices that were positive definite in exact
 * arithmetic: the wing twig's 542 inertia shifts, 41 to 107 with each constraint scaled to its own
 * stiffness (docs/unzipping.md). */
static void regularisation(plume_newton *s, double dc, double hmax, double jmax)
{
    for (plume_index r = 0; r < s->m; r++)
        s->acc_g[r] = 0.0, s->dcfv[r] = 0.0; /* |J_r|, h_r (acc_g: free outside the line search) */
    for (plume_index k = 0; k < s->jnnz; k++) {
        const plume_index r = s->jrow[k], c = s->jcol[k];
        s->acc_g[r] = fmax(s->acc_g[r], fabs(s->jval[k]));
        s->dcfv[r] = fmax(s->dcfv[r], fabs(s->hval[s->hp.colptr[c + 1] - 1]));
    }
    s->refine = s->eliminate && s->o.kkt_refine;
    for (plume_index r = 0; r < s->m; r++) {
        const double j = s->acc_g[r] > 0.0 ? s->acc_g[r] : (jmax > 0.0 ? jmax : 1.0);
        const double h = s->dcfv[r] > 0.0 && isfinite(s->dcfv[r]) ? s->dcfv[r] : hmax;
        s->dcv[r] = s->acc_g[r] > 0.0 ? 1e-8 * j * j / h : dc;
        s->dcfv[r] = s->refine ? DCF_OVER_DC * s->dcv[r] : s->dcv[r];
    }
}

/* Assembles and factorises the Newton/KKT matrix at u with multipliers lambda, with at least
 * dw_min added to the Hessian's diagonal; raises the regularisation until the factorisation
 * succeeds. *hmax_out receives the largest Hessian diagonal (the scale of any regularisation). */
static plume_status factorize(plume_newton *s, const double *u, const double *lambda, double dw_min,
                              double *hmax_out)
{
    plume_status st = PLUME_ESINGULAR;
    /* Projection per element slows Newton down to a crawl where elements are indefinite but the
     * assembled matrix is not (stiff fibres in compression): try the exact Hessian first and keep
     * it whenever CHOLMOD accepts the SPD system built from it (with constraints eliminated, that
     * is H positive definite on the constraints' tangent space — the second-order condition),
     * otherwise the projected one. The LDL^T mode cannot tell inertia, so it always projects. */
    int exact_first = s->o.exact_hessian_first && dw_min == 0.0 && (s->m == 0 || s->eliminate);
    /* The Hessians tried in turn: exact; then (when some term has a cheap closed-form projection
     * that keeps its stiffness: Gauss-Newton bending, compressed edges' curvature dropped) those
     * terms projected and the rest exact, before any shift of the whole matrix: a compressed barb
     * or a bending element gone indefinite is a local matter, and the global shift that would
     * cover it damps every soft direction of the feather (measured: 92 iterations and 95 shifts
     * against 55 and 16 on the feather at 11k elements); last, everything projected. */
    int partial = exact_first && s->o.partial_projection && plume_problem_has_partial_projection(s->p);
    int modes[3], nmodes = 0;
    if (exact_first)
        modes[nmodes++] = PLUME_HESSIAN_EXACT;
    if (partial)
        modes[nmodes++] = PLUME_HESSIAN_PARTIAL;
    modes[nmodes++] = PLUME_HESSIAN_PROJECTED;
    for (int k = 0; k < nmodes; k++) {
        const int mode = modes[k], project = mode == PLUME_HESSIAN_PROJECTED;
        if ((st = plume_problem_hessian(s->p, u, 1.0, s->m ? lambda : NULL, mode, s->hval)) != PLUME_OK)
            return st;
        double hmax = 0.0;
        for (plume_index c = 0; c < s->n; c++)
            hmax = fmax(hmax, fabs(s->hval[s->hp.colptr[c + 1] - 1]));
        if (!(hmax > 0.0) || !isfinite(hmax))
            hmax = 1.0;
        *hmax_out = hmax;
        double jmax = 0.0;
        for (plume_index q = 0; q < s->jnnz; q++)
            jmax = fmax(jmax, fabs(s->jval[q]));
        const double dc = s->m ? 1e-8 * (jmax > 0.0 ? jmax * jmax : 1.0) / hmax : 0.0;
        regularisation(s, dc, hmax, jmax);
        double dw = fmax(dw_min, s->m && !s->eliminate ? 1e-12 * hmax : 0.0);
        /* Exact (or partly projected) Hessian: Ipopt's inertia correction. Try no shift; if the
         * matrix is not positive definite, start from a third of the last shift that worked (or
         * 1e-6 of the typical diagonal the first time) and grow it 8x (100x the first time) until
         * it is, up to hmax. The first guess follows the median diagonal, not the largest: that
         * one belongs to the stiffest material (a feather's rachis, whose diagonal is 1e4 times its
         * vane's), and a shift scaled by it damps every soft direction of the rest for the many
         * iterations it takes to come down by 3 each (the 11.4k feather's first step: 16 iterations,
         * 9 of them shifted, against 10 and 2; docs/solver-nonconvexity.md);
         * then fall back to the next Hessian. The shift carried from one iteration to the next
         * damps the directions along soft (buckling) modes the way a trust region would, so full
         * steps are taken instead of cut ones. With a partly projected Hessian still to try, the
         * exact one gets no shift. */
        if (!project) {
            double sh = 0.0;
            const int shifts_allowed = !(mode == PLUME_HESSIAN_EXACT && partial);
            for (int attempt = 0; attempt < 40; attempt++) {
                st = factor_with(s, dw + sh, s->dcfv);
                if (st != PLUME_ESINGULAR) {
                    if (st == PLUME_OK) {
                        s->diag = dw + sh + s->tr_sigma;
                        s->shift = sh;
                        s->projected = mode == PLUME_HESSIAN_PARTIAL;
                        s->partial_factorizations += mode == PLUME_HESSIAN_PARTIAL;
                        /* As in Ipopt, the last shift that was needed is kept however many
                         * unshifted factorisations came since, from one solve to the next too:
                         * the next indefinite state (the vane buckling in a later time step)
                         * starts from a third of it */
                        if (sh > 0.0)
                            s->shift_last = sh;
                    }
                    return st;
                }
                if (!shifts_allowed)
                    break;
                s->shifts++;
                if (sh == 0.0)
                    sh = s->shift_last > 1e-12 * hmax ? s->shift_last / 3.0 : 1e-6 * typical_diagonal(s);
                else
                    sh *= s->shift_last > 1e-12 * hmax ? 8.0 : 100.0;
                if (!(sh <= s->o.inertia_max_shift * hmax) || s->o.inertia_corrections == 0)
                    break;
            }
            continue;
        }
        for (int attempt = 0; attempt < 12; attempt++) {
            st = factor_with(s, dw, s->dcfv);
            if (st != PLUME_ESINGULAR) {
                if (st == PLUME_OK) {
                    s->diag = dw + s->tr_sigma;
                    s->shift = dw;
                    s->projected = 1;
                }
                return st;
            }
            dw = dw > 0.0 ? dw * 100.0 : 1e-10 * hmax;
        }
    }
    return st;
}

/* One solve of [H + d I, J^T; J, -dcf I] [x; l] = [r1; r2] with the eliminated factorisation
 * (J values jv): K x = r1 + J^T r2 / dcf, then l = (J x - r2) / dcf. r and out may alias. */
static plume_status elim_solve(plume_newton *s, const double *jv, const double *r, double *out)
{
    plume_index n = s->n, m = s->m;
    const double *dcf = s->dcfv;
    for (plume_index i = 0; i < n; i++)
        s->kwork[i] = r[i];
    for (plume_index k = 0; k < s->jnnz; k++)
        s->kwork[s->jcol[k]] += jv[k] * r[n + s->jrow[k]] / dcf[s->jrow[k]];
    for (plume_index q = 0; q < m; q++) /* r2 is read before out (which may alias r) is written */
        s->lwork[q] = -r[n + q];
    plume_status st = plume_chol_solve(s->chol, s->kwork, out);
    if (st != PLUME_OK)
        return st;
    for (plume_index k = 0; k < s->jnnz; k++)
        s->lwork[s->jrow[k]] += jv[k] * out[s->jcol[k]];
    for (plume_index q = 0; q < m; q++)
        out[n + q] = s->lwork[q] / dcf[q];
    return PLUME_OK;
}

/* Solves the regularised KKT system [H + d I, J^T; J, -dc I] [x; l] = [r1; r2] (H and d of the
 * last factorisation, J values jv); out holds x (n) then l (m); r and out may alias.
 * With the multipliers eliminated, the factorised matrix is H + d I + J^T J / dcf with a dcf
 * larger than dc (kkt_refine): J^T J / dc is 1e8 times the Hessian's scale, and a Cholesky
 * factor of that loses 8 digits of the Hessian's own part (the soft, buckling directions of a
 * feather: Newton then converged linearly), while 1e3 loses 5. Iterative refinement against the
 * dc system recovers the rest: its error contracts by dcf / (dcf + sigma(J H^-1 J^T)) a pass. */
static plume_status kkt_solve_j(plume_newton *s, const double *jv, const double *r, double *out)
{
    if (!s->eliminate)
        return plume_chol_solve(s->chol, r, out);
    plume_index n = s->n, m = s->m, nk = n + m;
    if (!s->refine)
        return elim_solve(s, jv, r, out);
    double *b = s->rb, *res = s->rr, *dx = s->rd;
    memcpy(b, r, (size_t)nk * sizeof *b);
    plume_status st = elim_solve(s, jv, b, out);
    /* the force rows and the constraint rows are judged against their own right-hand sides (a
     * small violation g asks for a small residual in its rows), each at least to round-off of the
     * whole */
    double bf = 0.0, bc = 0.0;
    for (plume_index i = 0; i < n; i++)
        bf = nt_max_abs(bf, b[i]);
    for (plume_index q = 0; q < m; q++)
        bc = nt_max_abs(bc, b[n + q]);
    const double floor = 1e-15 * fmax(bf, bc);
    const double tol_f = fmax(s->refine_rtol * (s->refine_bf > 0.0 ? s->refine_bf : bf), floor);
    const double tol_c = fmax(s->refine_rtol * bc, floor);
    double last = INFINITY;
    for (int pass = 0; st == PLUME_OK && pass < 8; pass++) {
        /* res = b - [H + d I, J^T; J, -dc I] out */
        for (plume_index i = 0; i < n; i++)
            res[i] = b[i] - s->diag * out[i];
        for (plume_index q = 0; q < m; q++)
            res[n + q] = b[n + q] + s->dcv[q] * out[n + q];
        const plume_index *cp = s->hp.colptr, *ri = s->hp.rowind;
        for (plume_index c = 0; c < n; c++)
            for (plume_index k = cp[c]; k < cp[c + 1]; k++) {
                plume_index rw = ri[k];
                res[rw] -= s->hval[k] * out[c];
                if (rw != c)
                    res[c] -= s->hval[k] * out[rw];
            }
        for (plume_index k = 0; k < s->jnnz; k++) {
            res[s->jcol[k]] -= jv[k] * out[n + s->jrow[k]];
            res[n + s->jrow[k]] -= jv[k] * out[s->jcol[k]];
        }
        double rf = 0.0, rc = 0.0;
        for (plume_index i = 0; i < n; i++)
            rf = nt_max_abs(rf, res[i]);
        for (plume_index q = 0; q < m; q++)
            rc = nt_max_abs(rc, res[n + q]);
        double rmax = fmax(rf, rc);
        if ((!(rf > tol_f) && !(rc > tol_c)) || !(rmax < 0.5 * last))
            break;
        last = rmax;
        if ((st = elim_solve(s, jv, res, dx)) == PLUME_OK)
            for (plume_index i = 0; i < nk; i++)
                out[i] += dx[i];
        s->refinements++;
    }
    return st;
}

plume_status plume_newton_kkt_solve(plume_newton *s, const double *r, double *out)
{
    return kkt_solve_j(s, s->jval, r, out);
}

double plume_newton_force_residual(plume_newton *s, const double *lambda)
{
    double *fr = s->rd; /* scratch: the refinement's workspace, free between solves */
    memcpy(fr, s->grad, (size_t)s->n * sizeof *fr);
    for (plume_index k = 0; k < s->jnnz; k++)
        fr[s->jcol[k]] += s->jval[k] * lambda[s->jrow[k]];
    double bf = 0.0;
    for (plume_index i = 0; i < s->n; i++)
        bf = nt_max_abs(bf, fr[i]);
    return bf > 0.0 ? bf : 1e-300;
}

/* Newton/SQP direction: factorise and solve. A direction longer than max_step times the body
 * means the Hessian is (nearly) singular on the constraints' null space (e.g. a straight chain
 * with zero multipliers has no sideways stiffness), so the regularisation is raised,
 * Levenberg–Marquardt style, until the step is of a sensible size (after 8 tries the last step is
 * returned as it is: the line search judges it). PLUME_ESINGULAR when no factorisation worked. */
plume_status plume_newton_direction(plume_newton *s, const double *u, const double *lambda, double *step_max)
{
    plume_index n = s->n, m = s->m;
    double L = plume_problem_length_scale(s->p), dw = 0.0, hmax;
    plume_status st = PLUME_OK;
    for (int attempt = 0; attempt < 8; attempt++) {
        if ((st = factorize(s, u, lambda, dw, &hmax)) != PLUME_OK)
            return st;
        for (plume_index i = 0; i < n; i++)
            s->rhs[i] = -s->grad[i];
        for (plume_index r = 0; r < m; r++)
            s->rhs[n + r] = -s->g[r] - s->dcv[r] * lambda[r];
        /* the forcing term (refine_rtol) is relative to the nonlinear residual, the KKT residual
         * grad f + J^T lambda of the increment form, not to this right-hand side -grad f, which
         * does not vanish at a constrained solution (it is balanced by J^T lambda): measured
         * against it, the refinement stopped at a linear residual as large as the nonlinear one
         * (a forcing term of about 1) and the end game lost its quadratic rate */
        s->refine_bf = m > 0 ? plume_newton_force_residual(s, lambda) : 0.0;
        st = plume_newton_kkt_solve(s, s->rhs, s->sol);
        s->refine_bf = 0.0;
        if (st != PLUME_OK && st != PLUME_ESINGULAR)
            return st;
        *step_max = 0.0;
        double slope = 0.0;
        for (plume_index i = 0; i < n; i++) {
            *step_max = fmax(*step_max, fabs(s->sol[i]));
            slope += s->grad[i] * s->sol[i];
        }
        /* Without constraints a factorisation CHOLMOD accepted must give a descent direction;
         * near a bifurcation (a nearly singular exact Hessian) round-off can make it point
         * uphill: then regularise, which also switches to the projected Hessian. */
        int uphill = m == 0 && !(slope < 0.0) && *step_max > 0.0;
        if (st == PLUME_OK && *step_max <= s->o.max_step * L && !uphill)
            return PLUME_OK;
        dw = dw > 0.0 ? dw * 100.0 : 1e-8 * hmax;
    }
    return st == PLUME_OK ? PLUME_OK : PLUME_ESINGULAR; /* a long step is still a step */
}

/* Chord direction: the last factorisation (of an earlier iterate's matrix, perhaps of an earlier
 * solve) with the current residual. The fixed point is exact whatever matrix is used; only the
 * rate of convergence suffers, which the caller measures. Not usable (nonzero) when the solve
 * fails, the step is absurdly long, or (without constraints) it does not descend. */
int plume_newton_chord_direction(plume_newton *s, const double *lambda, double L, double *step_max)
{
    /* increment form with the factorisation's own Jacobian J_f, so that only the matrix is stale:
     *   (H_f + J_f^T J_f / dc) dx = r1 + J_f^T r2 / dc,  dlam = (J_f dx - r2) / dc,
     * r1 = -(grad + J^T lam) (s->jtl holds J^T lam from kkt_residual), r2 = -g */
    plume_index n = s->n, m = s->m;
    if (!s->eliminate && m > 0)
        return 1; /* the LDL^T mode keeps J inside its factorisation: no chord steps */
    for (plume_index i = 0; i < n; i++)
        s->rhs[i] = -(s->grad[i] + (m ? s->jtl[i] : 0.0));
    for (plume_index r = 0; r < m; r++)
        s->rhs[n + r] = -s->g[r];
    if (kkt_solve_j(s, s->jval_f, s->rhs, s->sol) != PLUME_OK)
        return 1;
    for (plume_index r = 0; r < m; r++)
        s->sol[n + r] += lambda[r];
    double slope = 0.0;
    *step_max = 0.0;
    for (plume_index i = 0; i < n; i++) {
        if (!isfinite(s->sol[i]))
            return 1;
        *step_max = fmax(*step_max, fabs(s->sol[i]));
        slope += s->grad[i] * s->sol[i];
    }
    return !(*step_max <= s->o.max_step * L) || (m == 0 && !(slope < 0.0) && *step_max > 0.0);
}

