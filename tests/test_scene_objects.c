/* Scenes with many objects (macro/scene/scene_objects.c): placement, kinematic bodies and attachments
 * that follow their keyframed rigid motion exactly, errors that name the key, and two feathers
 * pushed through each other by their handles: never an intersecting triangle pair with the
 * barrier (CGAL's exact audit after every step), the paper's penalty measured on the same scene. */
#define _DEFAULT_SOURCE
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "plume_tree.h"
#include "../lib/contact/contact_broad.h"
#include "../lib/core/rigid_motion.h"
#include "app_runner.h"

static void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (f) {
        fputs(text, f);
        fclose(f);
    }
}

static int remove_dir(const char *dir)
{
    char cmd[160];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    return system(cmd);
}

/* materials of a light isotropic sheet (0) and a stiff one (1, the feather's rachis id) */
static const char materials[] =
    "\"materials\": ["
    "{\"membrane\": {\"E\": 1e7, \"nu\": 0.3, \"thickness\": 5e-4}, \"density\": 0.05},"
    "{\"membrane\": {\"E\": 1e9, \"nu\": 0.3, \"thickness\": 2e-3}, \"density\": 0.5}]";

/* a scene with the shipped feather (coarse) attached to a kinematic plate that turns `turn` (an
 * axis and degrees) and slides 1 cm along x in 0.1 s; `extra` is appended inside objects[1] */
static int kinematic_scene_turning(const char *dir, char *path, size_t n, const char *extra, const char *turn)
{
    char feather[PATH_MAX], outline[PATH_MAX], plate[PATH_MAX + 16];
    if (!realpath("../data/feather/feather_shape.json", feather) || !realpath("../data/feather/outline.obj", outline))
        return 0;
    snprintf(plate, sizeof plate, "%s/plate.obj", dir);
    write_file(plate, "v -0.05 -0.3 -0.02\nv 0.05 -0.3 -0.02\nv 0.05 0.1 -0.03\nv -0.05 0.1 -0.03\nf 1 2 3\nf 1 3 4\n");
    static char text[20000];
    snprintf(text, sizeof text,
             "{\"objects\": ["
             "{\"name\": \"plate\", \"kinematic\": {\"obj\": \"plate.obj\", \"pivot\": [0, 0, 0],"
             " \"keyframes\": [[0, 0, 0, 0, 0, 0, 1, 0], [0.1, 0.01, 0, 0, %s]]}},"
             "{\"name\": \"f\", \"mesh\": {\"feather\": \"%s\", \"outline\": \"%s\", \"edge\": 0.02},"
             " \"place\": {\"rotate\": [[0, 0, 1, 90]], \"translate\": [0.1, 0, 0.01], \"scale\": 0.5},"
             " \"attach\": {\"to\": \"plate\", \"near\": [0, 0], \"radius\": 0.006}%s}],"
             "%s, \"dt\": 0.005, \"duration\": 0.1}",
             turn, feather, outline, extra ? extra : "", materials);
    snprintf(path, n, "%s/scene.json", dir);
    write_file(path, text);
    return 1;
}

/* the plate turns 90 degrees about z */
static int kinematic_scene(const char *dir, char *path, size_t n, const char *extra)
{
    return kinematic_scene_turning(dir, path, n, extra, "0, 0, 1, 90");
}

