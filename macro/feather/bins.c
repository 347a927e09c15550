/* plume: the uniform grid of macro/feather/internal/bins.h. */
#include <stdlib.h>
#include <string.h>

#include "internal/bins.h"

int plume_bins_init(plume_bins *g, double x0, double y0, double x1, double y1, double h)
{
    memset(g, 0, sizeof *g);
    g->x0 = x0, g->y0 = y0, g->h = h;
    g->nx = (long)ceil((x1 - x0) / h) + 1;
    g->ny = (long)ceil((y1 - y0) / h) + 1;
    g->head = malloc((size_t)(g->nx * g->ny) * sizeof *g->head);
    if (!g->head)
        return -1;
    for (long k = 0; k < g->nx * g->ny; k++)
        g->head[k] = -1;
    return 0;
}

void plume_bins_free(plume_bins *g)
{
    free(g->head);
    free(g->next);
    free(g->item);
    memset(g, 0, sizeof *g);
}

int plume_bins_add(plume_bins *g, plume_index item, double xa, double ya, double xb, double yb)
{
    long r[4];
    plume_bins_range(g, xa, ya, xb, yb, r);
    for (long j = r[2]; j <= r[3]; j++)
        for (long i = r[0]; i <= r[1]; i++) {
            if (g->n == g->cap) {
                plume_index cap = g->cap ? 2 * g->cap : 1024;
                plume_index *nx = realloc(g->next, (size_t)cap * sizeof *nx);
                if (!nx)
                    return -1;
                g->next = nx;
                plume_index *it = realloc(g->item, (size_t)cap * sizeof *it);
                if (!it)
                    return -1;
                g->item = it, g->cap = cap;
            }
            long c = j * g->nx + i;
            g->item[g->n] = item;
            g->next[g->n] = g->head[c];
            g->head[c] = g->n++;
        }
    return 0;
}
