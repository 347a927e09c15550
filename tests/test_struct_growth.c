/* The structs that grow (docs/library.md, "Structs that grow"): a caller's struct is read and
 * written only as far as its size member says, so a program compiled against an older, smaller
 * struct keeps working; a struct whose size was never set is refused with a message naming it. */
#include <stddef.h>
#include <string.h>

#include "harness.h"
#include "plume_tree.h"

static plume_status quadratic_eval(void *ctx, int dim, const double *x, double *energy, double *grad,
                                   double *hblocks, int project)
{
    (void)ctx, (void)project;
    for (int a = 0; a < dim; a++) {
        if (energy)
            *energy += 0.5 * (x[a] - 1.0) * (x[a] - 1.0);
        if (grad)
            grad[a] += x[a] - 1.0;
    }
    if (hblocks)
        for (int a = 0; a < dim * dim; a++)
            hblocks[a] = a % (dim + 1) == 0 ? 1.0 : 0.0;
    return PLUME_OK;
}

static const plume_index one_vertex[1] = {0};

/* A one-vertex problem whose energy 1/2 |x - (1, 1)|^2 has its minimum at (1, 1). */
static plume_problem *quadratic_problem(size_t term_size, plume_status *added, plume_err *err)
{
    plume_problem *p = NULL;
    if (plume_problem_create(1, 2, 1.0, &p, err) != PLUME_OK)
        return NULL;
    plume_term t = {.size = term_size, .name = "quadratic", .arity = 1, .nstencil = 1, .stencil = one_vertex,
                    .eval = quadratic_eval};
    *added = plume_problem_add_term(p, &t, err);
    return p;
}

void test_struct_growth_term_size(void)
{
    plume_err err = {{0}};
    plume_status added;
    /* a term compiled without the members after `padded`'s predecessors is still whole enough */
    plume_problem *p = quadratic_problem(offsetof(plume_term, hess_range), &added, &err);
    CHECK(p && added == PLUME_OK);
    plume_problem_destroy(&p);
    p = quadratic_problem(0, &added, &err);
    CHECK(added == PLUME_EINVAL && strstr(err.msg, "plume_term.size"));
    fprintf(stderr, "    %s\n", err.msg);
    plume_problem_destroy(&p);
}

void test_struct_growth_options(void)
{
    plume_err err = {{0}};
    plume_status added;
    plume_problem *p = quadratic_problem(sizeof(plume_term), &added, &err);
    CHECK(p && plume_problem_finalize(p, &err) == PLUME_OK);
    if (!p)
        return;
    /* an older caller's solver options: only its first members, the rest left as garbage that the
     * library must not read (it takes the defaults there) */
    plume_solver_opts old;
    memset(&old, 0x7f, sizeof old);
    plume_solver_opts_default_sized(&old, offsetof(plume_solver_opts, tol_violation));
    CHECK(old.size == offsetof(plume_solver_opts, tol_violation) && old.max_iter == 100 && old.tol_kkt == 1e-9);
    unsigned char tail = 0x7f;
    CHECK(memcmp((unsigned char *)&old + old.size, &tail, 1) == 0); /* nothing written past its size */
    plume_solver *s = NULL;
    CHECK(plume_solver_create(PLUME_SOLVER_NEWTON, p, &old, &s, &err) == PLUME_OK);
    double u[2] = {0.0, 0.0};
    plume_solve_report rep;
    CHECK(s && plume_solver_solve(s, u, NULL, &rep) == PLUME_OK && rep.reason == PLUME_REASON_CONVERGED);
    CHECK(fabs(u[0] - 1.0) < 1e-12 && fabs(u[1] - 1.0) < 1e-12);
    plume_solver_destroy(&s);
    /* a struct never filled by its _default: refused, naming it */
    plume_solver_opts unset;
    memset(&unset, 0, sizeof unset);
    CHECK(plume_solver_create(PLUME_SOLVER_NEWTON, p, &unset, &s, &err) == PLUME_EINVAL && s == NULL &&
          strstr(err.msg, "plume_solver_opts.size"));
    fprintf(stderr, "    %s\n", err.msg);
    plume_statics_opts so;
    memset(&so, 0, sizeof so);
    plume_statics *st = NULL;
    CHECK(plume_statics_create(p, &so, NULL, NULL, NULL, &st, &err) == PLUME_EINVAL && st == NULL);
    plume_problem_destroy(&p);
    plume_run_opts ro;
    memset(&ro, 0, sizeof ro);
    plume_scene *scene = NULL;
    CHECK(plume_scene_load("../data/shell/strip_scene.json", &scene, &err) == PLUME_OK);
    plume_run *run = NULL;
    CHECK(plume_run_create(scene, &ro, &run, &err) == PLUME_EINVAL && run == NULL &&
          strstr(err.msg, "plume_run_opts.size"));
    /* reports: the library writes no more than the caller's size */
    CHECK(plume_run_create(scene, NULL, &run, &err) == PLUME_OK);
    plume_run_report small;
    memset(&small, 0x7f, sizeof small);
    plume_run_get_report_sized(run, &small, offsetof(plume_run_report, step));
    CHECK(small.size == offsetof(plume_run_report, step) && small.time == 0.0);
    CHECK(memcmp((unsigned char *)&small + small.size, &tail, 1) == 0);
    plume_run_step_info info;
    memset(&info, 0x7f, sizeof info);
    CHECK(plume_run_step_sized(run, &info, offsetof(plume_run_step_info, load), &err) == PLUME_OK);
    CHECK(info.size == offsetof(plume_run_step_info, load) && info.step.converged);
    CHECK(memcmp((unsigned char *)&info + info.size, &tail, 1) == 0);
    plume_run_destroy(&run);
    plume_scene_destroy(&scene);
}