void test_scene_objects_kinematic(void)
{
    char dir[64] = "/tmp/plume-objects-XXXXXX", path[128];
    if (!mkdtemp(dir) || !kinematic_scene(dir, path, sizeof path, NULL)) {
        CHECK(0);
        return;
    }
    plume_scene *s = NULL;
    plume_err err = {{0}};
    CHECK(plume_scene_load(path, &s, &err) == PLUME_OK);
    if (!s) {
        fprintf(stderr, "    %s\n", err.msg);
        return;
    }
    /* the elastic object first, then the kinematic one */
    CHECK(s->nobjects == 2 && strcmp(s->objects[0].name, "f") == 0 && !s->objects[0].kinematic);
    CHECK(strcmp(s->objects[1].name, "plate") == 0 && s->objects[1].kinematic && s->objects[1].nv == 4 &&
          s->objects[1].nt == 2);
    CHECK(s->objects[1].v0 == s->objects[0].nv && s->mesh->nv == s->objects[0].nv + 4);
    CHECK(s->elastic && s->elastic->nt == s->objects[0].nt && s->mesh->nt == s->objects[0].nt + 2);
    CHECK(s->nhandles == 2);
    /* placement: x = t + Rz(90) (X, 0) with X already scaled */
    double worst = 0.0;
    for (plume_index i = 0; i < s->objects[0].nv; i++) {
        const double *X = s->mesh->X + 2 * i, *x = s->mesh->x + 3 * i;
        worst = fmax(worst, fabs(x[0] - (0.1 - X[1])) + fabs(x[1] - X[0]) + fabs(x[2] - 0.01));
    }
    CHECK(worst < 1e-15);
    double ymax = 0.0;
    for (plume_index i = 0; i < s->objects[0].nv; i++)
        ymax = fmax(ymax, s->mesh->X[2 * i + 1]);
    CHECK_REL(ymax, 0.1, 1e-12, 0.0); /* the 0.2 m feather at scale 0.5 */
    /* the plate and the feather's root follow the keyframed motion exactly */
    plume_problem *p = NULL;
    plume_dynamics *d = NULL;
    CHECK(plume_scene_dynamics(s, &p, &d, &err) == PLUME_OK);
    if (d) {
        const plume_handle *h = s->handles; /* the attachment: the feather's root */
        double r0[3], pivot[3] = {0, 0, 0};
        memcpy(r0, s->mesh->x + 3 * h->vertices[0], sizeof r0);
        double err_plate = 0.0, err_root = 0.0;
        int ok = 1;
        for (int k = 0; k < 14 && ok; k++) { /* to t = 0.07, between the two keys */
            plume_step_report rep;
            ok = plume_dynamics_advance(d, 0.0, &rep, NULL) == PLUME_OK && rep.converged;
            double t = plume_dynamics_time(d), a = (t / 0.1) * 90.0 * 3.14159265358979323846 / 180.0;
            double c = cos(a), sn = sin(a), off = 0.01 * t / 0.1;
            const double *x = plume_dynamics_positions(d);
            for (plume_index i = 0; i < 4; i++) {
                const double *y = s->mesh->x + 3 * (s->objects[1].v0 + i), *xi = x + 3 * (s->objects[1].v0 + i);
                double e[3] = {c * y[0] - sn * y[1] + off, sn * y[0] + c * y[1], y[2]};
                for (int q = 0; q < 3; q++)
                    err_plate = fmax(err_plate, fabs(xi[q] - e[q]));
            }
            const double *xr = x + 3 * h->vertices[0];
            double e[3] = {c * r0[0] - sn * r0[1] + off + pivot[0], sn * r0[0] + c * r0[1], r0[2]};
            for (int q = 0; q < 3; q++)
                err_root = fmax(err_root, fabs(xr[q] - e[q]));
        }
        CHECK(ok);
        CHECK(err_plate < 1e-14 && err_root < 1e-14);
        fprintf(stderr, "    plate and root against the analytic rotation + slide: %.2g, %.2g m\n", err_plate, err_root);
    }
    plume_dynamics_destroy(&d);
    plume_problem_destroy(&p);
    plume_scene_destroy(&s);
    CHECK(remove_dir(dir) == 0);
}

/* a variant of the kinematic scene must fail with a message containing `want` */
static void expect_error(const char *dir, const char *from, const char *to, const char *want)
{
    char path[128];
    if (!kinematic_scene(dir, path, sizeof path, NULL)) {
        CHECK(0);
        return;
    }
    FILE *f = fopen(path, "r");
    static char text[20000], out[21000];
    size_t n = f ? fread(text, 1, sizeof text - 1, f) : 0;
    text[n] = 0;
    if (f)
        fclose(f);
    char *at = strstr(text, from);
    CHECK(at != NULL);
    if (!at)
        return;
    snprintf(out, sizeof out, "%.*s%s%s", (int)(at - text), text, to, at + strlen(from));
    write_file(path, out);
    plume_scene *s = NULL;
    plume_err err = {{0}};
    plume_status st = plume_scene_load(path, &s, &err);
    CHECK(st != PLUME_OK && s == NULL);
    CHECK(strstr(err.msg, want) != NULL && strstr(err.msg, "scene.json") != NULL);
    if (!strstr(err.msg, want))
        fprintf(stderr, "    wanted \"%s\" in: %s\n", want, err.msg);
    plume_scene_destroy(&s);
}

void test_scene_objects_errors(void)
{
    char dir[64] = "/tmp/plume-objects-XXXXXX";
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    expect_error(dir, "\"name\": \"f\"", "\"name\": \"plate\"", "objects[1].name \"plate\" is also the name of objects[0]");
    expect_error(dir, "[0.1, 0.01, 0, 0, 0, 0, 1, 90]", "[0, 0.01, 0, 0, 0, 0, 1, 90]", "objects[0].kinematic.keyframes[1]");
    expect_error(dir, "\"to\": \"plate\"", "\"to\": \"wing\"", "objects[1].attach.to must name a kinematic object");
    expect_error(dir, "\"edge\": 0.02", "\"edge\": -1", "objects[1].mesh.edge");
    expect_error(dir, "[[0, 0, 1, 90]]", "[[0, 0, 0, 90]]", "objects[1].place.rotate[0] rotates 90 degrees about a zero axis");
    expect_error(dir, "\"scale\": 0.5", "\"scale\": 0", "objects[1].place.scale");
    expect_error(dir, "\"radius\": 0.006", "\"radius\": 0.006, \"box\": [0, 0, 1, 1]", "objects[1].attach needs exactly one selector");
    expect_error(dir, "\"plate.obj\"", "\"nothing.obj\"", "objects[0].kinematic.obj");
    expect_error(dir, "{\"objects\": [", "{\"mesh\": {\"obj\": \"plate.obj\"}, \"objects\": [", "mesh cannot be given with \"objects\"");
    expect_error(dir, "\"name\": \"plate\", \"kinematic\"", "\"name\": \"plate\", \"attach\": {}, \"kinematic\"",
                 "objects[0] is kinematic");
    expect_error(dir, "\"kinematic\": {\"obj\"", "\"mesh\": {}, \"kinematic\": {\"obj\"", "objects[0] needs exactly one of");
    expect_error(dir, "\"place\": {\"rotate\"", "\"place\": {\"spin\": 1, \"rotate\"", "objects[1].place.spin is an unknown key");
    CHECK(remove_dir(dir) == 0);
}

