/* plume example: the chain from a microstructure to a moving vane, on the public face only.
 *   1. homogenise a barb layout (include/plume/homogenize.h) and write its moduli file;
 *   2. write a scene whose vane takes its membrane and its bending from that file (no number copied;
 *      docs/scene-format.md) and load it (include/plume/scene.h);
 *   3. step it to its end with the scene runner, which writes the frames (frames.h5 and a ParaView
 *      series) into OUT_DIR;
 *   4. read the frames back and check the last one is where the run ended.
 *   scene LAYOUT.json OUT_DIR
 * Build against the installed library:
 *   cc -std=c11 scene.c $(pkg-config --cflags --libs plume) -o scene */
#include <stdio.h>
#include <string.h>

#include <plume/plume.h>

/* A vane sample 40 x 10 mm, barbs across it, clamped along one short side and sagging under
 * gravity for 0.1 s. Its membrane and bending moduli come from `moduli`. */
static int write_scene(const char *path, const char *moduli)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return 0;
    fprintf(f,
            "{\n"
            "  \"mesh\": {\"rectangle\": [0.04, 0.01], \"edge\": 0.0025, \"pattern\": \"aligned\",\n"
            "           \"barb_direction\": [0, 1]},\n"
            "  \"materials\": [{\"membrane\": {\"from_moduli\": \"%s\", \"kappa\": 0},\n"
            "                  \"bending\": {\"from_moduli\": \"%s\", \"drop_couplings\": true},\n"
            "                  \"density\": 0.026, \"constraint\": true}],\n"
            "  \"handles\": [{\"box\": [0, 0, 0.0026, 0.01], \"keyframes\": [[0, 0, 0, 0]]}],\n"
            "  \"gravity\": [0, 0, -9.81], \"dt\": 0.01, \"duration\": 0.1, \"solver\": \"newton\"\n"
            "}\n",
            moduli, moduli);
    return fclose(f) == 0;
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: scene LAYOUT.json OUT_DIR\n");
        return 2;
    }
    plume_openmp_serial();
    const char *out = argv[2];
    char moduli[512], scene_path[512];
    snprintf(moduli, sizeof moduli, "%s/cell.h5", out);
    snprintf(scene_path, sizeof scene_path, "%s/vane.json", out);
    plume_err err = {{0}};
    plume_layout layout;
    plume_layout_default(&layout);
    plume_homog_opts ho;
    plume_homog_opts_default(&ho);
    ho.strain_max = 0.0; /* the moduli only: no cell curves */
    plume_homog_result hr;
    plume_scene *scene = NULL;
    plume_run *run = NULL;
    plume_frames_info info;
    plume_frame last;
    memset(&last, 0, sizeof last);
    int ok = 0, have_result = 0;
    if (plume_make_dirs(out) != 0) {
        fprintf(stderr, "scene: cannot create %s\n", out);
        return 1;
    }
    /* 1. the microstructure's moduli, in the file the scene reads */
    if (plume_layout_load_json(argv[1], &layout, &err) || plume_homogenize(&layout, &ho, &hr, &err))
        goto done;
    have_result = 1;
    printf("homogenised: E_xx %.4g Pa, E_yy %.4g Pa, G_xy %.4g Pa; D_long %.4g N m, D_trans %.4g N m\n",
           hr.moduli.E_xx, hr.moduli.E_yy, hr.moduli.G_xy, hr.bending.D_long, hr.bending.D_trans);
    if (plume_homog_write(moduli, &layout, &hr, &err))
        goto done;
    /* 2. the scene (relative file names resolve against the scene's directory) */
    if (!write_scene(scene_path, "cell.h5")) {
        snprintf(err.msg, sizeof err.msg, "cannot write %s", scene_path);
        goto done;
    }
    if (plume_scene_load(scene_path, &scene, &err))
        goto done;
    /* 3. stepped to its end, the frames written */
    plume_run_opts ro;
    plume_run_opts_default(&ro);
    ro.output_dir = out;
    if (plume_run_create(scene, &ro, &run, &err) || plume_run_to_end(run, &err))
        goto done;
    plume_run_report rep;
    plume_run_get_report(run, &rep);
    printf("stepped: %ld steps to t = %g s, %ld frames, %ld Newton iterations, %s\n", rep.steps, rep.time, rep.frames,
           rep.iterations, rep.stopped ? "stopped early" : "every step accepted");
    /* 4. the frames read back: the last one is the run's final state */
    const char *frames = plume_run_frames_path(run);
    if (rep.stopped || plume_frames_info_read(frames, &info, &err) || plume_frames_read(frames, info.count - 1, &last, &err))
        goto done;
    const double *x = plume_run_positions(run);
    const long n = 3 * (long)last.nv;
    ok = info.count == rep.frames && last.x && memcmp(last.x, x, (size_t)n * sizeof *x) == 0;
    printf("read back: %ld frames from %s, the last at t = %g s %s the run's positions\n", (long)info.count, frames,
           last.t, ok ? "equal to" : "DIFFERENT from");
done:
    if (!ok && err.msg[0])
        fprintf(stderr, "scene: %s\n", err.msg);
    plume_frame_free(&last);
    plume_run_destroy(&run);
    plume_scene_destroy(&scene);
    if (have_result)
        plume_homog_result_free(&hr);
    printf("scene example: %s\n", ok ? "ok" : "FAILED");
    return ok ? 0 : 1;
}
