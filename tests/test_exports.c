/* Tests of the library's face. The public face is include/plume/ (one header a job), the only headers make install
 * puts on a user's include path: every function they declare PLUME_API carries a doc comment, and
 * no other header of the tree uses the macro. libplume.so exports exactly those functions (read
 * with `nm -D --defined-only`), and so does libplume.a (`readelf -s`): its other global symbols are
 * plume_ names of hidden visibility, never a bare name that could collide with a program's own.
 * The umbrella include/plume/plume.h includes every public header. */
#include <glob.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "harness.h"
#include "../include/plume/base.h"

typedef struct {
    char **name;
    size_t n, cap;
} names;

static void names_add(names *s, const char *p, size_t len)
{
    if (s->n == s->cap) {
        s->cap = s->cap ? 2 * s->cap : 256;
        s->name = realloc(s->name, s->cap * sizeof *s->name);
    }
    s->name[s->n] = malloc(len + 1);
    memcpy(s->name[s->n], p, len);
    s->name[s->n][len] = 0;
    s->n++;
}

static int names_has(const names *s, const char *p)
{
    for (size_t i = 0; i < s->n; i++)
        if (!strcmp(s->name[i], p))
            return 1;
    return 0;
}

static void names_free(names *s)
{
    for (size_t i = 0; i < s->n; i++)
        free(s->name[i]);
    free(s->name);
}

static char *read_all(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *s = malloc((size_t)n + 1);
    size_t got = fread(s, 1, (size_t)n, f);
    s[got] = 0;
    fclose(f);
    return s;
}