/* Two coarse feathers crossing at right angles, 5 mm apart; the upper one's root is pushed 3 cm
 * down through the lower one's plane in 0.15 s, its vane dragged across the lower vane. */
typedef struct {
    long steps, intersecting_steps, max_pairs, limited, halvings;
    double dmin;
    int converged;
} push_result;

static void push_through(const char *dir, const char *model, const char *stiffness, int nsteps, const char *limits,
                         push_result *r)
{
    char feather[PATH_MAX], outline[PATH_MAX], path[128];
    memset(r, 0, sizeof *r);
    r->dmin = INFINITY;
    if (!realpath("../data/feather/feather_shape.json", feather) || !realpath("../data/feather/outline.obj", outline)) {
        CHECK(0);
        return;
    }
    static char text[20000];
    snprintf(text, sizeof text,
             "{\"objects\": ["
             "{\"name\": \"lower\", \"mesh\": {\"feather\": \"%s\", \"outline\": \"%s\", \"edge\": 0.012},"
             " \"place\": {\"rotate\": [[0, 0, 1, 180]]},"
             " \"handles\": [{\"near\": [0, 0], \"radius\": 0.006, \"keyframes\": [[0, 0, 0, 0]]}]},"
             "{\"name\": \"upper\", \"mesh\": {\"feather\": \"%s\", \"outline\": \"%s\", \"edge\": 0.012},"
             " \"place\": {\"rotate\": [[0, 0, 1, -90]], \"translate\": [-0.1, -0.1, 0.005]},"
             " \"handles\": [{\"near\": [0, 0], \"radius\": 0.006, \"keyframes\": [[0, 0, 0, 0], [0.15, 0, 0, -0.03]]}]}],"
             "%s, \"contact\": {\"model\": \"%s\", \"dhat\": 1e-3, \"stiffness\": %s},"
             " \"gravity\": [0, 0, 0], \"dt\": 0.005, \"duration\": 0.2, %s}",
             feather, outline, feather, outline, materials, model, stiffness, limits);
    snprintf(path, sizeof path, "%s/push_%s.json", dir, model);
    write_file(path, text);
    plume_scene *s = NULL;
    plume_problem *p = NULL;
    plume_dynamics *d = NULL;
    plume_contact_broad *measure = NULL;
    plume_err err = {{0}};
    CHECK(plume_scene_load(path, &s, &err) == PLUME_OK && s->has_contact);
    if (!s) {
        fprintf(stderr, "    %s\n", err.msg);
        return;
    }
    CHECK(plume_scene_dynamics(s, &p, &d, &err) == PLUME_OK);
    int *body = malloc((size_t)s->mesh->nv * sizeof *body);
    CHECK(body && plume_scene_bodies(s, body) == 2);
    plume_contact_broad_opts bo;
    plume_contact_broad_opts_default(&bo);
    bo.self_contact = 0;
    CHECK(plume_contact_broad_create(s->mesh->nv, s->mesh->nt, s->mesh->tri, body, &bo, &measure, &err) == PLUME_OK);
    plume_contact_pairs pairs = {0};
    r->converged = d != NULL && measure != NULL;
    for (int k = 0; r->converged && k < nsteps; k++) {
        plume_step_report rep;
        CHECK(plume_dynamics_advance(d, 0.0, &rep, NULL) == PLUME_OK);
        r->converged = rep.converged;
        r->limited += rep.step_limited;
        r->halvings += rep.halvings;
        if (!rep.converged) {
            fprintf(stderr, "    %s: step %d not converged (%s)\n", model, k, plume_reason_name(rep.reason));
            break;
        }
        const double *x = plume_dynamics_positions(d);
        plume_contact_audit audit;
        double dm = 0.0;
        CHECK(plume_contact_count_intersections(s->mesh->nv, x, s->mesh->nt, s->mesh->tri, &pairs, &audit, &err) == PLUME_OK);
        CHECK(plume_contact_min_distance(measure, x, 0.01, &dm, &err) == PLUME_OK);
        r->steps++;
        r->intersecting_steps += audit.intersecting > 0;
        if (audit.intersecting > r->max_pairs)
            r->max_pairs = audit.intersecting;
        r->dmin = fmin(r->dmin, dm);
    }
    /* the push went through the lower plane: the upper root ends 2.5 cm below it */
    if (d && r->converged && nsteps == 40) {
        const double *x = plume_dynamics_positions(d);
        CHECK(x[3 * s->handles[1].vertices[0] + 2] < -0.02);
    }
    plume_contact_pairs_free(&pairs);
    plume_contact_broad_destroy(&measure);
    free(body);
    plume_dynamics_destroy(&d);
    plume_problem_destroy(&p);
    plume_scene_destroy(&s);
}

