/* plume: the flat interface for bindings (flat.h) — a scene handle with plain arrays, and a frames
 * file written as glTF. */
#include "flat.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <jansson.h>

#include "../include/plume/plume.h"
#include "internal/flat_common.h"
#include "internal/scene_description.h"

/* ------------------------------------------------------------------------------------------ */
/* scenes */

struct plume_flat_scene {
    plume_scene *scene;
    const plume_mesh *mesh; /* the scene's */
    plume_run *run;       /* open-ended, no frames, no contact audit (include/plume/scene.h) */
    plume_fields *fields; /* the ParaView series, once write_vtk is called */
    char *vtk_dir;
    long vtk_frames;
    char *frames_path;    /* the frames file write_frames appends to, once called */
};

/* 1 when the scene is static (its description's "solve") */
static int is_static(const plume_scene *scene)
{
    json_t *j = plume_scene_description(scene, NULL);
    int yes = j && strcmp(json_string_value(json_object_get(j, "solve")), "static") == 0;
    json_decref(j);
    return yes;
}

/* opens the scene document `json` standing for `path`, or (json NULL) the file at path */
static plume_status scene_open(const char *json, const char *path, plume_flat_scene **out, char *msg, long nmsg)
{
    plume_err err = {{0}};
    if (!path || !out)
        return plume_flat_finish(plume_err_set(&err, PLUME_EINVAL, "scene: invalid arguments"), &err, msg, nmsg);
    *out = NULL;
    plume_flat_scene *s = calloc(1, sizeof *s);
    if (!s)
        return plume_flat_finish(plume_err_set(&err, PLUME_ENOMEM, "scene: out of memory"), &err, msg, nmsg);
    plume_status st = json ? plume_scene_load_json(json, path, NULL, &s->scene, &err)
                           : plume_scene_load(path, &s->scene, &err);
    if (st == PLUME_OK && is_static(s->scene))
        st = plume_err_set(&err, PLUME_EINVAL, "%s is a static scene (\"solve\": \"static\"): run it with apps/shell",
                           path);
    s->mesh = plume_scene_mesh(s->scene);
    plume_run_opts o;
    plume_run_opts_default(&o);
    o.open = 1;
    o.audit = 0;
    if (st == PLUME_OK && (st = plume_run_create(s->scene, &o, &s->run, &err)) == PLUME_OK)
        st = plume_run_start(s->run, &err);
    if (st != PLUME_OK) {
        plume_flat_scene_close(&s);
        return plume_flat_finish(st, &err, msg, nmsg);
    }
    *out = s;
    return plume_flat_finish(PLUME_OK, &err, msg, nmsg);
}

plume_status plume_flat_scene_open(const char *path, plume_flat_scene **out, char *msg, long nmsg)
{
    return scene_open(NULL, path, out, msg, nmsg);
}

plume_status plume_flat_scene_open_json(const char *json, const char *path, plume_flat_scene **out, char *msg,
                                        long nmsg)
{
    if (!json) {
        plume_err err = {{0}};
        if (out)
            *out = NULL;
        return plume_flat_finish(plume_err_set(&err, PLUME_EINVAL, "scene: no document given"), &err, msg, nmsg);
    }
    return scene_open(json, path, out, msg, nmsg);
}

void plume_flat_scene_close(plume_flat_scene **ps)
{
    if (!ps || !*ps)
        return;
    plume_flat_scene *s = *ps;
    plume_fields_destroy(&s->fields);
    free(s->vtk_dir);
    plume_run_destroy(&s->run);
    free(s->frames_path);
    plume_scene_destroy(&s->scene);
    free(s);
    *ps = NULL;
}

