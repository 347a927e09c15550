/* plume (micro): the separation law of a barb line (plume_separation_law_of; docs/unzipping.md,
 * "The separation law of a barb line"), measured on the hooked cell (micro/hooked_cell.h). The
 * cell is opened across the barbs, F = [1 0; 0 1 + e] (no stretch along the stiff barbs), the
 * hooks committed at every equilibrium as the traction loop does, and closed again to find where
 * they catch. The traction across the barb line is (P_xy, P_yy) (N/m, force per barb length):
 * only the hook crosses it, so its magnitude is the hook's force per period, and the strength is
 * that magnitude at the release. */
#include "separation_cell.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "hooked_cell.h"

/* Where the hook first reaches its strength: secant steps on the hook's load, which grows almost
 * linearly with the opening, to a load in [1, 1 + PLUME_SEPARATION_LOAD_TOL]. */
#define PLUME_SEPARATION_LOAD_TOL 1e-4

plume_status plume_separation_law_of(const plume_layout *l, plume_separation_law *out, plume_err *err)
{
    if (!l || !out)
        return plume_err_set(err, PLUME_EINVAL, "separation law: a layout and an output are required");
    memset(out, 0, sizeof *out);
    plume_hooked_cell c;
    plume_status st = plume_hooked_cell_init(&c, l, "separation law", err);
    const double b = c.oc.cell.b, a = c.oc.cell.a, h = l->h;
    double T = 0.0, Tn = 0.0, E = 0.0, e = 0.0, work = 0.0, eprev = 0.0;
    /* 1. up to the strength: a first small opening, then secant steps on the hook's load */
    const double e0 = 1e-3 * l->hooks.opening / b;
    if (st == PLUME_OK)
        st = plume_hooked_cell_open(&c, e = e0, &T, &Tn, &E, err);
    double load = st == PLUME_OK ? plume_hooked_cell_load(&c) : 0.0, load_prev = 0.0;
    for (int it = 0; st == PLUME_OK && !(load >= 1.0 && load <= 1.0 + PLUME_SEPARATION_LOAD_TOL); it++) {
        if (it == 50 || !(load > load_prev)) {
            st = plume_err_set(err, PLUME_EINFEASIBLE, "separation law: the hook's load (%g of its strength at opening "
                               "strain %g) does not reach the strength", load, e);
            break;
        }
        const double target = 1.0 + 0.5 * PLUME_SEPARATION_LOAD_TOL;
        const double slope = (load - load_prev) / (e - (it == 0 ? 0.0 : eprev));
        const double enext = e + (target - load) / slope;
        if (load < 1.0) { /* accepted: work along the elastic branch */
            eprev = e, load_prev = load;
        }
        if ((st = plume_hooked_cell_open(&c, enext, &T, &Tn, &E, err)) != PLUME_OK)
            break;
        e = enext;
        load = plume_hooked_cell_load(&c);
    }
    /* the path so far is elastic: the work per barb length is the energy per barb length; the
     * hook's own opening across the line is its pairs' mean gap along y. The strength is the
     * traction's magnitude: the hook lets go at its strength whatever the direction of its pull,
     * and a leaning barbule pulls it askew (with the shear held, P_xy is half of P_yy for
     * data/layout_hooks.json), so the line's traction at the release is one hook's strength per
     * period in every mode, the macro link's criterion. */
    if (st == PLUME_OK) {
        out->strength = T;
        out->peak_opening = e * b;
        work = E / a;
        double gap = 0.0;
        for (plume_index p = 0; p < c.oc.npairs; p++)
            gap += c.xfull[2 * c.oc.pairs[2 * p + 1] + 1] - c.xfull[2 * c.oc.pairs[2 * p] + 1];
        gap /= (double)c.oc.npairs;
        if (!(gap > 0.0))
            st = plume_err_set(err, PLUME_EINFEASIBLE, "separation law: the hook has not opened at its strength "
                               "(mean gap %g m)", gap);
        else
            out->stiffness = Tn / gap;
    }
    /* 2. let go, and keep opening until the hook has cleared the capture distance (a hook held at
     * exactly its strength, which no commit lets go, is pulled on by 1/1000 of its opening). A slide
     * is crossed in 40 steps: each loads the hook beyond its strength, the commit slides it back and
     * the cell is solved again. The work is summed between admissible states (every hook within its
     * strength), the states a slide passes through; the strength is the largest of their
     * tractions. */
    const double slide_step = (l->hooks.slide > 0.0 ? l->hooks.slide / 40.0 : 1e-3 * l->hooks.opening) / b;
    const double free_step = (2.0 * l->hooks.capture + l->hooks.opening + l->hooks.slide) / 10.0 / b;
    const double e_clear = (2.0 * l->hooks.capture + l->hooks.opening + l->hooks.slide) / b + e;
    double T_adm = Tn, e_adm = e; /* the work is the normal traction's along the opening */
    int released = 0;
    for (int guard = 0; st == PLUME_OK; guard++) {
        plume_hooks_events ev;
        if ((st = plume_hooks_commit(c.hooks, 2, c.xfull, PLUME_HOOKS_ALL, &ev, err)) != PLUME_OK)
            break;
        if (ev.released && !released) /* the step that lets go: its work up to here */
            work += 0.5 * (T_adm + Tn) * (e - e_adm) * b;
        if (ev.released || ev.slid) { /* the change solved again at the same opening */
            if ((st = plume_hooked_cell_open(&c, e, &T, &Tn, &E, err)) != PLUME_OK)
                break;
            if (ev.released && !released) {
                released = 1;
                out->opening = e * b;
                out->energy = (work - E / a) / h;
            }
            continue;
        }
        if (!released) { /* admissible */
            work += 0.5 * (T_adm + Tn) * (e - e_adm) * b; /* per barb length */
            T_adm = Tn, e_adm = e;
            out->strength = fmax(out->strength, T);
        }
        if (released && e >= e_clear)
            break;
        if (guard == 100000) {
            st = plume_err_set(err, PLUME_EINFEASIBLE, "separation law: the hook has not let go at opening %g m", e * b);
            break;
        }
        const double step = released ? free_step : slide_step;
        if ((st = plume_hooked_cell_open(&c, e + step, &T, &Tn, &E, err)) != PLUME_OK)
            break;
        e += step;
    }
    /* 3. back until the hook catches again: steps of a tenth of the capture distance, and the step
     * that catches it undone and halved down to 1/1000 of it (the released cell holds no load, so
     * an undone step leaves nothing behind) */
    if (st == PLUME_OK && l->hooks.capture > 0.0) {
        double down = 0.1 * l->hooks.capture / b;
        const double finest = 1e-3 * l->hooks.capture / b;
        while (st == PLUME_OK && e > 0.0) {
            const double enext = fmax(e - down, 0.0);
            if ((st = plume_hooked_cell_open(&c, enext, &T, &Tn, &E, err)) != PLUME_OK)
                break;
            c.hook.keep(c.hook.ctx, 1);
            plume_hooks_events ev;
            if ((st = plume_hooks_commit(c.hooks, 2, c.xfull, PLUME_HOOKS_ALL, &ev, err)) != PLUME_OK)
                break;
            if (!ev.reengaged) {
                e = enext;
                continue;
            }
            if (down <= finest) {
                out->capture = enext * b;
                break;
            }
            c.hook.keep(c.hook.ctx, 0);
            down *= 0.5;
        }
        if (st == PLUME_OK && !(out->capture > 0.0))
            st = plume_err_set(err, PLUME_EINFEASIBLE, "separation law: the hook did not catch again on closing "
                               "(capture %g m)", l->hooks.capture);
    }
    out->cell_hooks = 1;
    out->cell_length = a;
    out->solves = c.solves;
    out->newton_iterations = c.iterations;
    plume_hooked_cell_free(&c);
    if (st != PLUME_OK)
        memset(out, 0, sizeof *out);
    return st;
}