void test_scene_objects_feathers_pushed(void)
{
    char dir[64] = "/tmp/plume-push-XXXXXX";
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    push_result b, q;
    push_through(dir, "barrier", "1.0", 40, "\"max_halvings\": 10", &b);
    /* the paper's penalty is so stiff that newton crawls once the vanes touch (the paper's solver
     * failures): its first steps, with few halvings, measure it */
    push_through(dir, "penalty", "1e11", 12, "\"max_halvings\": 1, \"max_iter\": 60", &q);
    fprintf(stderr, "    barrier: %ld steps, intersecting in %ld (at most %ld pairs), smallest distance %.3g m, %ld CCD-limited, "
                    "%ld halvings\n",
            b.steps, b.intersecting_steps, b.max_pairs, b.dmin, b.limited, b.halvings);
    fprintf(stderr, "    penalty 1e11: %ld steps%s, intersecting in %ld (at most %ld pairs), smallest distance %.3g m, %ld halvings\n",
            q.steps, q.converged ? "" : " (then a step failed)", q.intersecting_steps, q.max_pairs, q.dmin, q.halvings);
    CHECK(b.converged && b.steps == 40);
    CHECK(b.intersecting_steps == 0 && b.dmin > 0.0);
    CHECK(b.dmin < 1e-3); /* the vanes did touch: the barrier was active */
    CHECK(q.steps > 0); /* the penalty's measures are reported above, whatever they are */
    CHECK(remove_dir(dir) == 0);
}

/* A stiff 10 cm plate resting on a fixed kinematic ground under gravity tilted by theta (the same
 * as a slope), with lagged friction mu: its mean velocity after `steps` steps of 5 ms, and its
 * acceleration between t = 0.05 s and the end (the first step has no lagged pair yet). */
static int slope_run(const char *dir, double tan_theta, double mu, int steps, double *v_end, double *accel)
{
    char path[128], ground[128];
    snprintf(ground, sizeof ground, "%s/ground.obj", dir);
    write_file(ground, "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3\nf 1 3 4\n");
    double th = atan(tan_theta), g = 9.81;
    static char text[4096];
    char friction[64] = "";
    if (mu > 0.0)
        snprintf(friction, sizeof friction, ", \"friction\": %g", mu);
    snprintf(text, sizeof text,
             "{\"objects\": [{\"name\": \"ground\", \"kinematic\": {\"obj\": \"ground.obj\", \"keyframes\": [[0, 0, 0, 0]]}},"
             "{\"name\": \"plate\", \"mesh\": {\"rectangle\": [0.1, 0.1], \"edge\": 0.05, \"pattern\": \"grid\"},"
             " \"place\": {\"translate\": [-0.05, -0.05, 0.0005]}}],"
             "\"materials\": [{\"membrane\": {\"E\": 1e9, \"nu\": 0.3, \"thickness\": 1e-3}, \"density\": 1.0}],"
             "\"contact\": {\"model\": \"barrier\", \"dhat\": 1e-3, \"stiffness\": 10%s},"
             "\"gravity\": [%.17g, 0, %.17g], \"dt\": 0.005, \"duration\": 1}",
             friction, g * sin(th), -g * cos(th));
    snprintf(path, sizeof path, "%s/slope.json", dir);
    write_file(path, text);
    plume_scene *s = NULL;
    plume_problem *p = NULL;
    plume_dynamics *d = NULL;
    plume_err err = {{0}};
    int ok = plume_scene_load(path, &s, &err) == PLUME_OK && plume_scene_dynamics(s, &p, &d, &err) == PLUME_OK;
    if (!ok)
        fprintf(stderr, "    %s\n", err.msg);
    double v_mid = 0.0;
    for (int k = 0; ok && k < steps; k++) {
        plume_step_report rep;
        ok = plume_dynamics_advance(d, 0.0, &rep, NULL) == PLUME_OK && rep.converged;
        const double *v = plume_dynamics_velocities(d);
        double vx = 0.0;
        for (plume_index i = 0; i < s->objects[0].nv; i++)
            vx += v[3 * (s->objects[0].v0 + i)] / (double)s->objects[0].nv;
        if (k == 9)
            v_mid = vx;
        *v_end = vx;
    }
    *accel = (*v_end - v_mid) / (0.005 * (steps - 10));
    plume_dynamics_destroy(&d);
    plume_problem_destroy(&p);
    plume_scene_destroy(&s);
    return ok;
}