plume_status plume_flat_scene_step(plume_flat_scene *s, int nsteps, char **report, char *msg, long nmsg)
{
    plume_err err = {{0}};
    if (report)
        *report = NULL;
    if (!s || nsteps < 0)
        return plume_flat_finish(plume_err_set(&err, PLUME_EINVAL, "scene step: invalid arguments (nsteps >= 0)"), &err, msg, nmsg);
    long halvings = 0, iterations = 0, done = 0;
    double max_violation = 0.0, seconds = 0.0;
    int converged = 1;
    plume_reason reason = PLUME_REASON_CONVERGED;
    plume_status st = PLUME_OK;
    for (int i = 0; i < nsteps; i++) {
        plume_run_step_info info;
        plume_err why = {{0}};
        if ((st = plume_run_step(s->run, &info, &why)) != PLUME_OK) {
            plume_err_set(&err, st, "scene %s", why.msg);
            return plume_flat_finish(st, &err, msg, nmsg);
        }
        halvings += info.step.halvings, iterations += info.step.iterations, seconds += info.step.seconds;
        max_violation = fmax(max_violation, info.step.max_violation);
        if (!info.accepted) { /* the runner's acceptance rule (macro/scene/run.h, plume_run_accepts) */
            converged = 0;
            reason = info.step.reason;
            break;
        }
        done++;
    }
    if (!report)
        return plume_flat_finish(st, &err, msg, nmsg);
    json_t *j = json_pack("{s:I, s:f, s:b, s:I, s:I, s:f, s:f, s:s}", "steps", (json_int_t)done, "time",
                          plume_run_time(s->run), "converged", converged, "halvings", (json_int_t)halvings,
                          "newton_iterations", (json_int_t)iterations, "max_violation", max_violation, "seconds",
                          seconds, "stop_reason", plume_reason_name(reason));
    plume_run_report r;
    plume_run_get_report(s->run, &r);
    if (j && r.split_pairs > 0) /* the split lines since t = 0 (apps/feather's "splits") */
        json_object_set_new(j, "splits",
                            json_pack("{s:I, s:I, s:I, s:f, s:f, s:f}", "links", (json_int_t)r.split_pairs,
                                      "splits_opened", (json_int_t)r.splits_opened, "splits_closed",
                                      (json_int_t)r.splits_closed, "open_length", r.split_open_now,
                                      "longest_open_length", r.split_longest, "dissipated_energy",
                                      r.split_dissipated));
    if (j && (r.work != 0.0 || r.kinetic_energy != 0.0 || r.potential_change != 0.0)) /* apps/feather's "energy" */
        json_object_set_new(j, "energy",
                            json_pack("{s:f, s:f, s:f, s:f, s:f, s:f, s:f}", "work", r.work, "kinetic_energy",
                                      r.kinetic_energy, "kinetic_change", r.kinetic_change, "potential_change",
                                      r.potential_change, "numerical_dissipation", r.numerical_dissipation,
                                      "commit_dissipation", r.commit_dissipation, "energy_balance_error",
                                      r.energy_balance_error));
    st = plume_flat_emit(j, report, &err);
    return plume_flat_finish(st, &err, msg, nmsg);
}

long plume_flat_scene_nv(const plume_flat_scene *s)
{
    return s ? (long)s->mesh->nv : 0;
}

long plume_flat_scene_nt(const plume_flat_scene *s)
{
    return s ? (long)s->mesh->nt : 0;
}

double plume_flat_scene_time(const plume_flat_scene *s)
{
    return s ? plume_run_time(s->run) : NAN;
}

void plume_flat_scene_positions(const plume_flat_scene *s, double *out)
{
    if (s && out)
        memcpy(out, plume_run_positions(s->run), (size_t)(3 * s->mesh->nv) * sizeof *out);
}

void plume_flat_scene_velocities(const plume_flat_scene *s, double *out)
{
    if (s && out)
        memcpy(out, plume_run_velocities(s->run), (size_t)(3 * s->mesh->nv) * sizeof *out);
}

void plume_flat_scene_reference(const plume_flat_scene *s, double *out)
{
    if (s && out)
        memcpy(out, s->mesh->X, (size_t)(2 * s->mesh->nv) * sizeof *out);
}

void plume_flat_scene_triangles(const plume_flat_scene *s, long *out)
{
    if (!s || !out)
        return;
    const plume_mesh *m = s->mesh;
    for (plume_index k = 0; k < 3 * m->nt; k++)
        out[k] = (long)m->tri[k];
}

