/* Tests of the house's floors, read from its #include lines (docs/design.md, "Layout"):
 *  - include/plume/ (the public face) includes only itself; every room may include it;
 *  - the rooms stand on floors, lib/core < lib/io < lib/solve < lib/contact < lib/sim < micro, macro <
 *    drivers < apps (macro's own rooms: shell < feather < scene), and a file includes only its own
 *    room or a lower floor; micro and macro never include each other;
 *  - a room's internal/ headers are its own: no other room includes them;
 *  - the apps include the public face and their own headers, nothing else: the library's own first
 *    users live on the face other programs get.
 * Run from tests/, as every test is. */
#include <glob.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"

/* the floors, lowest first; rooms of one floor share a level */
static const struct {
    const char *room;
    int level;
} floors[] = {
    {"include/plume", 0}, {"lib/core", 10},     {"lib/io", 20},        {"lib/solve", 30},
    {"lib/contact", 40},  {"lib/sim", 50},      {"micro", 60},         {"macro/shell", 61},
    {"macro/feather", 62}, {"macro/scene", 63}, {"drivers", 70},       {"apps", 80},
};
enum { NFLOORS = sizeof floors / sizeof floors[0] };

/* the room of a path relative to the top ("lib/io/frames.c" -> index of lib/io), -1 outside */
static int room_of(const char *path)
{
    int best = -1;
    size_t best_len = 0;
    for (int i = 0; i < NFLOORS; i++) {
        size_t n = strlen(floors[i].room);
        if (!strncmp(path, floors[i].room, n) && path[n] == '/' && n > best_len) {
            best = i;
            best_len = n;
        }
    }
    return best;
}

/* dir + "/" + rel, with "." and ".." resolved lexically, into out (relative to the top) */
static void join_path(const char *dir, const char *rel, char *out, size_t n)
{
    char buf[2 * PATH_MAX + 2], *seg[64];
    int ns = 0;
    snprintf(buf, sizeof buf, "%s/%s", dir, rel);
    for (char *s = strtok(buf, "/"); s && ns < 64; s = strtok(NULL, "/")) {
        if (!strcmp(s, "."))
            continue;
        if (!strcmp(s, "..")) {
            if (ns > 0)
                ns--;
            continue;
        }
        seg[ns++] = s;
    }
    out[0] = 0;
    for (int i = 0; i < ns; i++) {
        strncat(out, seg[i], n - strlen(out) - 1);
        if (i + 1 < ns)
            strncat(out, "/", n - strlen(out) - 1);
    }
}

/* the room's folder of an internal header ("lib/io/internal/x.h" -> "lib/io"), or "" */
static void internal_owner(const char *path, char *out, size_t n)
{
    const char *p = strstr(path, "/internal/");
    out[0] = 0;
    if (p)
        snprintf(out, n, "%.*s", (int)(p - path), path);
}

void test_includes_floors(void)
{
    static const char *const pattern[] = {
        "../include/plume/*.h", "../lib/*/*.[ch]",  "../lib/*/*.cpp",    "../lib/*/internal/*.h", "../micro/*.[ch]",
        "../macro/*/*.[ch]",    "../macro/*/*/*.h", "../drivers/*.[ch]", "../drivers/*/*.h",      "../apps/*.[ch]",
    };
    glob_t g;
    memset(&g, 0, sizeof g);
    for (size_t i = 0; i < sizeof pattern / sizeof pattern[0]; i++)
        glob(pattern[i], i ? GLOB_APPEND : 0, NULL, &g);
    CHECK(g.gl_pathc > 100);
    int bad = 0;
    long includes = 0;
    for (size_t f = 0; f < g.gl_pathc; f++) {
        const char *file = g.gl_pathv[f] + 3; /* "lib/io/frames.c" */
        int a = room_of(file);
        if (a < 0)
            continue;
        char dir[PATH_MAX];
        snprintf(dir, sizeof dir, "%s", file);
        *strrchr(dir, '/') = 0;
        FILE *in = fopen(g.gl_pathv[f], "r");
        if (!in) {
            CHECK(!"every source file readable");
            continue;
        }
        char line[1024];
        int lineno = 0;
        while (fgets(line, sizeof line, in)) {
            lineno++;
            const char *p = line;
            while (*p == ' ')
                p++;
            if (strncmp(p, "#include \"", 10) != 0)
                continue;
            const char *q = strchr(p + 10, '"');
            if (!q)
                continue;
            char rel[PATH_MAX], target[PATH_MAX], owner[PATH_MAX], own[PATH_MAX];
            snprintf(rel, sizeof rel, "%.*s", (int)(q - (p + 10)), p + 10);
            join_path(dir, rel, target, sizeof target);
            includes++;
            int b = room_of(target);
            if (b < 0) {
                fprintf(stderr, "    %s:%d includes %s, outside every room\n", file, lineno, target);
                bad++;
                continue;
            }
            internal_owner(target, owner, sizeof owner);
            snprintf(own, sizeof own, "%s", floors[a].room);
            if (owner[0] && strcmp(owner, own) != 0) {
                fprintf(stderr, "    %s:%d includes %s, another room's internal header\n", file, lineno, target);
                bad++;
            }
            if (a == b || b == 0)
                continue;
            if (a == 0) {
                fprintf(stderr, "    %s:%d: the public face includes %s\n", file, lineno, target);
                bad++;
            } else if (floors[b].level > floors[a].level) {
                fprintf(stderr, "    %s:%d includes %s, a higher floor\n", file, lineno, target);
                bad++;
            } else if (floors[b].level == floors[a].level ||
                       (!strncmp(floors[a].room, "mic", 3) && !strncmp(floors[b].room, "mac", 3)) ||
                       (!strncmp(floors[a].room, "mac", 3) && !strncmp(floors[b].room, "mic", 3))) {
                fprintf(stderr, "    %s:%d includes %s: micro and macro never include each other\n", file, lineno,
                        target);
                bad++;
            } else if (!strcmp(floors[a].room, "apps")) {
                fprintf(stderr, "    %s:%d includes %s, below the public face\n", file, lineno, target);
                bad++;
            }
        }
        fclose(in);
    }
    fprintf(stderr, "    %zu files, %ld includes\n", g.gl_pathc, includes);
    CHECK(includes > 500);
    CHECK(bad == 0);
    globfree(&g);
}