void test_scene_objects_friction_slope(void)
{
    char dir[64] = "/tmp/plume-slope-XXXXXX";
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    const double g = 9.81, mu = 0.5;
    double v, a;
    /* steep (tan 0.8 > mu): slides at g (sin - mu cos); without friction at g sin */
    double th = atan(0.8);
    CHECK(slope_run(dir, 0.8, mu, 40, &v, &a));
    double expect = g * (sin(th) - mu * cos(th));
    fprintf(stderr, "    slope tan 0.8, mu 0.5: acceleration %.4g m/s^2 (Coulomb %.4g)\n", a, expect);
    CHECK(fabs(a - expect) < 0.01 * expect);
    CHECK(slope_run(dir, 0.8, 0.0, 40, &v, &a));
    fprintf(stderr, "    slope tan 0.8, no friction: acceleration %.4g m/s^2 (%.4g)\n", a, g * sin(th));
    CHECK(fabs(a - g * sin(th)) < 0.01 * g * sin(th));
    /* gentle (tan 0.3 < mu): sticks; the smoothed friction lets it creep below eps_v only */
    CHECK(slope_run(dir, 0.3, mu, 40, &v, &a));
    fprintf(stderr, "    slope tan 0.3, mu 0.5: velocity after 0.2 s %.3g m/s (sticks; eps_v 1e-3)\n", v);
    CHECK(fabs(v) < 1e-3);
    CHECK(remove_dir(dir) == 0);
}

/* OBJ shells as objects: two placed copies of the shipped strip, the second turned upright and
 * scaled; materials by group, vertex selectors in the OBJ's own numbering, one body each. */
void test_scene_objects_obj_shells(void)
{
    char dir[64] = "/tmp/plume-objshell-XXXXXX", strip[PATH_MAX], path[128];
    if (!mkdtemp(dir) || !realpath("../data/shell/strip.obj", strip)) {
        CHECK(0);
        return;
    }
    static char text[20000];
    snprintf(text, sizeof text,
             "{\"objects\": ["
             "{\"name\": \"a\", \"mesh\": {\"obj\": \"%s\", \"materials_by_group\": {\"strip\": 1}},"
             " \"handles\": [{\"vertices\": [0, 1], \"keyframes\": [[0, 0, 0, 0]]}]},"
             "{\"name\": \"b\", \"mesh\": {\"obj\": \"%s\"},"
             " \"place\": {\"rotate\": [[1, 0, 0, 90]], \"translate\": [0, 0.5, 0.2], \"scale\": 2}}],"
             "%s, \"dt\": 0.01, \"duration\": 0.02}",
             strip, strip, materials);
    snprintf(path, sizeof path, "%s/shells.json", dir);
    write_file(path, text);
    plume_scene *s = NULL;
    plume_err err = {{0}};
    CHECK(plume_scene_load(path, &s, &err) == PLUME_OK);
    if (!s) {
        fprintf(stderr, "    %s\n", err.msg);
        return;
    }
    CHECK(s->nobjects == 2 && s->objects[0].nv == 125 && s->objects[1].nv == 125 && s->elastic == NULL);
    CHECK(s->mesh->material[0] == 1 && s->mesh->material[s->objects[1].t0] == 0);
    CHECK(s->nhandles == 1 && s->handles[0].nvertices == 2);
    int *body = malloc((size_t)s->mesh->nv * sizeof *body);
    CHECK(body && plume_scene_bodies(s, body) == 2);
    free(body);
    /* b: x = (0, 0.5, 0.2) + Rx(90) (2 X, 0) = (2 X0, 0.5, 0.2 + 2 X1) */
    double worst = 0.0;
    for (plume_index i = 0; i < 125; i++) {
        plume_index v = s->objects[1].v0 + i;
        const double *X = s->mesh->X + 2 * v, *x = s->mesh->x + 3 * v;
        worst = fmax(worst, fabs(x[0] - X[0]) + fabs(x[1] - 0.5) + fabs(x[2] - (0.2 + X[1])));
    }
    CHECK(worst < 1e-15);
    plume_problem *p = NULL;
    plume_dynamics *d = NULL;
    CHECK(plume_scene_dynamics(s, &p, &d, &err) == PLUME_OK);
    plume_step_report rep;
    CHECK(d && plume_dynamics_advance(d, 0.0, &rep, NULL) == PLUME_OK && rep.converged);
    plume_dynamics_destroy(&d);
    plume_problem_destroy(&p);
    plume_scene_destroy(&s);
    CHECK(remove_dir(dir) == 0);
}