plume_status plume_flat_scene_write_vtk(plume_flat_scene *s, const char *dir, char *msg, long nmsg)
{
    plume_err err = {{0}};
    if (!s || !dir || !*dir)
        return plume_flat_finish(plume_err_set(&err, PLUME_EINVAL, "scene write_vtk: invalid arguments"), &err, msg, nmsg);
    plume_status st = PLUME_OK;
    if (!s->vtk_dir || strcmp(s->vtk_dir, dir) != 0) { /* a new series */
        if (plume_make_dirs(dir) != 0)
            return plume_flat_finish(plume_err_set(&err, PLUME_EIO, "scene write_vtk: cannot create the directory '%s': %s", dir,
                                        strerror(errno)),
                          &err, msg, nmsg);
        free(s->vtk_dir);
        s->vtk_dir = strdup(dir);
        s->vtk_frames = 0;
        if (!s->vtk_dir)
            return plume_flat_finish(plume_err_set(&err, PLUME_ENOMEM, "out of memory"), &err, msg, nmsg);
        if (!s->fields && (st = plume_run_fields(s->run, &s->fields, &err)) != PLUME_OK)
            return plume_flat_finish(st, &err, msg, nmsg);
        if ((st = plume_fields_series_start(s->fields, dir, "frames.pvd", "frame", -1.0, &err)) != PLUME_OK)
            return plume_flat_finish(st, &err, msg, nmsg);
    }
    st = plume_fields_series_frame(s->fields, s->vtk_frames, plume_run_time(s->run), plume_run_positions(s->run), &err);
    if (st == PLUME_OK)
        s->vtk_frames++;
    return plume_flat_finish(st, &err, msg, nmsg);
}

plume_status plume_flat_scene_write_frames(plume_flat_scene *s, const char *path, char *msg, long nmsg)
{
    plume_err err = {{0}};
    if (!s || !path || !*path)
        return plume_flat_finish(plume_err_set(&err, PLUME_EINVAL, "scene write_frames: invalid arguments (a scene and a path)"),
                      &err, msg, nmsg);
    const int create = !s->frames_path || strcmp(s->frames_path, path) != 0; /* a new file */
    plume_status st = plume_run_write_state(s->run, path, create, &err);
    if (st == PLUME_OK && create) {
        free(s->frames_path);
        if (!(s->frames_path = strdup(path)))
            st = plume_err_set(&err, PLUME_ENOMEM, "out of memory");
    }
    if (st != PLUME_OK && strncmp(err.msg, "scene write_frames", 18) != 0) {
        plume_err why = err;
        plume_err_set(&err, st, "scene write_frames: %s", why.msg);
    }
    return plume_flat_finish(st, &err, msg, nmsg);
}

/* The scene a frames file names: as recorded when that file exists, else relative to the frames
 * file's directory. */
static void frames_scene(const char *frames, const char *recorded, char *out, size_t n)
{
    const char *slash = strrchr(frames, '/');
    if (recorded[0] == '/' || access(recorded, R_OK) == 0 || !slash)
        snprintf(out, n, "%s", recorded);
    else
        snprintf(out, n, "%.*s/%s", (int)(slash - frames), frames, recorded);
}

plume_status plume_flat_gltf_export(const char *frames, const char *path, const char *scene, const char *animation,
                                    const char *field, char *msg, long nmsg)
{
    plume_err err = {{0}}, why = {{0}};
    if (!frames || !*frames || !path || !*path)
        return plume_flat_finish(plume_err_set(&err, PLUME_EINVAL, "gltf export: a frames file and an output file are required"),
                      &err, msg, nmsg);
    plume_gltf_opts o;
    plume_gltf_opts_default(&o);
    o.field = field && *field ? field : NULL;
    if (animation && strcmp(animation, "frames") == 0)
        o.animation = PLUME_GLTF_FRAMES;
    else if (animation && strcmp(animation, "morph") != 0)
        return plume_flat_finish(plume_err_set(&err, PLUME_EINVAL, "gltf export: animation must be \"morph\" or \"frames\" (got "
                                    "\"%s\")", animation), &err, msg, nmsg);
    plume_frames_info info;
    char scene_path[sizeof info.scene + 4096];
    plume_status st = PLUME_OK;
    if (!scene) {
        if ((st = plume_frames_info_read(frames, &info, &why)) != PLUME_OK)
            return plume_flat_finish(plume_err_set(&err, st, "gltf export: %s", why.msg), &err, msg, nmsg);
        frames_scene(frames, info.scene, scene_path, sizeof scene_path);
        scene = scene_path;
    }
    plume_run_opts ro;
    plume_run_opts_default(&ro);
    ro.progress = 0;
    plume_run *r = NULL;
    if ((st = plume_run_open(scene, &ro, &r, &why)) != PLUME_OK)
        plume_err_set(&err, st, "gltf export: the scene of '%s': %s", frames, why.msg);
    else if ((st = plume_run_write_gltf(r, frames, path, &o, &err)) != PLUME_OK && strncmp(err.msg, "gltf", 4) != 0 &&
             strncmp(err.msg, "glTF", 4) != 0) {
        why = err;
        plume_err_set(&err, st, "gltf export: %s", why.msg);
    }
    plume_run_destroy(&r);
    return plume_flat_finish(st, &err, msg, nmsg);
}
