#include "pslg.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

plume_index plume_pslg_point(plume_pslg *g, double x, double y)
{
    if (g->n == g->cap) {
        plume_index cap = g->cap ? 2 * g->cap : 256;
        double *p = realloc(g->p, (size_t)(2 * cap) * sizeof *p);
        if (!p)
            return -1;
        g->p = p, g->cap = cap;
    }
    g->p[2 * g->n] = x, g->p[2 * g->n + 1] = y;
    return g->n++;
}

int plume_pslg_segment(plume_pslg *g, plume_index a, plume_index b)
{
    if (g->ns == g->scap) {
        plume_index cap = g->scap ? 2 * g->scap : 256;
        plume_index *s = realloc(g->s, (size_t)(2 * cap) * sizeof *s);
        if (!s)
            return -1;
        g->s = s, g->scap = cap;
    }
    g->s[2 * g->ns] = a, g->s[2 * g->ns + 1] = b;
    g->ns++;
    return 0;
}

void plume_pslg_free(plume_pslg *g)
{
    free(g->p);
    free(g->s);
    memset(g, 0, sizeof *g);
}

void plume_barb_direction(double angle_deg, double d[2])
{
    double a = angle_deg * M_PI / 180.0;
    d[0] = sin(a), d[1] = cos(a);
    if (angle_deg == 0.0 || angle_deg == 180.0)
        d[0] = 0.0, d[1] = angle_deg == 0.0 ? 1.0 : -1.0;
    if (angle_deg == 90.0)
        d[0] = 1.0, d[1] = 0.0;
}