/* A contact scene that starts crossed: a plate through a kinematic ground at rest, or a
 * ground whose first keyframe (t = 0) lifts it through the plate, is refused before any step with a
 * message naming both bodies, instead of failing the first step's line search. */
static plume_status start_run(const char *dir, const char *ground_key, double plate_z, plume_err *err)
{
    char path[128], ground[128];
    snprintf(ground, sizeof ground, "%s/ground.obj", dir);
    write_file(ground, "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3\nf 1 3 4\n");
    static char text[4096];
    snprintf(text, sizeof text,
             "{\"objects\": [{\"name\": \"ground\", \"kinematic\": {\"obj\": \"ground.obj\", \"keyframes\": [%s]}},"
             "{\"name\": \"plate\", \"mesh\": {\"rectangle\": [0.1, 0.1], \"edge\": 0.05, \"pattern\": \"grid\"},"
             " \"place\": {\"rotate\": [[1, 0, 0, 30]], \"translate\": [-0.05, -0.05, %.17g]}}],"
             "\"materials\": [{\"membrane\": {\"E\": 1e9, \"nu\": 0.3, \"thickness\": 1e-3}, \"density\": 1.0}],"
             "\"contact\": {\"model\": \"barrier\", \"dhat\": 1e-3, \"stiffness\": 10},"
             "\"gravity\": [0, 0, -9.81], \"dt\": 0.005, \"duration\": 1}",
             ground_key, plate_z);
    snprintf(path, sizeof path, "%s/start.json", dir);
    write_file(path, text);
    plume_scene *s = NULL;
    plume_problem *p = NULL;
    plume_dynamics *d = NULL;
    plume_status st = plume_scene_load(path, &s, err);
    if (st == PLUME_OK)
        st = plume_scene_dynamics(s, &p, &d, err);
    plume_dynamics_destroy(&d);
    plume_problem_destroy(&p);
    plume_scene_destroy(&s);
    return st;
}

void test_scene_objects_start_crossed(void)
{
    char dir[64] = "/tmp/plume-start-XXXXXX";
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    plume_err err = {{0}};
    /* apart: fine (the plate tilted by 30 degrees, its lowest edge 2 mm above the ground) */
    CHECK(start_run(dir, "[0, 0, 0, 0]", 0.002, &err) == PLUME_OK);
    /* tilted through the ground at rest */
    CHECK(start_run(dir, "[0, 0, 0, 0]", -0.01, &err) == PLUME_EINVAL);
    fprintf(stderr, "    %s\n", err.msg);
    CHECK(strstr(err.msg, "'ground'") && strstr(err.msg, "'plate'") && strstr(err.msg, "intersect at rest") &&
          strstr(err.msg, "triangles"));
    /* the ground's keyframe at t = 0 lifts it 2 cm, through the plate */
    memset(&err, 0, sizeof err);
    CHECK(start_run(dir, "[0, 0, 0, 0.02], [1, 0, 0, 0.02]", 0.002, &err) == PLUME_EINVAL);
    fprintf(stderr, "    %s\n", err.msg);
    CHECK(strstr(err.msg, "keyframes at t = 0") && strstr(err.msg, "'ground'") && strstr(err.msg, "'plate'"));
    /* a keyframe at t = 0 that moves the ground away from the plate is no crossing */
    CHECK(start_run(dir, "[0, 0, 0, -0.02], [1, 0, 0, -0.02]", 0.002, &err) == PLUME_OK);
    char cmd[96];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    CHECK(system(cmd) == 0);
}

/* A kinematic body driven through a free sheet faster than contact can push the sheet away (the
 * ground rises 0.5 m in 5 ms through a plate 2 mm above it): the step fails at the smallest step
 * with its own reason, the contact term names the pair that stopped the prescribed motion (one
 * vertex of each body), and apps/feather's message names both bodies and the step. */
