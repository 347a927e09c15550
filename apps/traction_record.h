/* apps/traction's records of each state of the curve, through the traction loop's step callback:
 * the links' states for the HDF5 hooks table (-o) and the ParaView series (--vtk). Included by
 * apps/traction.c only (file-local functions). */
#ifndef PLUME_APPS_TRACTION_RECORD_H
#define PLUME_APPS_TRACTION_RECORD_H

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../include/plume/plume.h"
#include "cli.h"

/* The links' states (1 engaged, 0 let go) of the problem's term `term` ("hooks", "splits") at every
 * point of the curve, recorded by the traction loop's step callback, which then calls the one it
 * replaced (--vtk's). */
typedef struct {
    const plume_problem *p;
    const char *term;
    plume_index cols;
    long rows, cap;
    int *v;
    plume_status (*next)(void *user, int step, double strain, const double *x);
    void *next_user;
} links_record;

static plume_status record_links(void *user, int step, double strain, const double *x)
{
    links_record *r = user;
    plume_status st = r->next ? r->next(r->next_user, step, strain, x) : PLUME_OK;
    if (st != PLUME_OK)
        return st;
    if (r->rows == r->cap) {
        long cap = r->cap ? 2 * r->cap : 64;
        int *v = realloc(r->v, (size_t)cap * (size_t)r->cols * sizeof *v);
        if (!v)
            return PLUME_ENOMEM;
        r->v = v, r->cap = cap;
    }
    plume_index n = 0;
    plume_err err = {{0}};
    if ((st = plume_problem_term_states(r->p, r->term, r->v + r->rows * r->cols, &n, &err)) != PLUME_OK) {
        fprintf(stderr, "traction: %s\n", err.msg);
        return st;
    }
    r->rows++;
    return PLUME_OK;
}

/* Starts recording the term's states through to's step callback (chained after the one it has). */
static int links_start(const plume_problem *p, const char *term, plume_traction_opts *to, links_record *r)
{
    plume_err err = {{0}};
    memset(r, 0, sizeof *r);
    r->p = p, r->term = term;
    if (plume_problem_term_states(p, term, NULL, &r->cols, &err) != PLUME_OK) {
        fprintf(stderr, "traction: %s\n", err.msg);
        return 1;
    }
    r->next = to->on_step, r->next_user = to->on_step_user;
    to->on_step = record_links, to->on_step_user = r;
    return 0;
}

/* --restart: the rows the first run recorded, up to its checkpoint, from the checkpoint's table
 * (plume_traction_checkpoint_states), so that the table covers the whole curve. Returns an exit code. */
static int links_seed(links_record *r, const char *checkpoint)
{
    plume_err err = {{0}};
    long rows = 0;
    plume_index cols = 0;
    if (plume_traction_checkpoint_states(checkpoint, r->term, NULL, &rows, &cols, &err) != PLUME_OK) {
        fprintf(stderr, "traction: --restart: %s\n", err.msg);
        return 1;
    }
    if (cols != r->cols) {
        fprintf(stderr, "traction: --restart: '%s' holds the states of %ld %s pairs, this run has %ld\n", checkpoint,
                (long)cols, r->term, (long)r->cols);
        return 1;
    }
    free(r->v);
    r->v = malloc((size_t)(rows > 0 ? rows : 1) * (size_t)(cols > 0 ? cols : 1) * sizeof *r->v);
    if (!r->v || plume_traction_checkpoint_states(checkpoint, r->term, r->v, &rows, &cols, &err) != PLUME_OK) {
        fprintf(stderr, "traction: --restart: %s\n", r->v ? err.msg : "out of memory");
        return 1;
    }
    r->rows = r->cap = rows;
    return 0;
}

/* Hands the recording over (*v freed first; the caller frees the new one). */
static void links_keep(links_record *r, int **v, long *rows, plume_index *cols)
{
    free(*v);
    *v = r->v, *rows = r->rows, *cols = r->cols;
    r->v = NULL;
}

/* --vtk: each state of the curve as a frame of the series */
static plume_status vtk_step(void *user, int step, double strain, const double *x)
{
    plume_err err = {{0}};
    plume_status st = plume_fields_series_frame(user, step, strain, x, &err);
    if (st != PLUME_OK)
        fprintf(stderr, "traction: --vtk: %s\n", err.msg);
    return st;
}

/* --vtk: the series of one model in vtk_dir/<scale>/ (materials mats, constrained barbs), and the
 * traction options that write it. Returns an exit code. */
static int vtk_start(const char *vtk_dir, const char *scale, const plume_mesh *mesh, const plume_membrane_material *mats,
                     int nmat, const plume_index *barbs, plume_index nbarbs, plume_traction_opts *to,
                     plume_fields **f)
{
    char dir[4200];
    plume_err err = {{0}};
    snprintf(dir, sizeof dir, "%s/%s", vtk_dir, scale);
    if (plume_make_dirs(dir) != 0) {
        fprintf(stderr, "traction: --vtk: cannot create the directory '%s': %s\n", dir, strerror(errno));
        return 1;
    }
    if (plume_fields_create(mesh, 2, mesh->nt, mats, nmat, NULL, barbs, nbarbs, f, &err) != PLUME_OK ||
        plume_fields_series_start(*f, dir, "steps.pvd", "step", -1.0, &err) != PLUME_OK) {
        fprintf(stderr, "traction: --vtk: %s\n", err.msg);
        return 1;
    }
    to->on_step = vtk_step;
    to->on_step_user = *f;
    return 0;
}

#endif
