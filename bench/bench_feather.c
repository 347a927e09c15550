/* make bench (third part) — the shipped feather (data/feather/scene_anisotropic.json) at two
 * resolutions: seconds per frame and Newton iterations per step for `newton`, `ipopt` and
 * `linearized`, side by side, over the first steps of the scene (the rachis tip being pulled). */
#define _DEFAULT_SOURCE
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <jansson.h>

#include "../include/plume.h"

#define STEPS 20

/* A copy of the scene with another mesh edge and solver, paths made absolute, in /tmp. */
static int variant(const char *scene, double edge, const char *solver, char *out, size_t n)
{
    char dir[PATH_MAX];
    if (!realpath(scene, dir))
        return -1;
    *strrchr(dir, '/') = '\0';
    json_error_t je;
    json_t *j = json_load_file(scene, 0, &je);
    if (!j)
        return -1;
    json_t *mesh = json_object_get(j, "mesh");
    const char *keys[2] = {"feather", "outline"};
    for (int k = 0; k < 2; k++) {
        char p[PATH_MAX + 256];
        snprintf(p, sizeof p, "%s/%s", dir, json_string_value(json_object_get(mesh, keys[k])));
        json_object_set_new(mesh, keys[k], json_string(p));
    }
    json_object_set_new(mesh, "edge", json_real(edge));
    json_object_set_new(j, "solver", json_string(solver));
    snprintf(out, n, "/tmp/plume-bench-feather-%d.json", (int)getpid());
    int rc = json_dump_file(j, out, JSON_INDENT(1));
    json_decref(j);
    return rc;
}

int main(int argc, char **argv)
{
    plume_openmp_serial(); /* CHOLMOD's 4-thread OpenMP loops cost more than they save here */
    const char *scene = argc > 1 ? argv[1] : "data/feather/scene_anisotropic.json";
    const double edges[2] = {5e-3, 3.5e-3};
    const char *solvers[3] = {"newton", "ipopt", "linearized"};
    printf("\nplume bench (feather): %s, first %d steps, seconds per frame (= step) and Newton iterations per step\n",
           scene, STEPS);
    printf("%8s %9s | %-10s | %9s %8s %8s %9s | %s\n", "edge", "elements", "solver", "s/frame", "it/step", "halved",
           "violation", "vs newton");
    for (int e = 0; e < 2; e++) {
        double t_newton = NAN;
        for (int k = 0; k < 3; k++) {
            char path[256];
            plume_err err = {{0}};
            plume_scene *s = NULL;
            plume_problem *p = NULL;
            plume_dynamics *d = NULL;
            if (variant(scene, edges[e], solvers[k], path, sizeof path) != 0 || plume_scene_load(path, &s, &err) != PLUME_OK ||
                plume_scene_dynamics(s, &p, &d, &err) != PLUME_OK) {
                printf("%8.4f           | %-10s | setup failed: %s\n", edges[e], solvers[k], err.msg);
                plume_scene_destroy(&s);
                unlink(path);
                continue;
            }
            int iterations = 0, halvings = 0, steps = 0, ok = 1;
            double seconds = 0.0, viol = 0.0;
            for (; steps < STEPS && ok; steps++) {
                plume_step_report rep;
                if (plume_dynamics_advance(d, 0.0, &rep, NULL) != PLUME_OK)
                    break;
                iterations += rep.iterations, halvings += rep.halvings, seconds += rep.seconds;
                viol = fmax(viol, rep.max_violation);
                ok = rep.converged;
            }
            double per = seconds / steps;
            if (k == 0)
                t_newton = per;
            printf("%8.4f %9ld | %-10s | %9.4f %8.1f %8d %9.1e | %s%.2fx%s\n", edges[e], (long)s->mesh->nt, solvers[k], per,
                   (double)iterations / steps, halvings, viol, "", per / t_newton,
                   ok ? "" : k == 2 ? "  (single steps: not converged by design)" : "  (FAILED to converge)");
            plume_dynamics_destroy(&d);
            plume_problem_destroy(&p);
            plume_scene_destroy(&s);
            unlink(path);
        }
    }
    return 0;
}