void test_scene_objects_prescribed_crossing(void)
{
    char dir[64] = "/tmp/plume-through-XXXXXX", path[128], ground[128], args[256], out[4096], errs[4096];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    snprintf(ground, sizeof ground, "%s/ground.obj", dir);
    write_file(ground, "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3\nf 1 3 4\n");
    snprintf(path, sizeof path, "%s/through.json", dir);
    write_file(path,
               "{\"objects\": [{\"name\": \"ground\", \"kinematic\": {\"obj\": \"ground.obj\", \"keyframes\": "
               "[[0, 0, 0, 0], [0.01, 0, 0, 0], [0.015, 0, 0, 0.5]]}},"
               "{\"name\": \"plate\", \"mesh\": {\"rectangle\": [0.1, 0.1], \"edge\": 0.05, \"pattern\": \"grid\"},"
               " \"place\": {\"translate\": [-0.05, -0.05, 0.002]}}],"
               "\"materials\": [{\"membrane\": {\"E\": 1e9, \"nu\": 0.3, \"thickness\": 1e-3}, \"density\": 1.0}],"
               "\"contact\": {\"model\": \"barrier\", \"dhat\": 1e-3, \"stiffness\": 10},"
               "\"gravity\": [0, 0, 0], \"dt\": 0.005, \"duration\": 0.015, \"max_halvings\": 4}");
    plume_err err = {{0}};
    plume_scene *s = NULL;
    plume_problem *p = NULL;
    plume_dynamics *d = NULL;
    plume_contact *c = NULL;
    CHECK(plume_scene_load(path, &s, &err) == PLUME_OK);
    CHECK(s && plume_scene_dynamics_contact(s, &p, &d, &c, &err) == PLUME_OK);
    plume_step_report rep = {0};
    int steps = 0;
    for (; d && steps < 3; steps++)
        if (plume_dynamics_advance(d, 0.0, &rep, &err) != PLUME_OK || !rep.converged)
            break;
    CHECK(steps == 2 && !rep.converged && rep.reason == PLUME_REASON_PRESCRIBED_CROSSING && rep.halvings == 4);
    plume_index v[4];
    int ee = -1;
    double toi = 2.0;
    CHECK(plume_contact_last_limit(c, v, &ee, &toi) == 1 && toi >= 0.0 && toi < 1.0 && (ee == 0 || ee == 1));
    if (s && s->nobjects == 2) { /* one vertex of each body among the pair's */
        const plume_scene_object *g = s->objects, *q = s->objects + 1;
        int in_ground = 0, in_plate = 0;
        for (int k = 0; k < 4; k++) {
            in_ground |= v[k] >= g->v0 && v[k] < g->v0 + g->nv;
            in_plate |= v[k] >= q->v0 && v[k] < q->v0 + q->nv;
        }
        CHECK(in_ground && in_plate);
    }
    plume_dynamics_destroy(&d);
    plume_problem_destroy(&p);
    plume_scene_destroy(&s);
    snprintf(args, sizeof args, "%s -o %s/out --quiet", path, dir);
    CHECK(app_run(dir, "feather", args, out, sizeof out, errs, sizeof errs) == 3);
    fprintf(stderr, "    %s", errs);
    CHECK(strstr(errs, "step 3 ") && strstr(errs, "'ground'") && strstr(errs, "'plate'") &&
          strstr(errs, "prescribed motion runs into a body"));
    char cmd[96];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    CHECK(system(cmd) == 0);
}

/* Midedge bending on the feather attached to the turning plate: the attachment's edges would need
 * their directors turned with the plate, which the term does not do yet, so the scene's problem is
 * refused naming the handle; the shape operator's is built. */
/* The feather's tip: its vertex farthest from the attachment at the start. */
static plume_index tip_vertex(const plume_scene *s, const plume_handle *attach)
{
    plume_index tip = 0;
    double best = -1.0;
    const double *a = s->mesh->x + 3 * attach->vertices[0];
    for (plume_index v = 0; v < s->objects[0].nv; v++) {
        const double *x = s->mesh->x + 3 * v;
        const double d = (x[0] - a[0]) * (x[0] - a[0]) + (x[1] - a[1]) * (x[1] - a[1]) + (x[2] - a[2]) * (x[2] - a[2]);
        if (d > best)
            best = d, tip = v;
    }
    return tip;
}

/* Midedge bending with a turning handle: the plate tilts 40 degrees about y and carries the
 * feather's base; the directors of the edges the attachment holds turn with it (R e_z to rounding,
 * e_z their placed rest director), and the tip ends where the shape operator puts it, within a
 * few percent of its travel. A handle on one line cannot turn its edges: refused, naming it. */
