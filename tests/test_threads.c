/* Two problems solved at once in two threads give the serial answers bit for bit: the library
 * keeps no global state (docs/library.md, "Threads"). Each job is run alone first, then two at once,
 * and their results are compared with memcmp: the macro traction test at two angles, a
 * homogenisation beside a traction test, and a dynamic scene stepped twice. Only the public face
 * is used, as a program outside the tree would. */
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../include/plume/plume.h"
#include "harness.h"

/* a job and what it gave: a curve (traction), moduli (homogenisation) or positions (a scene) */
typedef struct {
    int kind;              /* 0 traction, 1 homogenisation, 2 scene */
    double angle;          /* traction: barbs from the pull (deg) */
    plume_status status;
    char msg[768];         /* the error, when status is not PLUME_OK */
    double *values;        /* the result, malloc'ed */
    long n;                /* its length */
} job;

static void run_traction(job *j)
{
    plume_err err = {{0}};
    plume_mesh *mesh = NULL;
    plume_problem *p = NULL;
    plume_index *barbs = NULL, nb = 0;
    plume_vane vane;
    plume_vane_default(&vane);
    j->status = plume_patch_mesh(1.0, 1.3, j->angle, 0.03, PLUME_PATCH_ALIGNED, 2, &mesh, &err);
    if (!j->status)
        j->status = plume_problem_create(mesh->nv, 2, 1.3, &p, &err);
    if (!j->status)
        j->status = plume_vane_add(p, mesh, &vane, &barbs, &nb, &err);
    if (!j->status) {
        plume_traction_opts o;
        plume_traction_opts_default(&o);
        o.lx = 1.0, o.ly = 1.3, o.h = vane.h, o.steps = 4;
        plume_traction_result r;
        j->status = plume_traction_run(mesh, p, barbs, nb, &o, &r, &err);
        if (!j->status) {
            j->n = 2 * (long)r.curve.n;
            j->values = malloc((size_t)j->n * sizeof *j->values);
            memcpy(j->values, r.curve.stress, (size_t)r.curve.n * sizeof(double));
            memcpy(j->values + r.curve.n, r.curve.wbar, (size_t)r.curve.n * sizeof(double));
            plume_traction_result_free(&r);
        }
    }
    if (j->status)
        snprintf(j->msg, sizeof j->msg, "%s", err.msg);
    free(barbs);
    plume_problem_destroy(&p);
    plume_mesh_destroy(&mesh);
}

static void run_homogenisation(job *j)
{
    plume_err err = {{0}};
    plume_layout l;
    plume_layout_default(&l);
    plume_homog_opts o;
    plume_homog_opts_default(&o);
    o.steps = 2;
    o.convergence = 0;
    plume_homog_result r;
    j->status = plume_homogenize(&l, &o, &r, &err);
    if (!j->status) {
        j->n = 4 + 9 + 9;
        j->values = malloc((size_t)j->n * sizeof *j->values);
        j->values[0] = r.moduli.E_xx;
        j->values[1] = r.moduli.E_yy;
        j->values[2] = r.moduli.nu_xy;
        j->values[3] = r.moduli.G_xy;
        memcpy(j->values + 4, r.C, sizeof r.C);
        memcpy(j->values + 13, r.D, sizeof r.D);
        plume_homog_result_free(&r);
    } else
        snprintf(j->msg, sizeof j->msg, "%s", err.msg);
}

static void run_scene(job *j)
{
    char msg[512];
    plume_flat_scene *s = NULL;
    j->status = plume_flat_scene_open("../data/feather/scene_anisotropic.json", &s, msg, sizeof msg);
    if (!j->status)
        j->status = plume_flat_scene_step(s, 3, NULL, msg, sizeof msg);
    if (j->status)
        snprintf(j->msg, sizeof j->msg, "%s", msg);
    else {
        j->n = 3 * plume_flat_scene_nv(s);
        j->values = malloc((size_t)j->n * sizeof *j->values);
        plume_flat_scene_positions(s, j->values);
    }
    plume_flat_scene_close(&s);
}

static void *run_job(void *arg)
{
    job *j = arg;
    if (j->kind == 0)
        run_traction(j);
    else if (j->kind == 1)
        run_homogenisation(j);
    else
        run_scene(j);
    return NULL;
}

/* a and b alone, then together in two threads: each result the same bits as alone */
static void alone_and_together(job a, job b)
{
    job sa = a, sb = b, ta = a, tb = b;
    run_job(&sa);
    run_job(&sb);
    if (sa.status || sb.status)
        fprintf(stderr, "    alone: %s%s\n", sa.msg, sb.msg);
    CHECK(sa.status == PLUME_OK && sb.status == PLUME_OK && sa.n > 0 && sb.n > 0);
    pthread_t t1, t2;
    CHECK(pthread_create(&t1, NULL, run_job, &ta) == 0);
    CHECK(pthread_create(&t2, NULL, run_job, &tb) == 0);
    pthread_join(t1, NULL);
    pthread_join(t2, NULL);
    CHECK(ta.status == PLUME_OK && tb.status == PLUME_OK);
    CHECK(ta.n == sa.n && tb.n == sb.n);
    for (long i = 0; ta.n == sa.n && ta.values && sa.values && i < sa.n; i++)
        if (ta.values[i] != sa.values[i])
            fprintf(stderr, "    a[%ld]: alone %.17g, in a thread %.17g\n", i, sa.values[i], ta.values[i]);
    if (ta.n == sa.n && ta.values && sa.values)
        CHECK(memcmp(ta.values, sa.values, (size_t)sa.n * sizeof(double)) == 0);
    if (tb.n == sb.n && tb.values && sb.values)
        CHECK(memcmp(tb.values, sb.values, (size_t)sb.n * sizeof(double)) == 0);
    fprintf(stderr, "    %ld and %ld values, the same bits in two threads as alone\n", sa.n, sb.n);
    free(sa.values);
    free(sb.values);
    free(ta.values);
    free(tb.values);
}

void test_threads_traction_pair(void)
{
    alone_and_together((job){.kind = 0, .angle = 45}, (job){.kind = 0, .angle = 60});
}

void test_threads_homogenise_beside_traction(void)
{
    alone_and_together((job){.kind = 1}, (job){.kind = 0, .angle = 50});
}

void test_threads_scenes(void)
{
    alone_and_together((job){.kind = 2}, (job){.kind = 2});
}