static int ident(char c)
{
    return c == '_' || (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9');
}

/* the installed headers, as the Makefile's PUBLIC_HEADERS globs them (run from tests/) */
static void installed_headers(glob_t *g)
{
    memset(g, 0, sizeof *g);
    glob("../include/plume/*.h", 0, NULL, g);
}

/* every other header of the tree, the internal/ ones too */
static void tree_headers(glob_t *g)
{
    static const char *const pattern[] = {"../lib/*/*.h", "../lib/*/internal/*.h", "../micro/*.h", "../macro/*/*.h",
                                          "../macro/*/internal/*.h", "../drivers/*.h", "../drivers/internal/*.h"};
    memset(g, 0, sizeof *g);
    for (size_t i = 0; i < sizeof pattern / sizeof pattern[0]; i++)
        glob(pattern[i], i ? GLOB_APPEND : 0, NULL, g);
}

/* Whether a line (comments blanked) is the prototype of a plume_ function without PLUME_API: type
 * words, then the name, then '(' (typedefs, static inline definitions and macros excepted). A
 * public function without the macro would silently stay inside the library. */
static int unmarked_prototype(const char *line, char *name, size_t n)
{
    while (*line == ' ')
        line++;
    static const char *const skip[] = {"typedef", "static", "#", "return", "PLUME_API", "extern"};
    for (size_t i = 0; i < sizeof skip / sizeof skip[0]; i++)
        if (!strncmp(line, skip[i], strlen(skip[i])))
            return 0;
    const char *paren = strchr(line, '(');
    if (!paren)
        return 0;
    const char *e = paren;
    while (e > line && e[-1] == ' ')
        e--;
    const char *b = e;
    while (b > line && ident(b[-1]))
        b--;
    if (b == line || e - b < 7 || strncmp(b, "plume_", 6) != 0)
        return 0;
    for (const char *p = line; p < b; p++) /* only type words before the name */
        if (!ident(*p) && *p != ' ' && *p != '*')
            return 0;
    snprintf(name, n, "%.*s", (int)(e - b), b);
    return 1;
}

/* Blanks the comments of s in place (offsets kept). */
static void blank_comments(char *s)
{
    for (char *p = s; *p; p++) {
        if (p[0] == '/' && p[1] == '*') {
            char *e = strstr(p + 2, "*/");
            char *end = e ? e + 2 : p + strlen(p);
            memset(p, ' ', (size_t)(end - p));
            p = end - 1;
        } else if (p[0] == '/' && p[1] == '/') {
            while (*p && *p != '\n')
                *p++ = ' ';
            if (!*p)
                break;
        }
    }
}

/* Whether the text before offset `at` of the original header (blanks skipped) is the end of a
 * doc comment that begins with slash-star-star. */
static int has_doc_comment(const char *orig, size_t at)
{
    size_t i = at;
    while (i > 0 && (orig[i - 1] == ' ' || orig[i - 1] == '\n'))
        i--;
    if (i < 2 || orig[i - 1] != '/' || orig[i - 2] != '*')
        return 0;
    for (size_t j = i - 2; j >= 2; j--)
        if (orig[j - 2] == '/' && orig[j - 1] == '*')
            return orig[j] == '*';
    return 0;
}

/* The functions a public header declares PLUME_API: the name before the first '(' after the
 * macro, comments blanked first (the macro's own definition, a preprocessor line, skipped).
 * Prototypes of plume_ functions without the macro are counted in *unmarked, PLUME_API functions
 * without a doc comment in *undocumented, and named. */
static void declared_api(names *api, int *unmarked, int *undocumented)
{
    glob_t g;
    installed_headers(&g);
    for (size_t h = 0; h < g.gl_pathc; h++) {
        char *s = read_all(g.gl_pathv[h]), *orig = s ? strdup(s) : NULL;
        if (!s || !orig) {
            free(s);
            continue;
        }
        blank_comments(s);
        for (char *line = s; line && *line;) {
            char *nl = strchr(line, '\n'), name[128];
            if (nl)
                *nl = 0;
            if (unmarked_prototype(line, name, sizeof name)) {
                fprintf(stderr, "    %s: %s is declared without PLUME_API\n", g.gl_pathv[h] + 3, name);
                (*unmarked)++;
            }
            if (nl)
                *nl = '\n';
            line = nl ? nl + 1 : NULL;
        }
        for (char *p = strstr(s, "PLUME_API"); p; p = strstr(p + 1, "PLUME_API")) {
            if ((p > s && ident(p[-1])) || ident(p[9]))
                continue;
            const char *bol = p;
            while (bol > s && bol[-1] != '\n')
                bol--;
            while (*bol == ' ')
                bol++;
            if (*bol == '#') /* the macro's definition */
                continue;
            char *paren = strchr(p, '(');
            if (!paren)
                continue;
            char *e = paren;
            while (e > p && e[-1] == ' ')
                e--;
            char *b = e;
            while (b > p && ident(b[-1]))
                b--;
            if (b > p + 9 && e > b) {
                names_add(api, b, (size_t)(e - b));
                if (!has_doc_comment(orig, (size_t)(p - s))) {
                    fprintf(stderr, "    %s: %s has no doc comment\n", g.gl_pathv[h] + 3, api->name[api->n - 1]);
                    (*undocumented)++;
                }
            }
        }
        free(s);
        free(orig);
    }
    globfree(&g);
}

/* Headers of the tree (not public) that use PLUME_API: each such use would export an internal
 * function. lib/core/export.h only forwards to the public definition. */
static int tree_api_uses(void)
{
    glob_t g;
    tree_headers(&g);
    int bad = 0;
    for (size_t h = 0; h < g.gl_pathc; h++) {
        char *s = read_all(g.gl_pathv[h]);
        if (!s)
            continue;
        blank_comments(s);
        if (strstr(s, "PLUME_API")) {
            fprintf(stderr, "    %s uses PLUME_API: only include/plume/ declares the public face\n", g.gl_pathv[h] + 3);
            bad++;
        }
        free(s);
    }
    globfree(&g);
    return bad;
}

/* The global symbols libplume.a defines, as "VIS NAME" pairs: default-visibility ones in *pub,
 * hidden ones in *hid; weak C++ template instances (mangled _Z names: the CGAL shim's std and
 * Boost templates, and the DW.ref. cells of C++ exception handling) are not plume's, nor are
 * AddressSanitizer's __odr_asan. markers of plume's own variables. 0 when there is no libplume.a next to the runner. */
static int static_globals(names *pub, names *hid, names *other)
{
    char self[PATH_MAX - 32];
    ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
    if (n <= 0)
        return 0;
    self[n] = 0;
    char *slash = strrchr(self, '/');
    if (slash)
        *slash = 0;
    char lib[PATH_MAX];
    snprintf(lib, sizeof lib, "%s/libplume.a", self);
    if (access(lib, R_OK) != 0)
        return 0;
    char cmd[PATH_MAX + 64];
    snprintf(cmd, sizeof cmd, "readelf -sW '%s' 2>/dev/null", lib);
    FILE *p = popen(cmd, "r");
    if (!p)
        return 0;
    char line[4096];
    while (fgets(line, sizeof line, p)) {
        /* "Num: Value Size Type Bind Vis Ndx Name" */
        char num[32], value[64], size[32], type[32], bind[32], vis[32], ndx[32], name[2048];
        if (sscanf(line, "%31s %63s %31s %31s %31s %31s %31s %2047s", num, value, size, type, bind, vis, ndx, name) != 8)
            continue;
        if (!strcmp(ndx, "UND") || (strcmp(bind, "GLOBAL") && strcmp(bind, "WEAK")))
            continue;
        if (!strcmp(bind, "WEAK") && (!strncmp(name, "_Z", 2) || !strncmp(name, "DW.ref.", 7)))
            continue;
        if (!strncmp(name, "__odr_asan.plume_", 17)) /* AddressSanitizer's marker of a plume_ variable */
            continue;
        if (strncmp(name, "plume_", 6) != 0)
            names_add(other, name, strlen(name));
        else if (!strcmp(vis, "DEFAULT"))
            names_add(pub, name, strlen(name));
        else
            names_add(hid, name, strlen(name));
    }
    pclose(p);
    return 1;
}

/* the defined dynamic symbols of libplume.so next to the runner; 0 when there is none */
static int exported(names *out, char *lib, size_t len)
{
    char self[PATH_MAX - 16];
    ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
    if (n <= 0)
        return 0;
    self[n] = 0;
    char *slash = strrchr(self, '/');
    if (slash)
        *slash = 0;
    snprintf(lib, len, "%s/libplume.so", self);
    if (access(lib, R_OK) != 0)
        return 0;
    char cmd[PATH_MAX + 64];
    snprintf(cmd, sizeof cmd, "nm -D --defined-only '%s' 2>/dev/null", lib);
    FILE *p = popen(cmd, "r");
    if (!p)
        return 0;
    char line[4096];
    while (fgets(line, sizeof line, p)) {
        /* "address type name" */
        char addr[64], type[8], name[sizeof line];
        if (sscanf(line, "%63s %7s %4095s", addr, type, name) == 3)
            names_add(out, name, strlen(name));
    }
    pclose(p);
    return 1;
}

/* The names of `a` that `b` lacks, each printed after `what`; their count. */
static int missing_from(const names *a, const names *b, const char *what)
{
    int n = 0;
    for (size_t i = 0; i < a->n; i++)
        if (!names_has(b, a->name[i])) {
            fprintf(stderr, "    %s: %s\n", what, a->name[i]);
            n++;
        }
    return n;
}

void test_exports_only_the_api(void)
{
    names api = {0}, dyn = {0};
    char lib[PATH_MAX];
    int unmarked = 0, undocumented = 0;
    declared_api(&api, &unmarked, &undocumented);
    CHECK(unmarked == 0);
    CHECK(undocumented == 0);
    CHECK(tree_api_uses() == 0);
    CHECK(api.n > 50);
    /* libplume.a: every global is a plume_ name, and the default-visibility ones are the face */
    names pub = {0}, hid = {0}, other = {0};
    if (static_globals(&pub, &hid, &other)) {
        fprintf(stderr, "    libplume.a: %zu public and %zu hidden plume_ globals, %zu others\n", pub.n, hid.n, other.n);
        for (size_t i = 0; i < other.n; i++)
            fprintf(stderr, "    libplume.a defines %s, not a plume_ name\n", other.name[i]);
        CHECK(other.n == 0);
        CHECK(missing_from(&pub, &api, "libplume.a, default visibility but not in include/plume/") == 0);
        CHECK(missing_from(&api, &pub, "libplume.a, declared PLUME_API but not defined public") == 0);
    }
    names_free(&pub);
    names_free(&hid);
    names_free(&other);
    if (!exported(&dyn, lib, sizeof lib)) {
        /* the sanitizer build links the runner alone, without a shared library */
        fprintf(stderr, "    no libplume.so next to the runner: the exported set is checked in the regular build "
                        "(skipped)\n");
        names_free(&api);
        return;
    }
    fprintf(stderr, "    %s exports %zu symbols; include/plume/ declares %zu functions PLUME_API\n", lib, dyn.n, api.n);
    CHECK(dyn.n > 0);
    int bad = 0;
    for (size_t i = 0; i < dyn.n; i++) {
        const char *s = dyn.name[i];
        if (!strncmp(s, "GOMP_", 5) || !strncmp(s, "omp_", 4) || !strncmp(s, "gomp_", 5)) {
            fprintf(stderr, "    exported: %s, OpenMP's runtime's own symbol\n", s);
            bad++;
        } else if (strncmp(s, "plume_", 6) != 0) {
            fprintf(stderr, "    exported: %s, not a plume_ name\n", s);
            bad++;
        } else if (!names_has(&api, s)) {
            fprintf(stderr, "    exported: %s, declared PLUME_API in no public header\n", s);
            bad++;
        }
    }
    bad += missing_from(&api, &dyn, "declared PLUME_API but not exported");
    CHECK(bad == 0);
    names_free(&api);
    names_free(&dyn);
}

/* include/plume/plume.h includes every public header */
void test_exports_umbrella(void)
{
    char *umbrella = read_all("../include/plume/plume.h");
    CHECK(umbrella != NULL);
    if (!umbrella)
        return;
    glob_t g;
    installed_headers(&g);
    CHECK(g.gl_pathc >= 8);
    for (size_t h = 0; h < g.gl_pathc; h++) {
        const char *name = strrchr(g.gl_pathv[h], '/') + 1;
        if (!strcmp(name, "plume.h"))
            continue;
        char inc[PATH_MAX + 16];
        snprintf(inc, sizeof inc, "#include \"%s\"", name);
        if (!strstr(umbrella, inc)) {
            fprintf(stderr, "    include/plume/plume.h does not include %s\n", name);
            CHECK(!"every public header in the umbrella");
        }
    }
    globfree(&g);
    free(umbrella);
}
static int sh(const char *fmt, const char *a, const char *b)
{
    /* numbered conversions only (%1$s: a, %2$s: b); a leading %1$.0s names a's type for the
     * formats that use b alone */
    char f[4 * PATH_MAX + 16], cmd[8 * PATH_MAX];
    snprintf(f, sizeof f, "%%1$.0s%s", fmt);
    snprintf(cmd, sizeof cmd, f, a, b);
    int rc = system(cmd);
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

/* The arguments of the examples that take some (%1$s: the source tree, %2$s: the prefix) */
static const struct {
    const char *name, *args;
} example_args[] = {
    {"homogenize", "'%1$s/data/layout_barbules.json' '%2$s/examples/moduli.h5'"},
    {"scene", "'%1$s/data/layout_feather_si.json' '%2$s/examples/scene_out'"},
};

/* The library as another C program uses it: `make install` into a fresh prefix, then every
 * program of docs/examples/ built with pkg-config against the shared library (it starts without
 * LD_LIBRARY_PATH: plume.pc's run path) and run from / to its own verdict (exit 0); the traction
 * example also against the static library (no libplume.so needed at all); `make uninstall`
 * leaves the prefix with only what the test put there. */
void test_exports_installed_example(void)
{
    names dyn = {0};
    char lib[PATH_MAX];
    if (!exported(&dyn, lib, sizeof lib)) {
        fprintf(stderr, "    no libplume.so next to the runner: installed in the regular build (skipped)\n");
        return;
    }
    names_free(&dyn);
    char build[PATH_MAX], prefix[64] = "/tmp/plume-prefix-XXXXXX", src[PATH_MAX];
    snprintf(build, sizeof build, "%s", lib);
    *strrchr(build, '/') = 0;
    char cwd[PATH_MAX - 8];
    if (!mkdtemp(prefix) || !getcwd(cwd, sizeof cwd)) {
        CHECK(0);
        return;
    }
    snprintf(src, sizeof src, "%s/..", cwd);
    /* the runner's own build directory: everything is up to date, install only copies */
    CHECK(sh("make -s -C .. BUILD='%1$s' install PREFIX='%2$s' >'%2$s/make.log' 2>&1", build, prefix) == 0);
    CHECK(sh("mkdir -p '%2$s/examples'", build, prefix) == 0);
    const char *env = "env -u LD_LIBRARY_PATH PKG_CONFIG_PATH='%2$s/lib/pkgconfig'";
    char cmd[4096];
    glob_t g;
    memset(&g, 0, sizeof g);
    glob("../docs/examples/*.c", 0, NULL, &g);
    CHECK(g.gl_pathc >= 5);
    for (size_t i = 0; i < g.gl_pathc; i++) {
        char name[256];
        const char *base = strrchr(g.gl_pathv[i], '/') + 1;
        snprintf(name, sizeof name, "%.*s", (int)(strlen(base) - 2), base);
        snprintf(cmd, sizeof cmd,
                 "%s sh -c 'cc -std=c11 -Wall -Wextra -Wpedantic -Werror %s $(pkg-config --cflags --libs plume) -lm "
                 "-o %%2$s/examples/%s' >>'%%2$s/make.log' 2>&1",
                 env, g.gl_pathv[i], name);
        int built = sh(cmd, build, prefix) == 0;
        if (!built)
            fprintf(stderr, "    docs/examples/%s.c does not build against the installed library\n", name);
        CHECK(built);
        const char *args = "";
        for (size_t k = 0; k < sizeof example_args / sizeof example_args[0]; k++)
            if (!strcmp(example_args[k].name, name))
                args = example_args[k].args;
        char run[2048];
        snprintf(run, sizeof run, "cd / && env -u LD_LIBRARY_PATH '%%2$s/examples/%s' %s >'%%2$s/examples/%s.out' 2>&1",
                 name, args, name);
        char full[4096];
        snprintf(full, sizeof full, run, src, prefix); /* %1$s and %2$s of the arguments */
        /* sh() formats again: percent signs left in the arguments would be read as conversions */
        int ran = built && sh("%2$s", build, full) == 0;
        fprintf(stderr, "    docs/examples/%s.c: %s\n", name, ran ? "built, ran, ok" : "FAILED");
        if (!ran) {
            snprintf(run, sizeof run, "%s/examples/%s.out", prefix, name);
            sh("sed 's/^/      /' '%2$s' | tail -n 5 >&2", build, run);
        }
        CHECK(ran);
    }
    globfree(&g);
    snprintf(cmd, sizeof cmd,
             "%s sh -c 'cc -std=c11 ../docs/examples/traction.c $(pkg-config --cflags plume) "
             "$(pkg-config --variable=static_libs plume) -o %%2$s/static' >>'%%2$s/make.log' 2>&1",
             env);
    CHECK(sh(cmd, build, prefix) == 0);
    CHECK(sh("cd / && env -u LD_LIBRARY_PATH '%2$s/examples/traction' 2>&1 | tail -n 1 | grep -q 'converged: 1'", build,
             prefix) == 0);
    CHECK(sh("cd / && env -u LD_LIBRARY_PATH '%2$s/static' 2>&1 | tail -n 1 | grep -q 'converged: 1'", build, prefix) == 0);
    char needed[128];
    snprintf(needed, sizeof needed, "readelf -d '%%2$s/examples/traction' | grep NEEDED | grep -q 'libplume.so.%d\\]'",
             PLUME_VERSION_MAJOR);
    CHECK(sh(needed, build, prefix) == 0);
    CHECK(sh("readelf -d '%2$s/static' | grep NEEDED | grep -q libplume", build, prefix) != 0);
    CHECK(sh("make -s -C .. BUILD='%1$s' uninstall PREFIX='%2$s' >>'%2$s/make.log' 2>&1", build, prefix) == 0);
    CHECK(sh("test -z \"$(find '%2$s' \\( -type f -o -type l \\) -not -name static -not -name make.log "
             "-not -path '*/examples/*')\"", build, prefix) == 0);
    if (plume_test_failures)
        sh("sed 's/^/    /' '%2$s/make.log' | tail -n 20 >&2", build, prefix);
    sh("rm -rf '%2$s'", build, prefix);
}