void test_scene_objects_midedge_rotating_handle(void)
{
    char dir[64] = "/tmp/plume-objects-XXXXXX", path[128];
    if (!mkdtemp(dir) || !kinematic_scene_turning(dir, path, sizeof path, NULL, "0, 1, 0, 40")) {
        CHECK(0);
        return;
    }
    double tip_end[2][3] = {{0}}, tip0[3] = {0};
    for (int model = 0; model < 2; model++) {
        plume_scene *s = NULL;
        plume_err err = {{0}};
        plume_problem *p = NULL;
        plume_dynamics *d = NULL;
        CHECK(plume_scene_load(path, &s, &err) == PLUME_OK);
        CHECK(s && plume_scene_set(s, model ? "{\"bending_model\": \"midedge\"}" : "{}", &err) == PLUME_OK);
        CHECK(s && plume_scene_dynamics(s, &p, &d, &err) == PLUME_OK);
        if (!p) {
            fprintf(stderr, "    %s\n", err.msg);
            plume_scene_destroy(&s);
            break;
        }
        const plume_handle *attach = NULL; /* the handle on the feather's vertices */
        for (int h = 0; h < s->nhandles; h++)
            if (s->handles[h].vertices[0] < s->objects[0].nv)
                attach = &s->handles[h];
        CHECK(attach != NULL);
        if (!attach)
            break;
        const plume_index tip = tip_vertex(s, attach);
        memcpy(tip0, s->mesh->x + 3 * tip, sizeof tip0);
        int steps = 0, converged = 1;
        while (plume_dynamics_time(d) < 0.1 - 1e-9 && converged && steps < 100) {
            plume_step_report rep;
            CHECK(plume_dynamics_advance(d, 0.0, &rep, &err) == PLUME_OK);
            converged = rep.converged;
            steps++;
        }
        CHECK(converged);
        const double *x = plume_problem_x(p);
        memcpy(tip_end[model], x + 3 * tip, sizeof tip_end[model]);
        if (model == 1) {
            plume_midedge_term *t = plume_problem_term_ctx(p, PLUME_MIDEDGE_TERM_NAME);
            const plume_index ne = t ? plume_midedge_term_nedge(t) : 0;
            double *dir3 = malloc((size_t)(3 * ne + 1) * sizeof *dir3), worst = 0.0;
            unsigned char *on = calloc((size_t)s->objects[0].nv + 1, 1);
            const double c = cos(40.0 * M_PI / 180.0), sn = sin(40.0 * M_PI / 180.0), Rz[3] = {sn, 0.0, c};
            int nheld = 0;
            if (t && dir3 && on) {
                plume_midedge_term_directors(t, x, dir3);
                for (plume_index i = 0; i < attach->nvertices; i++)
                    on[attach->vertices[i]] = 1;
                const plume_mesh *m = s->elastic;
                for (plume_index e = 0; e < m->ne; e++)
                    if (on[m->edges[2 * e]] && on[m->edges[2 * e + 1]]) {
                        nheld++;
                        for (int k = 0; k < 3; k++)
                            worst = fmax(worst, fabs(dir3[3 * e + k] - Rz[k]));
                    }
            }
            fprintf(stderr, "    %d steps; the %d edges the turned attachment holds: directors within %.1e of R e_z\n", steps,
                    nheld, worst);
            CHECK(nheld > 0 && worst < 1e-9);
            free(dir3);
            free(on);
        }
        plume_dynamics_destroy(&d);
        plume_problem_destroy(&p);
        plume_scene_destroy(&s);
    }
    const double travel = sqrt(pow(tip_end[0][0] - tip0[0], 2) + pow(tip_end[0][1] - tip0[1], 2) + pow(tip_end[0][2] - tip0[2], 2));
    const double gap = sqrt(pow(tip_end[1][0] - tip_end[0][0], 2) + pow(tip_end[1][1] - tip_end[0][1], 2) +
                            pow(tip_end[1][2] - tip_end[0][2], 2));
    fprintf(stderr, "    tip travel %.4f m (shape operator); midedge ends %.2e m from it (%.2f %% of the travel)\n", travel, gap,
            100.0 * gap / travel);
    CHECK(travel > 0.01 && gap < 0.05 * travel);
    /* a turning attachment on one line (an OBJ strip held by its three vertices along y = 0) gives
     * its edges no frame: refused, naming the handle */
    char strip[PATH_MAX + 16], text[4096];
    snprintf(strip, sizeof strip, "%s/line.obj", dir);
    write_file(strip, "v 0 0 0\nv 0.01 0 0\nv 0.02 0 0\nv 0 0.01 0\nv 0.01 0.01 0\nv 0.02 0.01 0\n"
                      "f 1 2 5\nf 1 5 4\nf 2 3 6\nf 2 6 5\n");
    snprintf(text, sizeof text,
             "{\"objects\": [{\"name\": \"plate\", \"kinematic\": {\"obj\": \"plate.obj\", \"keyframes\": "
             "[[0, 0, 0, 0, 0, 1, 0, 0], [0.1, 0, 0, 0, 0, 1, 0, 40]]}},"
             "{\"name\": \"s\", \"mesh\": {\"obj\": \"line.obj\"}, \"attach\": {\"to\": \"plate\", \"vertices\": [0, 1, 2]}}],"
             "%s, \"bending_model\": \"midedge\", \"dt\": 0.005, \"duration\": 0.1}",
             materials);
    snprintf(path, sizeof path, "%s/line.json", dir);
    write_file(path, text);
    plume_scene *s = NULL;
    plume_err err = {{0}};
    plume_problem *p = NULL;
    plume_dynamics *d = NULL;
    CHECK(plume_scene_load(path, &s, &err) == PLUME_OK);
    CHECK(s && plume_scene_dynamics(s, &p, &d, &err) == PLUME_EINVAL && !p && !d);
    fprintf(stderr, "    %s\n", err.msg);
    CHECK(strstr(err.msg, "rotates") && strstr(err.msg, "one line"));
    plume_scene_destroy(&s);
    CHECK(remove_dir(dir) == 0);
}
