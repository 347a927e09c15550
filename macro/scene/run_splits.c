/* plume: a scene run's split lines (macro/scene/internal/run.h): what they did, for the report, and
 * their state, for the frames file and a restart. */
#include "internal/run.h"

#include <math.h>
#include <stdlib.h>

#include "../../lib/core/hooks.h"
#include "internal/scene_internal.h"

plume_hooks *plume_run_split_hooks(const plume_run *r)
{
    return r && r->scene->splits ? plume_problem_term_ctx(r->p, "splits") : NULL;
}

void plume_run_splits_tally(plume_run *r)
{
    plume_hooks *h = plume_run_split_hooks(r);
    if (!h)
        return;
    const plume_split_lines *sl = r->scene->splits;
    plume_run_report *rep = &r->rep;
    plume_hooks_totals(h, &rep->splits_opened, &rep->splits_closed, &rep->split_dissipated);
    rep->split_pairs = (long)sl->npairs;
    /* open lengths: the pairs of a line are in order along it, each holding its share of the line */
    double open = 0.0;
    for (int l = 0; l < sl->nlines; l++) {
        double run = 0.0;
        for (plume_index k = sl->first[l]; k < sl->first[l + 1]; k++) {
            if (plume_hooks_engaged(h, (int)k)) {
                run = 0.0;
                continue;
            }
            run += sl->length[k];
            open += sl->length[k];
            rep->split_longest = fmax(rep->split_longest, run);
        }
    }
    rep->split_open_now = open;
}

int plume_run_splits_array(plume_run *r, plume_frame_array *a)
{
    plume_hooks *h = plume_run_split_hooks(r);
    if (!h)
        return 0;
    const plume_index n = plume_hooks_state_size(h);
    if (!r->split_state && !(r->split_state = malloc((size_t)n * sizeof *r->split_state)))
        return -1;
    plume_hooks_state_get(h, r->split_state);
    *a = (plume_frame_array){"split_links", r->split_state, n,
                             "engaged, armed (0/1), slide (m) per link; offsets (m); released, caught, dissipated (J)"};
    return 1;
}

plume_status plume_run_splits_restore(plume_run *r, const char *file, long frame, plume_err *err)
{
    plume_hooks *h = plume_run_split_hooks(r);
    if (!h)
        return PLUME_OK;
    const plume_index n = plume_hooks_state_size(h);
    double *s = malloc((size_t)n * sizeof *s);
    if (!s)
        return plume_err_set(err, PLUME_ENOMEM, "restart: out of memory");
    plume_status st = plume_frames_read_array(file, frame, "split_links", s, n, err);
    if (st == PLUME_OK)
        st = plume_hooks_state_set(h, s, err);
    free(s);
    if (st == PLUME_OK)
        plume_run_splits_tally(r);
    return st;
}

plume_index plume_run_splits_unwelded(plume_run *r, const plume_contact_pairs *pairs)
{
    plume_index n = 0;
    for (plume_index i = 0; i < pairs->n; i++)
        n += !plume_scene_welded_neighbours(r->scene, pairs->p[i].a, pairs->p[i].b);
    return n;
}
