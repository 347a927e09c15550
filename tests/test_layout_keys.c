/* docs/layout-format.md's table of layout keys against the parser, so that neither drifts: every
 * key the parser accepts is a row and every row a key it accepts (the parser's list is the one its
 * unknown-key message gives), every flag of the table is one apps/homogenize --help lists, and
 * every default the table gives as a value is plume_layout_default's. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "app_runner.h"
#include "harness.h"
#include "plume_tree.h"
#include "../micro/layout.h"
#include "../micro/layout_json.h"

#define MAX_KEYS 64

typedef struct {
    char key[64], flag[64], def[256];
} row;

static char *slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *s = malloc((size_t)n + 1);
    if (s && fread(s, 1, (size_t)n, f) != (size_t)n) {
        free(s);
        s = NULL;
    }
    if (s)
        s[n] = '\0';
    fclose(f);
    return s;
}

/* cell k (0-based) of a table line "| a | b | ... |", trimmed, into out */
static int cell(const char *line, int k, char *out, size_t n)
{
    const char *p = line;
    for (int i = 0; i <= k; i++) {
        p = strchr(p, '|');
        if (!p)
            return -1;
        p++;
    }
    const char *e = strchr(p, '|');
    if (!e)
        return -1;
    while (p < e && *p == ' ')
        p++;
    while (e > p && e[-1] == ' ')
        e--;
    snprintf(out, n, "%.*s", (int)(e - p), p);
    return 0;
}

/* the first `...` of s into out; -1 without one */
static int ticked(const char *s, char *out, size_t n)
{
    const char *a = strchr(s, '`'), *b = a ? strchr(a + 1, '`') : NULL;
    if (!b)
        return -1;
    snprintf(out, n, "%.*s", (int)(b - a - 1), a + 1);
    return 0;
}

static int same_layout(const plume_layout *a, const plume_layout *b)
{
    const double x[] = {a->phi, a->d_B, a->E_b, a->nu_b, a->ratio, a->nu_B, a->h, a->h_barb, a->h_barbule, a->kappa,
                        a->barbule_width, a->barbule_spacing, a->barbule_angle, a->e_rel, a->hooks.strength,
                        a->hooks.opening, a->hooks.slide, a->hooks.capture};
    const double y[] = {b->phi, b->d_B, b->E_b, b->nu_b, b->ratio, b->nu_B, b->h, b->h_barb, b->h_barbule, b->kappa,
                        b->barbule_width, b->barbule_spacing, b->barbule_angle, b->e_rel, b->hooks.strength,
                        b->hooks.opening, b->hooks.slide, b->hooks.capture};
    for (size_t i = 0; i < sizeof x / sizeof x[0]; i++)
        if (!(fabs(x[i] - y[i]) <= 1e-12 * fabs(y[i])))
            return 0;
    return a->kind == b->kind && a->order == b->order;
}

