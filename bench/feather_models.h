/* bench_feather --models: the feather's three bending models at its three meshes (feather_models.c). */
#ifndef PLUME_BENCH_FEATHER_MODELS_H
#define PLUME_BENCH_FEATHER_MODELS_H

/* The table's title, its legend (the pull's `steps` steps) and its column line. */
void feather_models_header(int steps);

/* For each of the n scenes (coarse to fine) and each bending model, in one run: the sizes, CHOLMOD's
 * counts, one factorisation's CPU time, the first step's wall seconds per Newton iteration, the
 * vane's sag and the tip's reaction after the scene's first `steps` steps (the pull), and the
 * vane's sag under gravity with the handles at rest; then the ratios to midedge, size by size. */
void feather_models(const char *const *scenes, int n, int steps);

#endif