void test_layout_keys_table(void)
{
    /* the table's rows */
    char *doc = slurp("../docs/layout-format.md");
    CHECK(doc != NULL);
    if (!doc)
        return;
    row rows[MAX_KEYS];
    int nrows = 0;
    const char *p = strstr(doc, "\n## Keys");
    CHECK(p != NULL);
    for (p = p ? strchr(p + 1, '\n') : NULL; p && nrows < MAX_KEYS; p = strchr(p + 1, '\n')) {
        const char *line = p + 1;
        if (strncmp(line, "## ", 3) == 0)
            break;
        if (strncmp(line, "| `", 3) != 0)
            continue;
        char c0[128], c3[128];
        row *r = &rows[nrows];
        if (cell(line, 0, c0, sizeof c0) || cell(line, 3, c3, sizeof c3) || cell(line, 4, r->def, sizeof r->def) ||
            ticked(c0, r->key, sizeof r->key) || ticked(c3, r->flag, sizeof r->flag)) {
            fprintf(stderr, "    unreadable row: %.80s\n", line);
            CHECK(!"every row has a key, a flag and a default");
            continue;
        }
        nrows++;
    }
    free(doc);
    CHECK(nrows >= 17);

    /* the parser's keys, from its unknown-key message */
    plume_layout l;
    plume_err err = {{0}};
    plume_layout_default(&l);
    CHECK(plume_layout_apply_json("{\"no_such_key\": 1}", "test", &l, &err) == PLUME_EFORMAT);
    char *a = strstr(err.msg, "(expected "), *b = a ? strstr(a, ", or note)") : NULL;
    CHECK(a && b);
    if (!a || !b)
        return;
    *b = '\0';
    char *keys[MAX_KEYS];
    int nkeys = 0;
    for (char *t = strtok(a + strlen("(expected "), ", "); t && nkeys < MAX_KEYS; t = strtok(NULL, ", "))
        keys[nkeys++] = t;
    CHECK(nkeys >= 17);
    for (int i = 0; i < nkeys; i++) {
        int found = 0;
        for (int k = 0; k < nrows; k++)
            found |= strcmp(keys[i], rows[k].key) == 0;
        if (!found)
            fprintf(stderr, "    the parser accepts \"%s\", which the table does not list\n", keys[i]);
        CHECK(found);
    }
    for (int k = 0; k < nrows; k++) {
        int found = 0;
        for (int i = 0; i < nkeys; i++)
            found |= strcmp(keys[i], rows[k].key) == 0;
        if (!found)
            fprintf(stderr, "    the table lists \"%s\", which the parser refuses\n", rows[k].key);
        CHECK(found);
    }

    /* flags: each one apps/homogenize --help lists */
    char dir[] = "/tmp/plume-layoutkeys-XXXXXX", help[16384], errs[1024];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    CHECK(app_run(dir, "homogenize", "--help", help, sizeof help, errs, sizeof errs) == 0);
    for (int k = 0; k < nrows; k++) {
        char with_space[80];
        snprintf(with_space, sizeof with_space, "%s ", rows[k].flag);
        int ok = strncmp(rows[k].flag, "--", 2) == 0 && strstr(help, with_space) != NULL;
        if (!ok)
            fprintf(stderr, "    %s: flag %s is not in homogenize --help\n", rows[k].key, rows[k].flag);
        CHECK(ok);
    }

    /* defaults given as a value: setting the key to it changes nothing */
    int checked = 0;
    for (int k = 0; k < nrows; k++) {
        char v[128], json[1024];
        if (ticked(rows[k].def, v, sizeof v) != 0 || rows[k].def[0] != '`')
            continue; /* a default said in words (the thickness, phi d_B) */
        char *end = NULL;
        strtod(v, &end);
        if (end && *end == '\0' && end != v)
            snprintf(json, sizeof json, "{\"%.63s\": %.127s}", rows[k].key, v);
        else
            snprintf(json, sizeof json, "{\"%.63s\": \"%.127s\"}", rows[k].key, v);
        plume_layout d, set;
        plume_layout_default(&d);
        plume_layout_default(&set);
        int ok = plume_layout_apply_json(json, "test", &set, &err) == PLUME_OK && same_layout(&set, &d);
        if (!ok)
            fprintf(stderr, "    %s: the table's default %s is not the library's\n", rows[k].key, v);
        CHECK(ok);
        checked++;
    }
    CHECK(checked >= 14);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    CHECK(system(cmd) == 0);
}

/* "note" is a comment in a layout, of any value; an unknown key names itself and lists the keys. */
void test_layout_keys_note(void)
{
    plume_layout l, d;
    plume_err err = {{0}};
    plume_layout_default(&l);
    plume_layout_default(&d);
    CHECK(plume_layout_apply_json("{\"note\": {\"E_b\": \"a citation\"}, \"E_b\": 2e9}", "test", &l, &err) == PLUME_OK);
    d.E_b = 2e9;
    CHECK(same_layout(&l, &d));
    CHECK(plume_layout_apply_json("{\"note\": \"text\"}", "test", &l, &err) == PLUME_OK);
    CHECK(plume_layout_apply_json("{\"Eb\": 2e9}", "request.layout", &l, &err) == PLUME_EFORMAT &&
          strstr(err.msg, "request.layout: unknown key \"Eb\" (expected layout, phi, d_B, w_B, E_b,") &&
          strstr(err.msg, "hook_capture, or note)"));
    CHECK(plume_layout_apply_json("{\"notes\": \"text\"}", "test", &l, &err) == PLUME_EFORMAT && strstr(err.msg, "\"notes\""));
    /* every shipped layout loads */
    const char *files[] = {"../data/layout_fig10.json", "../data/layout_barbules.json",
                           "../data/layout_barbules_table3a.json", "../data/layout_feather_si.json"};
    for (int k = 0; k < 4; k++) {
        plume_layout_default(&l);
        int ok = plume_layout_load_json(files[k], &l, &err) == PLUME_OK && plume_layout_check(&l, &err) == PLUME_OK;
        if (!ok)
            fprintf(stderr, "    %s: %s\n", files[k], err.msg);
        CHECK(ok);
    }
}
