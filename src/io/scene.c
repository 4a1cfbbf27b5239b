/* cohfrac — scene loading.
 *
 * A scene is a Lua 5.4 script that returns a table.  Loading runs in four
 * steps:
 *   1. run the script in a sandboxed state (base, string, table, math only;
 *      text chunks only);
 *   2. apply the `key.path=value` overrides to the returned table;
 *   3. walk the table against the schema in cohfrac/scene.h, in schema order,
 *      filling a cf_world_def and every default;
 *   4. print the filled scene back as Lua text (`resolved`).
 *
 * Steps 2 and 3 run inside lua_pcall so that a Lua memory error cannot
 * unwind through C code unprotected, and every table access is raw so that
 * metatables set by the script cannot run code behind our back.
 */
#define _XOPEN_SOURCE 700 /* realpath (XSI), stat */

#include "cohfrac/scene.h"
#include "cohfrac/settings.h"
#include "cohfrac/surface.h"

#include <lauxlib.h>
#include <lua.h>
#include <lualib.h>

#include <assert.h>
#include <ctype.h>
#include <errno.h>
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define COUNT(a) ((int)(sizeof(a) / sizeof((a)[0])))
#define TRY(x)                                                                 \
    do {                                                                       \
        cf_status try_status_ = (x);                                           \
        if (try_status_ != CF_OK)                                              \
            return try_status_;                                                \
    } while (0)

/* ---------------------------------------------------------------- schema */

/* Key lists in schema order: they drive unknown-key checks and the
 * "allowed:" lists in messages; resolved_text() writes keys in this order. */
static const char *const top_keys[] = {"name",     "duration", "gravity",   "material", "bodies",
                                       "boundary", "obstacles", "solver",   "output"};
static const char *const body_keys[] = {"mesh",     "scale",   "position", "orientation",
                                        "velocity", "angular_velocity", "expansion_rate",
                                        "expansion_center", "hollow_layers", "visual"};
/* Primitive meshes (bodies[i].mesh = {type = ...}), one key list per type. */
static const char *const prim_box_keys[] = {"type", "size", "cells", "tets_per_cell"};
static const char *const prim_sphere_keys[] = {"type", "radius", "mesh_size"};
static const char *const prim_hollow_keys[] = {"type", "radius", "thickness", "mesh_size"};
static const char *const prim_plate_keys[] = {"type", "size", "mesh_size"};
static const char *const prim_beam_keys[] = {"type", "size", "notch", "mesh_size"};
static const char *const boundary_keys[] = {"region", "velocity", "fixed", "axes", "body"};
static const char *const region_box_keys[] = {"type", "min", "max"};
static const char *const region_plane_keys[] = {"type", "point", "normal", "tolerance"};
static const char *const region_group_keys[] = {"type", "name"};
static const char *const plane_keys[] = {"type", "point", "normal", "friction", "restitution"};
static const char *const sphere_keys[] = {"type",     "center",   "radius",
                                          "velocity", "friction", "restitution"};
static const char *const box_keys[] = {"type",     "center",   "half_extents",
                                       "velocity", "friction", "restitution"};
static const char *const mesh_obstacle_keys[] = {"type",     "file",     "scale",      "orientation",
                                                 "position", "friction", "restitution"};
static const char *const crack_plane_keys[] = {"point", "normal", "tolerance"};
static const char *const output_keys[] = {"file", "frame_interval", "cracks", "fields"};

/* Enum spellings, indexed by the enum values of scene.h (primitive_names by
 * cf_primitive_type - 1: CF_PRIM_NONE has no spelling). */
static const char *const primitive_names[] = {"box", "sphere", "hollow_sphere", "plate",
                                              "notched_beam"};
static const char *const region_names[] = {"box", "plane", "group"};
static const char *const obstacle_names[] = {
#define CF_OBSTACLE_NAME_(NAME, name) #name,
    CF_OBSTACLE_TYPES(CF_OBSTACLE_NAME_)
#undef CF_OBSTACLE_NAME_
};
_Static_assert(CF_PRIM_NONE == 0 && CF_PRIM_BOX == 1 && CF_PRIM_SPHERE == 2 &&
                   CF_PRIM_HOLLOW_SPHERE == 3 && CF_PRIM_PLATE == 4 && CF_PRIM_NOTCHED_BEAM == 5,
               "primitive_names follows cf_primitive_type");
_Static_assert(CF_REGION_BOX == 0 && CF_REGION_PLANE == 1 && CF_REGION_GROUP == 2,
               "region_names follows cf_region_type");
_Static_assert(CF_CONSTRAINTS_PBD == 0 && CF_CONSTRAINTS_XPBD == 1 && CF_CONSTRAINTS_NONE == 2,
               "constraints_names follows cf_constraints");

/* An allowed interval for a number; `why` is appended to the message. */
typedef struct range {
    double lo, hi;
    int lo_closed, hi_closed;
    const char *why;
} range;

static const range POSITIVE = {0.0, INFINITY, 0, 0, NULL};
static const range NON_NEGATIVE = {0.0, INFINITY, 1, 0, NULL};
static const range ANY = {-INFINITY, INFINITY, 0, 0, NULL};

static const double ZERO3[3] = {0.0, 0.0, 0.0};

/* ---------------------------------------------------------------- loader */

/* Limits on a scene script (docs/reliability.md): a script that loops
 * forever or fills memory stops with an error naming the limit. */
#define SCENE_MAX_INSTRUCTIONS 200000000L /* about a second of Lua */
#define SCENE_MAX_BYTES (256L << 20)
#define SCENE_HOOK_EVERY 100000

typedef struct script_budget {
    size_t bytes;
    long instructions;
    /* Why the last allocation Lua asked for was refused: the limit (1) or
     * the system's allocator (0).  Lua reports both as LUA_ERRMEM. */
    int refused_by_limit;
} script_budget;

typedef struct loader {
    lua_State *L;
    const char *file;     /* scene path as given: every message starts with it */
    const char *text;     /* the script itself, or NULL to read `file` */
    char dir[1024];       /* the scene file's directory: relative mesh paths start here */
    const char *mesh_dir; /* where prepared meshes live; may be NULL */
    const char *const *overrides;
    int n_overrides;
    cf_scene *sc;         /* the scene being filled */
    cf_world_def *s;      /* its world definition, &sc->world */
    cf_error *err;
    cf_status status;   /* result of the protected part */
    char path[512];     /* key path of the table being read, e.g. "solver.pbd" */
    size_t path_len;
    char key[768];      /* scratch: the full path of one key, for messages */
} loader;

static cf_status fail(loader *ld, cf_status code, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

static cf_status fail(loader *ld, cf_status code, const char *fmt, ...)
{
    char msg[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return cf_error_set(ld->err, code, "%s: %s", ld->file, msg);
}

/* A Lua call that ended with LUA_ERRMEM while doing `what`: the script
 * went over its memory limit (bad input, exit 2), or the process is out of
 * memory (exit 5). */
static cf_status memory_failure(loader *ld, const char *what)
{
    void *ud;
    lua_getallocf(ld->L, &ud);
    if (((script_budget *)ud)->refused_by_limit)
        return fail(ld, CF_ERR_SCENE_SYNTAX,
                    "the script used more than %ld MiB of memory: a scene only builds a table",
                    SCENE_MAX_BYTES >> 20);
    return fail(ld, CF_ERR_NOMEM, "out of memory %s", what);
}

/* Full path of `key` inside the current table ("solver.pbd.iterations"). */
static const char *kp(loader *ld, const char *key)
{
    if (ld->path_len == 0)
        snprintf(ld->key, sizeof ld->key, "%s", key);
    else
        snprintf(ld->key, sizeof ld->key, "%s.%s", ld->path, key);
    return ld->key;
}

static size_t path_push_key(loader *ld, const char *key)
{
    size_t old = ld->path_len;
    snprintf(ld->path + old, sizeof ld->path - old, old ? ".%s" : "%s", key);
    ld->path_len = strlen(ld->path);
    return old;
}

static size_t path_push_index(loader *ld, int i)
{
    size_t old = ld->path_len;
    snprintf(ld->path + old, sizeof ld->path - old, "[%d]", i);
    ld->path_len = strlen(ld->path);
    return old;
}

static void path_pop(loader *ld, size_t old)
{
    ld->path_len = old;
    ld->path[old] = '\0';
}

/* Pushes t[key] without metamethods; returns its Lua type. */
static int raw_get(lua_State *L, int t, const char *key)
{
    lua_pushstring(L, key);
    return lua_rawget(L, t);
}

/* Edit distance between two short keys, for "did you mean" hints. */
static int edit_distance(const char *a, const char *b)
{
    size_t la = strlen(a), lb = strlen(b);
    int prev[64], cur[64];
    if (la > 63 || lb > 63)
        return INT_MAX;
    for (size_t j = 0; j <= lb; j++)
        prev[j] = (int)j;
    for (size_t i = 1; i <= la; i++) {
        cur[0] = (int)i;
        for (size_t j = 1; j <= lb; j++) {
            int best = prev[j - 1] + (a[i - 1] != b[j - 1]);
            if (prev[j] + 1 < best)
                best = prev[j] + 1;
            if (cur[j - 1] + 1 < best)
                best = cur[j - 1] + 1;
            cur[j] = best;
        }
        memcpy(prev, cur, (lb + 1) * sizeof prev[0]);
    }
    return prev[lb];
}

/* "a, b, c" and, when one name is close to `given`, " (did you mean 'b'?)". */
static void list_names(const char *const *names, int n, const char *given, char *list,
                       size_t list_size, char *hint, size_t hint_size)
{
    size_t len = 0;
    int best = INT_MAX, best_i = -1;
    list[0] = '\0';
    hint[0] = '\0';
    for (int i = 0; i < n; i++) {
        int w = snprintf(list + len, list_size - len, "%s%s", i ? ", " : "", names[i]);
        if (w > 0)
            len += (size_t)w < list_size - len ? (size_t)w : list_size - len - 1;
        if (given) {
            int d = edit_distance(given, names[i]);
            if (d < best) {
                best = d;
                best_i = i;
            }
        }
    }
    /* Two edits catch most typos without suggesting unrelated keys. */
    if (best_i >= 0 && best > 0 && best <= 2)
        snprintf(hint, hint_size, " (did you mean '%s'?)", names[best_i]);
}

/* The key at stack index -2 is not in `allowed`: report it. */
static cf_status unknown_key(loader *ld, const char *const *allowed, int n)
{
    lua_State *L = ld->L;
    char name[1024], list[512], hint[128];
    const char *given = NULL;
    switch (lua_type(L, -2)) {
    case LUA_TSTRING:
        given = lua_tostring(L, -2);
        snprintf(name, sizeof name, "%s", kp(ld, given));
        break;
    case LUA_TNUMBER:
        if (lua_isinteger(L, -2))
            snprintf(name, sizeof name, "%s[%lld]", ld->path, (long long)lua_tointeger(L, -2));
        else
            snprintf(name, sizeof name, "%s[%g]", ld->path, (double)lua_tonumber(L, -2));
        break;
    default:
        snprintf(name, sizeof name, "%s[<%s>]", ld->path, luaL_typename(L, -2));
        break;
    }
    list_names(allowed, n, given, list, sizeof list, hint, sizeof hint);
    return fail(ld, CF_ERR_SCENE_KEY, "unknown key '%s'; allowed: %s%s", name, list, hint);
}

/* Every key of the table at `t` must be one of `allowed`. */
static cf_status check_keys(loader *ld, int t, const char *const *allowed, int n)
{
    lua_State *L = ld->L;
    lua_pushnil(L);
    while (lua_next(L, t)) {
        int ok = 0;
        if (lua_type(L, -2) == LUA_TSTRING) {
            size_t len;
            const char *k = lua_tolstring(L, -2, &len);
            for (int i = 0; i < n && !ok; i++)
                ok = strlen(allowed[i]) == len && memcmp(allowed[i], k, len) == 0;
        }
        if (!ok)
            return unknown_key(ld, allowed, n);
        lua_pop(L, 1);
    }
    return CF_OK;
}

/* The shortest of %.15g..%.17g that reads back as v: "0.1", not
 * "0.10000000000000001", yet 0.49999999999999994 is not shown as 0.5. */
static const char *shortest(char buf[40], double v)
{
    for (int prec = 15; prec <= 17; prec++) {
        snprintf(buf, 40, "%.*g", prec, v);
        if (strtod(buf, NULL) == v)
            break;
    }
    return buf;
}

static cf_status check_range(loader *ld, const char *key, double v, const range *r)
{
    char rule[128], got[40];
    int ok = (r->lo_closed ? v >= r->lo : v > r->lo) && (r->hi_closed ? v <= r->hi : v < r->hi);
    if (ok)
        return CF_OK;
    if (isinf(r->hi))
        snprintf(rule, sizeof rule, "%s %g", r->lo_closed ? ">=" : ">", r->lo);
    else if (isinf(r->lo))
        snprintf(rule, sizeof rule, "%s %g", r->hi_closed ? "<=" : "<", r->hi);
    else
        snprintf(rule, sizeof rule, "in %c%g, %g%c", r->lo_closed ? '[' : '(', r->lo, r->hi,
                 r->hi_closed ? ']' : ')');
    return fail(ld, CF_ERR_SCENE_VALUE, "'%s' must be %s%s%s, got %s", kp(ld, key), rule,
                r->why ? " " : "", r->why ? r->why : "", shortest(got, v));
}

/* A number at t[key]; absent: *def, or a missing-key error when def is NULL. */
static cf_status get_num(loader *ld, int t, const char *key, const double *def, const range *r,
                         double *out)
{
    lua_State *L = ld->L;
    int ty = raw_get(L, t, key);
    if (ty == LUA_TNIL) {
        lua_pop(L, 1);
        if (!def)
            return fail(ld, CF_ERR_SCENE_KEY, "missing required key '%s'", kp(ld, key));
        *out = *def;
    } else {
        if (ty != LUA_TNUMBER)
            return fail(ld, CF_ERR_SCENE_TYPE, "'%s' must be a number, got %s", kp(ld, key),
                        lua_typename(L, ty));
        *out = (double)lua_tonumber(L, -1);
        lua_pop(L, 1);
        if (!isfinite(*out))
            return fail(ld, CF_ERR_SCENE_VALUE, "'%s' must be a finite number, got %g",
                        kp(ld, key), *out);
    }
    return check_range(ld, key, *out, r);
}

/* An integer at t[key] (a float with an integral value is accepted). */
static cf_status get_int(loader *ld, int t, const char *key, int def, const range *r, int *out)
{
    lua_State *L = ld->L;
    int ty = raw_get(L, t, key);
    if (ty == LUA_TNIL) {
        lua_pop(L, 1);
        *out = def;
    } else {
        int is_int = 0;
        lua_Integer v;
        if (ty != LUA_TNUMBER)
            return fail(ld, CF_ERR_SCENE_TYPE, "'%s' must be an integer, got %s", kp(ld, key),
                        lua_typename(L, ty));
        v = lua_tointegerx(L, -1, &is_int);
        if (!is_int)
            return fail(ld, CF_ERR_SCENE_TYPE, "'%s' must be an integer, got %g", kp(ld, key),
                        (double)lua_tonumber(L, -1));
        lua_pop(L, 1);
        if (v < INT_MIN || v > INT_MAX)
            return fail(ld, CF_ERR_SCENE_VALUE, "'%s' is out of range, got %lld", kp(ld, key),
                        (long long)v);
        *out = (int)v;
    }
    return check_range(ld, key, *out, r);
}

/* A non-empty string without NUL bytes that fits in `size` bytes. */
static cf_status get_str(loader *ld, int t, const char *key, const char *def, char *out,
                         size_t size)
{
    lua_State *L = ld->L;
    int ty = raw_get(L, t, key);
    size_t len;
    const char *v;
    if (ty == LUA_TNIL) {
        lua_pop(L, 1);
        if (!def)
            return fail(ld, CF_ERR_SCENE_KEY, "missing required key '%s'", kp(ld, key));
        v = def;
        len = strlen(def);
    } else {
        if (ty != LUA_TSTRING)
            return fail(ld, CF_ERR_SCENE_TYPE, "'%s' must be a string, got %s", kp(ld, key),
                        lua_typename(L, ty));
        v = lua_tolstring(L, -1, &len);
    }
    if (len == 0)
        return fail(ld, CF_ERR_SCENE_VALUE, "'%s' must not be empty", kp(ld, key));
    if (strlen(v) != len)
        return fail(ld, CF_ERR_SCENE_VALUE, "'%s' must not contain NUL bytes", kp(ld, key));
    if (len >= size)
        return fail(ld, CF_ERR_SCENE_VALUE, "'%s' is too long (%zu bytes, at most %zu)",
                    kp(ld, key), len, size - 1);
    memcpy(out, v, len + 1);
    if (ty != LUA_TNIL)
        lua_pop(L, 1);
    return CF_OK;
}

/* One of `names` at t[key]; *out is its index.  def < 0: required. */
static cf_status get_enum(loader *ld, int t, const char *key, const char *const *names, int n,
                          int def, int *out)
{
    lua_State *L = ld->L;
    int ty = raw_get(L, t, key);
    const char *v;
    char list[256], hint[128];
    if (ty == LUA_TNIL) {
        lua_pop(L, 1);
        if (def < 0)
            return fail(ld, CF_ERR_SCENE_KEY, "missing required key '%s'", kp(ld, key));
        *out = def;
        return CF_OK;
    }
    if (ty != LUA_TSTRING)
        return fail(ld, CF_ERR_SCENE_TYPE, "'%s' must be a string, got %s", kp(ld, key),
                    lua_typename(L, ty));
    v = lua_tostring(L, -1);
    for (int i = 0; i < n; i++) {
        if (strcmp(v, names[i]) == 0) {
            *out = i;
            lua_pop(L, 1);
            return CF_OK;
        }
    }
    list_names(names, n, v, list, sizeof list, hint, sizeof hint);
    return fail(ld, CF_ERR_SCENE_VALUE, "'%s' is \"%s\"; allowed: %s%s", kp(ld, key), v, list,
                hint);
}

/* A list of exactly n numbers; def NULL: required. */
static cf_status get_vec(loader *ld, int t, const char *key, int n, const double *def,
                         double *out)
{
    lua_State *L = ld->L;
    int ty = raw_get(L, t, key), v, count = 0;
    const char *what = n == 4 ? "a list of 4 numbers (quaternion w, x, y, z)"
                              : "a list of 3 numbers";
    if (ty == LUA_TNIL) {
        lua_pop(L, 1);
        if (!def)
            return fail(ld, CF_ERR_SCENE_KEY, "missing required key '%s'", kp(ld, key));
        memcpy(out, def, (size_t)n * sizeof out[0]);
        return CF_OK;
    }
    if (ty != LUA_TTABLE)
        return fail(ld, CF_ERR_SCENE_TYPE, "'%s' must be %s, got %s", kp(ld, key), what,
                    lua_typename(L, ty));
    v = lua_gettop(L);
    lua_pushnil(L);
    while (lua_next(L, v)) {
        count++;
        lua_pop(L, 1);
    }
    if (count != n)
        return fail(ld, CF_ERR_SCENE_TYPE, "'%s' must be %s, got a table of %d entries",
                    kp(ld, key), what, count);
    for (int i = 0; i < n; i++) {
        int ety = lua_rawgeti(L, v, i + 1);
        if (ety != LUA_TNUMBER)
            return fail(ld, CF_ERR_SCENE_TYPE, "'%s' must be %s, got %s at [%d]", kp(ld, key),
                        what, lua_typename(L, ety), i + 1);
        out[i] = (double)lua_tonumber(L, -1);
        lua_pop(L, 1);
        if (!isfinite(out[i]))
            return fail(ld, CF_ERR_SCENE_VALUE, "'%s' must hold finite numbers, got %g at [%d]",
                        kp(ld, key), out[i], i + 1);
    }
    lua_pop(L, 1);
    return CF_OK;
}

/* Scale v to unit length.  A vector already within rounding of unit length
 * is kept as it is, so that loading the resolved text again reproduces the
 * same bits (normalising twice can move the last bit). */
static cf_status normalise(loader *ld, const char *key, double *v, int n, const char *what)
{
    double m = 0.0, sum = 0.0, norm;
    for (int i = 0; i < n; i++)
        m = fmax(m, fabs(v[i]));
    if (m == 0.0)
        return fail(ld, CF_ERR_SCENE_VALUE, "'%s' must be a non-zero %s, got all zeros",
                    kp(ld, key), what);
    /* Dividing by the largest component first avoids overflow in the squares. */
    for (int i = 0; i < n; i++)
        sum += (v[i] / m) * (v[i] / m);
    norm = sqrt(sum);
    if (fabs(m * norm - 1.0) > 8.0 * DBL_EPSILON)
        for (int i = 0; i < n; i++)
            v[i] = (v[i] / m) / norm;
    return CF_OK;
}

/* A boolean at t[key]; absent: def. */
static cf_status get_bool(loader *ld, int t, const char *key, int def, int *out)
{
    lua_State *L = ld->L;
    int ty = raw_get(L, t, key);
    if (ty == LUA_TNIL) {
        *out = def;
    } else {
        if (ty != LUA_TBOOLEAN)
            return fail(ld, CF_ERR_SCENE_TYPE, "'%s' must be a boolean (true or false), got %s",
                        kp(ld, key), lua_typename(L, ty));
        *out = lua_toboolean(L, -1);
    }
    lua_pop(L, 1);
    return CF_OK;
}

/* A number (the same for x, y and z) or a list of 3 numbers; absent: def. */
static cf_status get_num_or_vec3(loader *ld, int t, const char *key, const double def[3],
                                 double out[3])
{
    lua_State *L = ld->L;
    int ty = raw_get(L, t, key);
    lua_pop(L, 1);
    if (ty == LUA_TNUMBER) {
        double v;
        TRY(get_num(ld, t, key, NULL, &ANY, &v));
        out[0] = out[1] = out[2] = v;
        return CF_OK;
    }
    if (ty == LUA_TNIL || ty == LUA_TTABLE)
        return get_vec(ld, t, key, 3, def, out);
    return fail(ld, CF_ERR_SCENE_TYPE, "'%s' must be a number or a list of 3 numbers, got %s",
                kp(ld, key), lua_typename(L, ty));
}

/* Every component of a 3-vector > 0. */
static cf_status check_positive3(loader *ld, const char *key, const double v[3])
{
    char a[40], b[40], c[40];
    for (int i = 0; i < 3; i++)
        if (!(v[i] > 0.0))
            return fail(ld, CF_ERR_SCENE_VALUE,
                        "'%s' must have every component > 0, got {%s, %s, %s}", kp(ld, key),
                        shortest(a, v[0]), shortest(b, v[1]), shortest(c, v[2]));
    return CF_OK;
}

/* Pushes the table at t[key]; when absent, an empty one, so that every
 * default inside applies. */
static cf_status push_table(loader *ld, int t, const char *key)
{
    lua_State *L = ld->L;
    int ty = raw_get(L, t, key);
    if (ty == LUA_TNIL) {
        lua_pop(L, 1);
        lua_newtable(L);
    } else if (ty != LUA_TTABLE) {
        return fail(ld, CF_ERR_SCENE_TYPE, "'%s' must be a table, got %s", kp(ld, key),
                    lua_typename(L, ty));
    }
    return CF_OK;
}

/* Pushes the list at t[key] (an empty one when absent) and counts it: its
 * keys must be exactly 1..n and every entry a table. */
static cf_status push_list(loader *ld, int t, const char *key, int *n)
{
    lua_State *L = ld->L;
    lua_Integer count = 0, max = 0;
    int li;
    TRY(push_table(ld, t, key));
    li = lua_gettop(L);
    lua_pushnil(L);
    while (lua_next(L, li)) {
        if (!lua_isinteger(L, -2) || lua_tointeger(L, -2) < 1) {
            char k[256];
            if (lua_type(L, -2) == LUA_TSTRING)
                snprintf(k, sizeof k, "key '%s'", lua_tostring(L, -2));
            else
                snprintf(k, sizeof k, "a %s key", luaL_typename(L, -2));
            return fail(ld, CF_ERR_SCENE_TYPE,
                        "'%s' must be a list of tables ({ {...}, {...} }), found %s",
                        kp(ld, key), k);
        }
        if (lua_type(L, -1) != LUA_TTABLE) {
            char item[1024];
            snprintf(item, sizeof item, "%s[%lld]", kp(ld, key), (long long)lua_tointeger(L, -2));
            return fail(ld, CF_ERR_SCENE_TYPE, "'%s' must be a table, got %s", item,
                        luaL_typename(L, -1));
        }
        count++;
        if (lua_tointeger(L, -2) > max)
            max = lua_tointeger(L, -2);
        lua_pop(L, 1);
    }
    if (max != count) {
        lua_Integer hole = 1;
        while (lua_rawgeti(L, li, hole) != LUA_TNIL) {
            lua_pop(L, 1);
            hole++;
        }
        return fail(ld, CF_ERR_SCENE_TYPE, "'%s' must be a list without holes; [%lld] is missing",
                    kp(ld, key), (long long)hole);
    }
    if (count > INT_MAX / 2)
        return fail(ld, CF_ERR_SCENE_VALUE, "'%s' has too many entries", kp(ld, key));
    *n = (int)count;
    return CF_OK;
}

/* ---------------------------------------------------------------- meshes */

static int is_file(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0 && S_ISREG(st.st_mode);
}

static int ends_with(const char *s, const char *suffix)
{
    size_t ls = strlen(s), lx = strlen(suffix);
    return ls >= lx && strcmp(s + ls - lx, suffix) == 0;
}

/* Turn the `mesh` value into an absolute TetGen base path (no extension),
 * or, for a name ending in ".msh", the absolute path of that Gmsh file.
 * The directory part goes through realpath so that the resolved scene loads
 * the same mesh from any working directory; the file name is kept as given
 * (not following a symlinked .node), so the .ele beside it still matches. */
/* `path` (which contains a '/') made absolute: its directory goes through
 * realpath, its file name is kept.  `what` names the file in errors. */
static cf_status absolute_path(loader *ld, const char *key, const char *path, const char *what,
                               char *out, size_t size)
{
    char dir[2048];
    const char *cut = strrchr(path, '/');
    assert(cut);
    if (cut == path) {
        snprintf(dir, sizeof dir, "/");
    } else {
        memcpy(dir, path, (size_t)(cut - path));
        dir[cut - path] = '\0';
    }
    char *real = realpath(dir, NULL);
    if (!real)
        return fail(ld, cf_status_of_errno(errno, CF_ERR_FILE_OPEN),
                    "%s: cannot resolve directory %s: %s", kp(ld, key), dir, strerror(errno));
    int w = snprintf(out, size, "%s%s%s", real, ends_with(real, "/") ? "" : "/", cut + 1);
    free(real);
    if (w < 0 || (size_t)w >= size)
        return fail(ld, CF_ERR_SCENE_VALUE, "'%s': resolved %s path too long", kp(ld, key), what);
    return CF_OK;
}

static cf_status resolve_mesh(loader *ld, const char *key, const char *name, char *out,
                              size_t size)
{
    char base[2048], node[2100];
    const char *slash = strrchr(name, '/');
    const char *leaf = slash ? slash + 1 : name;
    int prepared = !slash && !strchr(leaf, '.');
    int w;

    if (prepared) {
        if (!ld->mesh_dir || !*ld->mesh_dir)
            return fail(ld, CF_ERR_FILE_OPEN,
                        "%s: prepared mesh '%s' cannot be found: no mesh directory was given "
                        "(or give a path to a .node file)",
                        kp(ld, key), name);
        w = snprintf(base, sizeof base, "%s/%s", ld->mesh_dir, name);
    } else if (name[0] == '/') {
        w = snprintf(base, sizeof base, "%s", name);
    } else {
        w = snprintf(base, sizeof base, "%s/%s", ld->dir, name);
    }
    if (w < 0 || (size_t)w >= sizeof base)
        return fail(ld, CF_ERR_SCENE_VALUE, "'%s': mesh path too long", kp(ld, key));
    if (!prepared && ends_with(base, ".msh")) {
        if (!is_file(base))
            return fail(ld, CF_ERR_FILE_OPEN,
                        "%s: Gmsh mesh '%s' not found: no file %s (relative paths start at the "
                        "scene file's directory)",
                        kp(ld, key), name, base);
        node[0] = '\0';
    } else {
        if (ends_with(base, ".node"))
            base[strlen(base) - 5] = '\0';
        else if (ends_with(base, ".ele"))
            base[strlen(base) - 4] = '\0';
        snprintf(node, sizeof node, "%s.node", base);
    }

    if (node[0] && !is_file(node)) {
        if (prepared) {
            /* The bunny is the one mesh we know a source surface for. */
            const char *src = strncmp(name, "bunny", 5) == 0
                                  ? "/usr/share/glmark2/models/bunny.obj"
                                  : "<surface.obj>";
            return fail(ld, CF_ERR_FILE_OPEN,
                        "%s: prepared mesh '%s' not found in %s: run `cohfrac mesh %s -o %s/%s` "
                        "or `make run`",
                        kp(ld, key), name, ld->mesh_dir, src, ld->mesh_dir, name);
        }
        return fail(ld, CF_ERR_FILE_OPEN,
                    "%s: mesh '%s' not found: no file %s (a TetGen .node/.ele pair; relative "
                    "paths start at the scene file's directory)",
                    kp(ld, key), name, node);
    }

    return absolute_path(ld, key, base, "mesh", out, size);
}

/* Turn a triangle-surface path (an obstacle's `file`) into an absolute path:
 * relative paths start at the scene file's directory, as body mesh paths
 * do; the directory part goes through realpath, the file name is kept. */
static cf_status resolve_surface(loader *ld, const char *key, const char *name, char *out,
                                 size_t size)
{
    char path[2048];
    int w;

    if (!cf_surface_format_known(name))
        return fail(ld, CF_ERR_SCENE_VALUE,
                    "'%s' is \"%s\"; a triangle surface must be in a format assimp reads "
                    "(.obj, .off, .stl, .ply, .gltf, .glb, .3ds, .fbx, .dae, ...)",
                    kp(ld, key), name);
    if (name[0] == '/')
        w = snprintf(path, sizeof path, "%s", name);
    else
        w = snprintf(path, sizeof path, "%s/%s", ld->dir, name);
    if (w < 0 || (size_t)w >= sizeof path)
        return fail(ld, CF_ERR_SCENE_VALUE, "'%s': surface path too long", kp(ld, key));
    if (!is_file(path))
        return fail(ld, CF_ERR_FILE_OPEN,
                    "%s: surface '%s' not found: no file %s (relative paths start at the scene "
                    "file's directory)",
                    kp(ld, key), name, path);
    return absolute_path(ld, key, path, "surface", out, size);
}

/* ---------------------------------------------------------------- sections */

/* Runs `call` with the sub-table t[key] on top of the stack and the key
 * path extended by `key`. */
#define WITH_TABLE(ld, t, key, call)                                                        \
    do {                                                                                    \
        size_t old_;                                                                        \
        TRY(push_table(ld, t, key));                                                        \
        old_ = path_push_key(ld, key);                                                      \
        TRY(call);                                                                          \
        path_pop(ld, old_);                                                                 \
        lua_pop((ld)->L, 1);                                                                \
    } while (0)


static cf_status read_crack_plane(loader *ld, int t, cf_solver_settings *s);

/* The settings of schema table `table` (cohfrac/settings.h) at t into the
 * definition: each key with its kind, default and range, in the schema's
 * order; tables within it in turn. */
static cf_status read_settings(loader *ld, int t, const char *table)
{
    int n, nk = 0;
    const cf_setting *e = cf_settings(&n);
    const char *keys[64];
    for (int i = 0; i < n && nk < COUNT(keys); i++)
        if (strcmp(e[i].table, table) == 0)
            keys[nk++] = e[i].key;
    TRY(check_keys(ld, t, keys, nk));
    for (int i = 0; i < n; i++) {
        const cf_setting *x = &e[i];
        if (strcmp(x->table, table) != 0)
            continue;
        double def = x->def, v = 0;
        if (x->def_from) /* read before it, in the schema's order */
            def = cf_setting_get(cf_setting_find(table, x->def_from), ld->s);
        const range r = {x->lo, x->hi, x->lo_closed, x->hi_closed, x->why};
        int k = 0;
        switch (x->kind) {
        case CF_SET_NUM:
            TRY(get_num(ld, t, x->key, &def, &r, &v));
            break;
        case CF_SET_INT:
            TRY(get_int(ld, t, x->key, (int)def, &r, &k));
            v = k;
            break;
        case CF_SET_BOOL:
            TRY(get_bool(ld, t, x->key, (int)def, &k));
            v = k;
            break;
        case CF_SET_ENUM: {
            int count = 0;
            while (x->names[count])
                count++;
            TRY(get_enum(ld, t, x->key, x->names, count, (int)def, &k));
            v = k;
            break;
        }
        case CF_SET_TABLE: {
            char sub[64];
            snprintf(sub, sizeof sub, "%s.%s", table, x->key);
            WITH_TABLE(ld, t, x->key, read_settings(ld, lua_gettop(ld->L), sub));
            continue;
        }
        case CF_SET_CUSTOM: /* solver.crack_plane, the one optional table */
            ld->s->solver.has_crack_plane = 0;
            if (raw_get(ld->L, t, x->key) != LUA_TNIL) {
                lua_pop(ld->L, 1);
                WITH_TABLE(ld, t, x->key, read_crack_plane(ld, lua_gettop(ld->L), &ld->s->solver));
            } else {
                lua_pop(ld->L, 1);
            }
            continue;
        }
        cf_setting_set(x, ld->s, v);
    }
    return CF_OK;
}

/* cells: a list of 3 integers >= 1. */
static cf_status get_cells(loader *ld, int t, const char *key, int out[3])
{
    static const double one3[3] = {1.0, 1.0, 1.0};
    double v[3];
    char got[40];
    TRY(get_vec(ld, t, key, 3, one3, v));
    for (int i = 0; i < 3; i++) {
        if (v[i] != floor(v[i]))
            return fail(ld, CF_ERR_SCENE_TYPE, "'%s' must be a list of 3 integers, got %s at [%d]",
                        kp(ld, key), shortest(got, v[i]), i + 1);
        if (v[i] < 1.0 || v[i] > INT_MAX)
            return fail(ld, CF_ERR_SCENE_VALUE, "'%s' must hold integers in [1, %d], got %s at [%d]",
                        kp(ld, key), INT_MAX, shortest(got, v[i]), i + 1);
        out[i] = (int)v[i];
    }
    return CF_OK;
}

/* A primitive mesh table (the key path ends in ".mesh"); only records the
 * parameters: meshing happens when the simulation starts. */
static cf_status read_primitive(loader *ld, int t, cf_primitive *p)
{
    char a[40], b[40];
    int type = 0;
    memset(p, 0, sizeof *p);
    TRY(get_enum(ld, t, "type", primitive_names, COUNT(primitive_names), -1, &type));
    p->type = (cf_primitive_type)(type + 1);
    switch (p->type) {
    case CF_PRIM_BOX: {
        double tets;
        TRY(check_keys(ld, t, prim_box_keys, COUNT(prim_box_keys)));
        TRY(get_vec(ld, t, "size", 3, NULL, p->size));
        TRY(check_positive3(ld, "size", p->size));
        TRY(get_cells(ld, t, "cells", p->cells));
        TRY(get_int(ld, t, "tets_per_cell", 6, &ANY, &p->tets_per_cell));
        if (p->tets_per_cell != 5 && p->tets_per_cell != 6)
            return fail(ld, CF_ERR_SCENE_VALUE, "'%s' must be 5 or 6, got %d",
                        kp(ld, "tets_per_cell"), p->tets_per_cell);
        tets = (double)p->cells[0] * p->cells[1] * p->cells[2] * p->tets_per_cell;
        if (tets > INT_MAX)
            return fail(ld, CF_ERR_SCENE_VALUE,
                        "'%s' = {%d, %d, %d} gives %.3g tets, more than %d", kp(ld, "cells"),
                        p->cells[0], p->cells[1], p->cells[2], tets, INT_MAX);
        break;
    }
    case CF_PRIM_SPHERE:
        TRY(check_keys(ld, t, prim_sphere_keys, COUNT(prim_sphere_keys)));
        TRY(get_num(ld, t, "radius", NULL, &POSITIVE, &p->radius));
        TRY(get_num(ld, t, "mesh_size", NULL, &POSITIVE, &p->mesh_size));
        break;
    case CF_PRIM_HOLLOW_SPHERE:
        TRY(check_keys(ld, t, prim_hollow_keys, COUNT(prim_hollow_keys)));
        TRY(get_num(ld, t, "radius", NULL, &POSITIVE, &p->radius));
        TRY(get_num(ld, t, "thickness", NULL, &POSITIVE, &p->thickness));
        if (p->thickness >= p->radius)
            return fail(ld, CF_ERR_SCENE_VALUE,
                        "'%s' must be < radius (%s): the shell needs a cavity, got %s",
                        kp(ld, "thickness"), shortest(a, p->radius), shortest(b, p->thickness));
        TRY(get_num(ld, t, "mesh_size", NULL, &POSITIVE, &p->mesh_size));
        break;
    case CF_PRIM_PLATE:
        TRY(check_keys(ld, t, prim_plate_keys, COUNT(prim_plate_keys)));
        TRY(get_vec(ld, t, "size", 3, NULL, p->size));
        TRY(check_positive3(ld, "size", p->size));
        TRY(get_num(ld, t, "mesh_size", NULL, &POSITIVE, &p->mesh_size));
        break;
    case CF_PRIM_NOTCHED_BEAM: {
        const double *n = p->notch;
        char c[40];
        TRY(check_keys(ld, t, prim_beam_keys, COUNT(prim_beam_keys)));
        TRY(get_vec(ld, t, "size", 3, NULL, p->size));
        TRY(check_positive3(ld, "size", p->size));
        TRY(get_vec(ld, t, "notch", 3, NULL, p->notch));
        if (!(n[0] > 0.0 && n[0] < p->size[2]))
            return fail(ld, CF_ERR_SCENE_VALUE,
                        "'%s' depth (notch[1]) must be in (0, %s), less than the beam height "
                        "size[3], got %s",
                        kp(ld, "notch"), shortest(a, p->size[2]), shortest(b, n[0]));
        if (!(n[1] > 0.0))
            return fail(ld, CF_ERR_SCENE_VALUE, "'%s' width (notch[2]) must be > 0, got %s",
                        kp(ld, "notch"), shortest(a, n[1]));
        if (!(fabs(n[2]) + 0.5 * n[1] < 0.5 * p->size[0]))
            return fail(ld, CF_ERR_SCENE_VALUE,
                        "'%s' must lie inside the beam length: |offset| + width/2 (notch[3], "
                        "notch[2]) must be < size[1]/2 = %s, got %s + %s",
                        kp(ld, "notch"), shortest(a, 0.5 * p->size[0]), shortest(b, fabs(n[2])),
                        shortest(c, 0.5 * n[1]));
        TRY(get_num(ld, t, "mesh_size", NULL, &POSITIVE, &p->mesh_size));
        break;
    }
    case CF_PRIM_NONE:
        break;
    }
    return CF_OK;
}

/* Body t into b (its placement and motion) and src (where its mesh comes
 * from). */
static cf_status read_body(loader *ld, int t, cf_body_def *b, cf_body_source *src)
{
    const cf_body_def d = cf_default_body(); /* a key left out takes its value */
    lua_State *L = ld->L;
    char mesh[1024];
    TRY(check_keys(ld, t, body_keys, COUNT(body_keys)));
    switch (raw_get(L, t, "mesh")) {
    case LUA_TTABLE: {
        size_t old = path_push_key(ld, "mesh");
        TRY(read_primitive(ld, lua_gettop(L), &src->primitive));
        path_pop(ld, old);
        lua_pop(L, 1);
        src->mesh[0] = '\0';
        break;
    }
    case LUA_TNIL:
    case LUA_TSTRING:
        lua_pop(L, 1);
        TRY(get_str(ld, t, "mesh", NULL, mesh, sizeof mesh));
        TRY(resolve_mesh(ld, "mesh", mesh, src->mesh, sizeof src->mesh));
        src->primitive.type = CF_PRIM_NONE;
        break;
    default:
        return fail(ld, CF_ERR_SCENE_TYPE,
                    "'%s' must be a string (a mesh name or path) or a table (a primitive), got %s",
                    kp(ld, "mesh"), luaL_typename(L, -1));
    }
    TRY(get_num(ld, t, "scale", &d.scale, &POSITIVE, &b->scale));
    TRY(get_vec(ld, t, "position", 3, d.position, b->position));
    TRY(get_vec(ld, t, "orientation", 4, d.orientation, b->orientation));
    TRY(normalise(ld, "orientation", b->orientation, 4, "quaternion"));
    TRY(get_vec(ld, t, "velocity", 3, ZERO3, b->velocity));
    TRY(get_vec(ld, t, "angular_velocity", 3, ZERO3, b->angular_velocity));
    TRY(get_num_or_vec3(ld, t, "expansion_rate", ZERO3, b->expansion_rate));
    if (raw_get(L, t, "expansion_center") != LUA_TNIL) {
        b->has_expansion_center = 1;
        TRY(get_vec(ld, t, "expansion_center", 3, NULL, b->expansion_center));
    }
    lua_pop(L, 1);
    TRY(get_int(ld, t, "hollow_layers", 0, &NON_NEGATIVE, &src->hollow_layers));
    src->visual[0] = '\0';
    if (raw_get(L, t, "visual") != LUA_TNIL) {
        lua_pop(L, 1);
        char visual[1024];
        TRY(get_str(ld, t, "visual", NULL, visual, sizeof visual));
        TRY(resolve_surface(ld, "visual", visual, src->visual, sizeof src->visual));
    } else {
        lua_pop(L, 1);
    }
    return CF_OK;
}

/* The `region` of a boundary entry (the key path ends in ".region"). */
static cf_status read_region(loader *ld, int t, cf_boundary *b)
{
    static const double tolerance = 1e-6;
    int type = 0;
    TRY(get_enum(ld, t, "type", region_names, COUNT(region_names), -1, &type));
    b->type = (cf_region_type)type;
    switch (b->type) {
    case CF_REGION_BOX:
        TRY(check_keys(ld, t, region_box_keys, COUNT(region_box_keys)));
        TRY(get_vec(ld, t, "min", 3, NULL, b->min));
        TRY(get_vec(ld, t, "max", 3, NULL, b->max));
        for (int i = 0; i < 3; i++)
            if (!(b->min[i] < b->max[i])) {
                char x[40], y[40];
                return fail(ld, CF_ERR_SCENE_VALUE,
                            "'%s' must exceed min in every component, got max[%d] = %s <= "
                            "min[%d] = %s",
                            kp(ld, "max"), i + 1, shortest(x, b->max[i]), i + 1,
                            shortest(y, b->min[i]));
            }
        break;
    case CF_REGION_PLANE:
        TRY(check_keys(ld, t, region_plane_keys, COUNT(region_plane_keys)));
        TRY(get_vec(ld, t, "point", 3, NULL, b->point));
        TRY(get_vec(ld, t, "normal", 3, NULL, b->normal));
        TRY(normalise(ld, "normal", b->normal, 3, "vector"));
        TRY(get_num(ld, t, "tolerance", &tolerance, &POSITIVE, &b->tolerance));
        break;
    case CF_REGION_GROUP:
        TRY(check_keys(ld, t, region_group_keys, COUNT(region_group_keys)));
        TRY(get_str(ld, t, "name", NULL, b->group, sizeof b->group));
        break;
    }
    return CF_OK;
}

/* One entry of `boundary`; bodies are read already (n_bodies of them). */
static cf_status read_boundary(loader *ld, int t, int n_bodies, cf_boundary *b)
{
    lua_State *L = ld->L;
    char axes[64];
    int has_velocity, fixed = 0;
    TRY(check_keys(ld, t, boundary_keys, COUNT(boundary_keys)));
    if (raw_get(L, t, "region") == LUA_TNIL)
        return fail(ld, CF_ERR_SCENE_KEY,
                    "missing required key '%s' (a box, plane or group region)", kp(ld, "region"));
    lua_pop(L, 1);
    WITH_TABLE(ld, t, "region", read_region(ld, lua_gettop(L), b));

    has_velocity = raw_get(L, t, "velocity") != LUA_TNIL;
    lua_pop(L, 1);
    TRY(get_bool(ld, t, "fixed", 0, &fixed));
    if (has_velocity && fixed)
        return fail(ld, CF_ERR_SCENE_VALUE,
                    "'%s' gives both 'velocity' and 'fixed = true'; give one of them (fixed = "
                    "true means velocity {0, 0, 0})",
                    ld->path);
    if (!has_velocity && !fixed)
        return fail(ld, CF_ERR_SCENE_KEY,
                    "missing required key '%s' (or 'fixed = true'): a boundary prescribes a "
                    "velocity",
                    kp(ld, "velocity"));
    TRY(get_vec(ld, t, "velocity", 3, ZERO3, b->velocity));

    TRY(get_str(ld, t, "axes", "xyz", axes, sizeof axes));
    b->axes = 0;
    for (const char *c = axes; *c; c++) {
        static const char xyz[] = "xyz";
        const char *at = strchr(xyz, *c);
        int bit = at ? 1 << (at - xyz) : 0;
        if (!bit || (b->axes & bit))
            return fail(ld, CF_ERR_SCENE_VALUE,
                        "'%s' is \"%s\"; allowed: distinct letters from \"xyz\" (\"z\", "
                        "\"xy\", ...)",
                        kp(ld, "axes"), axes);
        b->axes |= bit;
    }

    if (raw_get(L, t, "body") == LUA_TNIL) {
        b->body = -1;
    } else {
        range bodies = {1.0, (double)n_bodies, 1, 1, "(a 1-based index into bodies)"};
        TRY(get_int(ld, t, "body", 0, &bodies, &b->body));
        b->body--;
    }
    lua_pop(L, 1);
    return CF_OK;
}

static cf_status read_obstacle(loader *ld, int t, cf_obstacle *o)
{
    int type = 0;
    TRY(get_enum(ld, t, "type", obstacle_names, COUNT(obstacle_names), -1, &type));
    o->type = (cf_obstacle_type)type;
    const cf_obstacle d = cf_default_obstacle(o->type); /* a key left out takes its value */
    switch (o->type) {
    case CF_OBSTACLE_PLANE:
        TRY(check_keys(ld, t, plane_keys, COUNT(plane_keys)));
        TRY(get_vec(ld, t, "point", 3, ZERO3, o->point));
        TRY(get_vec(ld, t, "normal", 3, d.normal, o->normal));
        TRY(normalise(ld, "normal", o->normal, 3, "vector"));
        break;
    case CF_OBSTACLE_SPHERE:
        TRY(check_keys(ld, t, sphere_keys, COUNT(sphere_keys)));
        TRY(get_vec(ld, t, "center", 3, NULL, o->center));
        TRY(get_num(ld, t, "radius", NULL, &POSITIVE, &o->radius));
        TRY(get_vec(ld, t, "velocity", 3, ZERO3, o->velocity));
        break;
    case CF_OBSTACLE_BOX:
        TRY(check_keys(ld, t, box_keys, COUNT(box_keys)));
        TRY(get_vec(ld, t, "center", 3, NULL, o->center));
        TRY(get_vec(ld, t, "half_extents", 3, NULL, o->half_extents));
        for (int i = 0; i < 3; i++)
            if (!(o->half_extents[i] > 0.0))
                return fail(ld, CF_ERR_SCENE_VALUE,
                            "'%s' must have every component > 0, got {%g, %g, %g}",
                            kp(ld, "half_extents"), o->half_extents[0], o->half_extents[1],
                            o->half_extents[2]);
        TRY(get_vec(ld, t, "velocity", 3, ZERO3, o->velocity));
        break;
    case CF_OBSTACLE_MESH: {
        char file[1024];
        TRY(check_keys(ld, t, mesh_obstacle_keys, COUNT(mesh_obstacle_keys)));
        TRY(get_str(ld, t, "file", NULL, file, sizeof file));
        TRY(resolve_surface(ld, "file", file, o->file, sizeof o->file));
        TRY(get_num(ld, t, "scale", &d.scale, &POSITIVE, &o->scale));
        TRY(get_vec(ld, t, "orientation", 4, d.orientation, o->orientation));
        TRY(normalise(ld, "orientation", o->orientation, 4, "quaternion"));
        TRY(get_vec(ld, t, "position", 3, ZERO3, o->position));
        break;
    }
    }
    /* Factors on the material's values: the pair's coefficient is their
     * product (Bullet multiplies the two bodies' coefficients). */
    TRY(get_num(ld, t, "friction", &d.friction, &NON_NEGATIVE, &o->friction));
    TRY(get_num(ld, t, "restitution", &d.restitution, &NON_NEGATIVE, &o->restitution));
    return CF_OK;
}

static cf_status read_crack_plane(loader *ld, int t, cf_solver_settings *s)
{
    static const double tolerance = 1e-6;
    TRY(check_keys(ld, t, crack_plane_keys, COUNT(crack_plane_keys)));
    TRY(get_vec(ld, t, "point", 3, NULL, s->crack_plane_point));
    TRY(get_vec(ld, t, "normal", 3, NULL, s->crack_plane_normal));
    TRY(normalise(ld, "normal", s->crack_plane_normal, 3, "vector"));
    TRY(get_num(ld, t, "tolerance", &tolerance, &POSITIVE, &s->crack_plane_tolerance));
    s->has_crack_plane = 1;
    return CF_OK;
}

static cf_status read_output(loader *ld, int t, const char *name, int fracture_only,
                             cf_output_settings *o)
{
    const cf_output_settings d = cf_default_output(); /* a key left out takes its value */
    lua_State *L = ld->L;
    char def[sizeof o->file];
    TRY(check_keys(ld, t, output_keys, COUNT(output_keys)));
    snprintf(def, sizeof def, "out/%s.h5", name); /* name < 128 bytes: fits */
    /* "" means no output file. */
    if (raw_get(L, t, "file") == LUA_TSTRING && lua_rawlen(L, -1) == 0) {
        lua_pop(L, 1);
        o->file[0] = '\0';
    } else {
        lua_pop(L, 1);
        TRY(get_str(ld, t, "file", def, o->file, sizeof o->file));
        /* A relative output path starts at the scene file's directory (as
         * mesh paths do), so a run writes the same file from anywhere. */
        if (o->file[0] != '/' && strcmp(ld->dir, ".") != 0) {
            char *real = realpath(ld->dir, NULL), rel[sizeof o->file];
            int w = -1;
            if (real) {
                memcpy(rel, o->file, sizeof rel);
                w = snprintf(o->file, sizeof o->file, "%s/%s", real, rel);
                free(real);
            } else if (errno == ENOMEM) {
                return fail(ld, CF_ERR_NOMEM, "'%s': out of memory resolving the scene's directory",
                            kp(ld, "file"));
            }
            if (w < 0 || (size_t)w >= sizeof o->file)
                return fail(ld, CF_ERR_SCENE_VALUE,
                            "'%s': cannot make %s absolute against the scene's directory %s",
                            kp(ld, "file"), o->file, ld->dir);
        }
    }
    TRY(get_num(ld, t, "frame_interval", &d.frame_interval, &POSITIVE, &o->frame_interval));
    TRY(get_bool(ld, t, "cracks", fracture_only, &o->cracks));
    TRY(get_bool(ld, t, "fields", d.fields, &o->fields));
    return CF_OK;
}

static cf_status read_scene(loader *ld, int t)
{
    const cf_scene d = cf_default_scene(); /* a key left out takes its value */
    lua_State *L = ld->L;
    cf_scene *sc = ld->sc;
    cf_world_def *s = ld->s;
    int n, li;

    TRY(check_keys(ld, t, top_keys, COUNT(top_keys)));
    TRY(get_str(ld, t, "name", d.name, sc->name, sizeof sc->name));
    TRY(get_num(ld, t, "duration", &d.duration, &POSITIVE, &sc->duration));
    TRY(get_vec(ld, t, "gravity", 3, d.world.gravity, s->gravity));
    WITH_TABLE(ld, t, "material", read_settings(ld, lua_gettop(L), "material"));

    if (raw_get(L, t, "bodies") == LUA_TNIL)
        return fail(ld, CF_ERR_SCENE_KEY, "missing required key 'bodies' (a list of solids)");
    lua_pop(L, 1);
    TRY(push_list(ld, t, "bodies", &n));
    if (n == 0)
        return fail(ld, CF_ERR_SCENE_VALUE, "'bodies' is empty; a scene needs at least one body");
    li = lua_gettop(L);
    s->bodies = calloc((size_t)n, sizeof s->bodies[0]);
    sc->sources = calloc((size_t)n, sizeof sc->sources[0]);
    if (!s->bodies || !sc->sources)
        return fail(ld, CF_ERR_NOMEM, "out of memory for %d bodies", n);
    for (int i = 0; i < n; i++) {
        size_t old = path_push_key(ld, "bodies");
        path_push_index(ld, i + 1);
        lua_rawgeti(L, li, i + 1);
        TRY(read_body(ld, lua_gettop(L), &s->bodies[i], &sc->sources[i]));
        lua_pop(L, 1);
        path_pop(ld, old);
        s->n_bodies = i + 1;
    }
    lua_pop(L, 1);

    TRY(push_list(ld, t, "boundary", &n));
    li = lua_gettop(L);
    if (n > 0) {
        s->boundaries = calloc((size_t)n, sizeof s->boundaries[0]);
        if (!s->boundaries)
            return fail(ld, CF_ERR_NOMEM, "out of memory for %d boundary entries", n);
    }
    for (int i = 0; i < n; i++) {
        size_t old = path_push_key(ld, "boundary");
        path_push_index(ld, i + 1);
        lua_rawgeti(L, li, i + 1);
        TRY(read_boundary(ld, lua_gettop(L), s->n_bodies, &s->boundaries[i]));
        lua_pop(L, 1);
        path_pop(ld, old);
        s->n_boundaries = i + 1;
    }
    lua_pop(L, 1);

    TRY(push_list(ld, t, "obstacles", &n));
    li = lua_gettop(L);
    if (n > 0) {
        s->obstacles = calloc((size_t)n, sizeof s->obstacles[0]);
        if (!s->obstacles)
            return fail(ld, CF_ERR_NOMEM, "out of memory for %d obstacles", n);
    }
    for (int i = 0; i < n; i++) {
        size_t old = path_push_key(ld, "obstacles");
        path_push_index(ld, i + 1);
        lua_rawgeti(L, li, i + 1);
        TRY(read_obstacle(ld, lua_gettop(L), &s->obstacles[i]));
        lua_pop(L, 1);
        path_pop(ld, old);
        s->n_obstacles = i + 1;
    }
    lua_pop(L, 1);

    WITH_TABLE(ld, t, "solver", read_settings(ld, lua_gettop(L), "solver"));
    cf_error rule;
    if (cf_solver_check_rules(&s->solver, &rule) != CF_OK)
        return fail(ld, rule.code, "%s", rule.msg);
    if (s->n_boundaries > 0 && s->solver.mode != CF_RUN_FRACTURE)
        return fail(ld, CF_ERR_SCENE_VALUE,
                    "'boundary' has %d entr%s but solver.mode is \"%s\": boundary conditions "
                    "need solver.mode = \"fracture\"",
                    s->n_boundaries, s->n_boundaries == 1 ? "y" : "ies",
                    cf_setting_find("solver", "mode")->names[s->solver.mode]);
    WITH_TABLE(ld, t, "output",
               read_output(ld, lua_gettop(L), sc->name, s->solver.mode == CF_RUN_FRACTURE,
                           &sc->output));
    return CF_OK;
}

/* ---------------------------------------------------------------- overrides */

typedef struct segment {
    char name[64];      /* a key, or "" for a list index */
    lua_Integer index;  /* 1-based list index when name is "" */
} segment;

enum { MAX_SEGMENTS = 32 };

/* Parse "a.b[2].c" (the part before '=') into segments. */
static cf_status parse_key_path(loader *ld, const char *ov, const char *p, const char *end,
                                segment *seg, int *n_seg)
{
    int n = 0;
    while (p < end && isspace((unsigned char)*p))
        p++;
    while (end > p && isspace((unsigned char)end[-1]))
        end--;
    if (p == end)
        return fail(ld, CF_ERR_SCENE_OVERRIDE, "bad override '%s': empty key path before '='",
                    ov);
    for (;;) {
        const char *s = p;
        if (p < end && (isalpha((unsigned char)*p) || *p == '_'))
            for (p++; p < end && (isalnum((unsigned char)*p) || *p == '_'); p++)
                ;
        if (p == s)
            return fail(ld, CF_ERR_SCENE_OVERRIDE,
                        "bad override '%s': expected a key name at character %d", ov,
                        (int)(s - ov) + 1);
        if (n == MAX_SEGMENTS || (size_t)(p - s) >= sizeof seg[0].name)
            return fail(ld, CF_ERR_SCENE_OVERRIDE, "bad override '%s': key path too long", ov);
        memcpy(seg[n].name, s, (size_t)(p - s));
        seg[n].name[p - s] = '\0';
        seg[n++].index = 0;
        while (p < end && *p == '[') {
            lua_Integer v = 0;
            const char *d = ++p;
            for (; p < end && isdigit((unsigned char)*p) && v <= INT_MAX; p++)
                v = v * 10 + (*p - '0');
            if (p == d || p >= end || *p != ']' || v < 1 || v > INT_MAX)
                return fail(ld, CF_ERR_SCENE_OVERRIDE,
                            "bad override '%s': bad list index at character %d (write "
                            "name[1], name[2], ...; lists start at 1)",
                            ov, (int)(d - ov));
            p++;
            if (n == MAX_SEGMENTS)
                return fail(ld, CF_ERR_SCENE_OVERRIDE, "bad override '%s': key path too long",
                            ov);
            seg[n].name[0] = '\0';
            seg[n++].index = v;
        }
        if (p == end)
            break;
        if (*p != '.')
            return fail(ld, CF_ERR_SCENE_OVERRIDE,
                        "bad override '%s': unexpected '%c' in the key path", ov, *p);
        p++;
    }
    *n_seg = n;
    return CF_OK;
}

static void push_segment(lua_State *L, const segment *s)
{
    if (s->name[0])
        lua_pushstring(L, s->name);
    else
        lua_pushinteger(L, s->index);
}

/* Apply one "key.path=value" to the scene table at `scene`. */
static cf_status apply_override(loader *ld, int scene, const char *ov)
{
    lua_State *L = ld->L;
    segment seg[MAX_SEGMENTS];
    int base = lua_gettop(L), n_seg, value, cur, ty;
    const char *eq = strchr(ov, '='), *v;
    luaL_Buffer code;

    if (!eq)
        return fail(ld, CF_ERR_SCENE_OVERRIDE,
                    "bad override '%s': expected key.path=value (e.g. solver.dt_rigid=1e-3)", ov);
    TRY(parse_key_path(ld, ov, ov, eq, seg, &n_seg));
    for (v = eq + 1; *v && isspace((unsigned char)*v); v++)
        ;
    if (!*v)
        return fail(ld, CF_ERR_SCENE_OVERRIDE, "bad override '%s': no value after '='", ov);

    /* The value is a Lua expression evaluated in the same sandbox. */
    luaL_buffinit(L, &code);
    luaL_addstring(&code, "return ");
    luaL_addstring(&code, eq + 1);
    luaL_pushresult(&code);
    int rc = luaL_loadbufferx(L, lua_tostring(L, -1), lua_rawlen(L, -1), "=override", "t");
    if (rc == LUA_ERRMEM)
        return memory_failure(ld, "parsing an override");
    if (rc != LUA_OK)
        return fail(ld, CF_ERR_SCENE_OVERRIDE, "bad override '%s': the value does not parse: %s",
                    ov, lua_type(L, -1) == LUA_TSTRING ? lua_tostring(L, -1) : "?");
    rc = lua_pcall(L, 0, 1, 0);
    if (rc == LUA_ERRMEM)
        return memory_failure(ld, "evaluating an override");
    if (rc != LUA_OK)
        return fail(ld, CF_ERR_SCENE_OVERRIDE, "bad override '%s': the value fails: %s", ov,
                    lua_type(L, -1) == LUA_TSTRING ? lua_tostring(L, -1) : "?");
    if (lua_isnil(L, -1))
        return fail(ld, CF_ERR_SCENE_OVERRIDE,
                    "bad override '%s': the value is nil (strings need quotes: "
                    "name=\"drop\")",
                    ov);
    value = lua_gettop(L);

    /* Walk down, creating missing tables on the way. */
    cur = scene;
    for (int i = 0; i + 1 < n_seg; i++) {
        push_segment(L, &seg[i]);
        ty = lua_rawget(L, cur);
        if (ty == LUA_TNIL) {
            lua_pop(L, 1);
            lua_newtable(L);
            push_segment(L, &seg[i]);
            lua_pushvalue(L, -2);
            lua_rawset(L, cur);
        } else if (ty != LUA_TTABLE) {
            return fail(ld, CF_ERR_SCENE_OVERRIDE,
                        "bad override '%s': part %d of the key path is a %s, not a table", ov,
                        i + 1, lua_typename(L, ty));
        }
        cur = lua_gettop(L);
    }
    push_segment(L, &seg[n_seg - 1]);
    lua_pushvalue(L, value);
    lua_rawset(L, cur);
    lua_settop(L, base);
    return CF_OK;
}

/* The protected part: overrides, then the schema walk.  Arguments: the
 * loader (light userdata) and the scene table. */
static int build_protected(lua_State *L)
{
    loader *ld = lua_touserdata(L, 1);
    cf_status st = CF_OK;
    luaL_checkstack(L, 40, "scene nesting");
    for (int i = 0; i < ld->n_overrides && st == CF_OK; i++)
        st = apply_override(ld, 2, ld->overrides[i]);
    lua_settop(L, 2);
    if (st == CF_OK)
        st = read_scene(ld, 2);
    ld->status = st;
    return 0;
}

/* ---------------------------------------------------------------- sandbox */

static int open_sandbox(lua_State *L)
{
    static const luaL_Reg libs[] = {{LUA_GNAME, luaopen_base},
                                    {LUA_STRLIBNAME, luaopen_string},
                                    {LUA_TABLIBNAME, luaopen_table},
                                    {LUA_MATHLIBNAME, luaopen_math}};
    /* Base functions that reach files, compile code or tune the collector. */
    static const char *const removed[] = {"dofile", "loadfile", "load", "require",
                                          "collectgarbage"};
    for (int i = 0; i < COUNT(libs); i++) {
        luaL_requiref(L, libs[i].name, libs[i].func, 1);
        lua_pop(L, 1);
    }
    for (int i = 0; i < COUNT(removed); i++) {
        lua_pushnil(L);
        lua_setglobal(L, removed[i]);
    }
    return 0;
}

/* Lua's message, prefixed with the scene file unless it already names it. */
static cf_status lua_failure(loader *ld, cf_status code, const char *hint)
{
    lua_State *L = ld->L;
    const char *msg = lua_type(L, -1) == LUA_TSTRING ? lua_tostring(L, -1) : NULL;
    char buf[768];
    if (!msg) {
        snprintf(buf, sizeof buf, "(error object is a %s value)", luaL_typename(L, -1));
        msg = buf;
    }
    if (!hint)
        hint = "";
    if (strncmp(msg, ld->file, strlen(ld->file)) == 0)
        return cf_error_set(ld->err, code, "%s%s", msg, hint);
    return cf_error_set(ld->err, code, "%s: %s%s", ld->file, msg, hint);
}

/* ---------------------------------------------------------------- resolved text */

typedef struct text {
    char *p;
    size_t len, cap;
    int oom;
} text;

static void put(text *b, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

static void put(text *b, const char *fmt, ...)
{
    va_list ap;
    int n;
    if (b->oom)
        return;
    va_start(ap, fmt);
    n = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    if (n < 0) {
        b->oom = 1;
        return;
    }
    if (b->len + (size_t)n + 1 > b->cap) {
        size_t cap = b->cap ? b->cap : 1024;
        char *p;
        while (cap < b->len + (size_t)n + 1)
            cap *= 2;
        p = realloc(b->p, cap);
        if (!p) {
            b->oom = 1;
            return;
        }
        b->p = p;
        b->cap = cap;
    }
    va_start(ap, fmt);
    vsnprintf(b->p + b->len, b->cap - b->len, fmt, ap);
    va_end(ap);
    b->len += (size_t)n;
}

/* %.17g reads back to the same double; ".0" keeps integral values floats
 * (and -0.0 negative) when Lua reads them back. */
static const char *num(char buf[40], double v)
{
    snprintf(buf, 40, "%.17g", v);
    /* Whatever the locale's decimal point, Lua wants '.'. */
    for (char *c = buf; *c; c++)
        if (!isdigit((unsigned char)*c) && *c != '-' && *c != '+' && *c != 'e')
            *c = '.';
    if (!strpbrk(buf, ".e"))
        strcat(buf, ".0");
    return buf;
}

static void put_num(text *b, int ind, const char *key, double v)
{
    char n[40];
    put(b, "%*s%s = %s,\n", ind, "", key, num(n, v));
}

static void put_vec(text *b, int ind, const char *key, const double *v, int n)
{
    char s[40];
    put(b, "%*s%s = {", ind, "", key);
    for (int i = 0; i < n; i++)
        put(b, "%s%s", i ? ", " : "", num(s, v[i]));
    put(b, "},\n");
}

static void put_str(text *b, int ind, const char *key, const char *s)
{
    put(b, "%*s%s = \"", ind, "", key);
    for (const unsigned char *c = (const unsigned char *)s; *c; c++) {
        if (*c == '"' || *c == '\\')
            put(b, "\\%c", *c);
        else if (*c == '\n')
            put(b, "\\n");
        else if (*c < 0x20 || *c == 0x7f)
            put(b, "\\%03d", *c); /* three digits: a following digit cannot join */
        else
            put(b, "%c", *c);
    }
    put(b, "\",\n");
}

static void put_primitive(text *b, int ind, const cf_primitive *p)
{
    put(b, "%*smesh = {\n", ind, "");
    put_str(b, ind + 2, "type", primitive_names[p->type - 1]);
    switch (p->type) {
    case CF_PRIM_BOX:
        put_vec(b, ind + 2, "size", p->size, 3);
        put(b, "%*scells = {%d, %d, %d},\n", ind + 2, "", p->cells[0], p->cells[1], p->cells[2]);
        put(b, "%*stets_per_cell = %d,\n", ind + 2, "", p->tets_per_cell);
        break;
    case CF_PRIM_SPHERE:
        put_num(b, ind + 2, "radius", p->radius);
        put_num(b, ind + 2, "mesh_size", p->mesh_size);
        break;
    case CF_PRIM_HOLLOW_SPHERE:
        put_num(b, ind + 2, "radius", p->radius);
        put_num(b, ind + 2, "thickness", p->thickness);
        put_num(b, ind + 2, "mesh_size", p->mesh_size);
        break;
    case CF_PRIM_PLATE:
        put_vec(b, ind + 2, "size", p->size, 3);
        put_num(b, ind + 2, "mesh_size", p->mesh_size);
        break;
    case CF_PRIM_NOTCHED_BEAM:
        put_vec(b, ind + 2, "size", p->size, 3);
        put_vec(b, ind + 2, "notch", p->notch, 3);
        put_num(b, ind + 2, "mesh_size", p->mesh_size);
        break;
    case CF_PRIM_NONE:
        break;
    }
    put(b, "%*s},\n", ind, "");
}

static void put_boundary(text *b, const cf_boundary *d)
{
    static const char xyz[] = "xyz";
    char axes[4];
    int n = 0;
    put(b, "    {\n      region = {\n");
    put_str(b, 8, "type", region_names[d->type]);
    switch (d->type) {
    case CF_REGION_BOX:
        put_vec(b, 8, "min", d->min, 3);
        put_vec(b, 8, "max", d->max, 3);
        break;
    case CF_REGION_PLANE:
        put_vec(b, 8, "point", d->point, 3);
        put_vec(b, 8, "normal", d->normal, 3);
        put_num(b, 8, "tolerance", d->tolerance);
        break;
    case CF_REGION_GROUP:
        put_str(b, 8, "name", d->group);
        break;
    }
    put(b, "      },\n");
    /* fixed = true reads back as velocity +0.0 exactly; anything else,
     * -0.0 included, is written as it is. */
    if (memcmp(d->velocity, ZERO3, sizeof ZERO3) == 0)
        put(b, "      fixed = true,\n");
    else
        put_vec(b, 6, "velocity", d->velocity, 3);
    for (int k = 0; k < 3; k++)
        if (d->axes & (1 << k))
            axes[n++] = xyz[k];
    axes[n] = '\0';
    put_str(b, 6, "axes", axes);
    if (d->body >= 0)
        put(b, "      body = %d,\n", d->body + 1);
    else
        put(b, "      -- body: every body\n");
    put(b, "    },\n");
}

/* The settings of schema table `table` in d, as read_settings reads them. */
static void put_settings(text *b, int ind, const cf_world_def *d, const char *table)
{
    int n;
    const cf_setting *e = cf_settings(&n);
    for (int i = 0; i < n; i++) {
        const cf_setting *x = &e[i];
        if (strcmp(x->table, table) != 0)
            continue;
        double v = cf_setting_get(x, d);
        const cf_solver_settings *sv = &d->solver;
        char sub[64];
        switch (x->kind) {
        case CF_SET_NUM: put_num(b, ind, x->key, v); break;
        case CF_SET_INT: put(b, "%*s%s = %d,\n", ind, "", x->key, (int)v); break;
        case CF_SET_BOOL: put(b, "%*s%s = %s,\n", ind, "", x->key, v ? "true" : "false"); break;
        case CF_SET_ENUM: put_str(b, ind, x->key, x->names[(int)v]); break;
        case CF_SET_TABLE:
            snprintf(sub, sizeof sub, "%s.%s", table, x->key);
            put(b, "%*s%s = {\n", ind, "", x->key);
            put_settings(b, ind + 2, d, sub);
            put(b, "%*s},\n", ind, "");
            break;
        case CF_SET_CUSTOM: /* solver.crack_plane */
            if (!sv->has_crack_plane) {
                put(b, "%*s-- %s: none\n", ind, "", x->key);
                break;
            }
            put(b, "%*s%s = {\n", ind, "", x->key);
            put_vec(b, ind + 2, "point", sv->crack_plane_point, 3);
            put_vec(b, ind + 2, "normal", sv->crack_plane_normal, 3);
            put_num(b, ind + 2, "tolerance", sv->crack_plane_tolerance);
            put(b, "%*s},\n", ind, "");
            break;
        }
    }
}

/* The whole scene as Lua text in schema order; NULL when out of memory. */
static char *resolved_text(const cf_scene *sc)
{
    const cf_world_def *s = &sc->world;
    text b = {0};
    put(&b, "return {\n");
    put_str(&b, 2, "name", sc->name);
    put_num(&b, 2, "duration", sc->duration);
    put_vec(&b, 2, "gravity", s->gravity, 3);
    put(&b, "  material = {\n");
    put_settings(&b, 4, s, "material");
    put(&b, "  },\n  bodies = {\n");
    for (int i = 0; i < s->n_bodies; i++) {
        const cf_body_def *d = &s->bodies[i];
        const cf_body_source *src = &sc->sources[i];
        put(&b, "    {\n");
        if (src->primitive.type != CF_PRIM_NONE)
            put_primitive(&b, 6, &src->primitive);
        else
            put_str(&b, 6, "mesh", src->mesh);
        put_num(&b, 6, "scale", d->scale);
        put_vec(&b, 6, "position", d->position, 3);
        put_vec(&b, 6, "orientation", d->orientation, 4);
        put_vec(&b, 6, "velocity", d->velocity, 3);
        put_vec(&b, 6, "angular_velocity", d->angular_velocity, 3);
        put_vec(&b, 6, "expansion_rate", d->expansion_rate, 3);
        if (d->has_expansion_center)
            put_vec(&b, 6, "expansion_center", d->expansion_center, 3);
        else
            put(&b, "      -- expansion_center: the body's centre of mass\n");
        put(&b, "      hollow_layers = %d,\n", src->hollow_layers);
        if (src->visual[0])
            put_str(&b, 6, "visual", src->visual);
        put(&b, "    },\n");
    }
    put(&b, "  },\n  boundary = {\n");
    for (int i = 0; i < s->n_boundaries; i++)
        put_boundary(&b, &s->boundaries[i]);
    put(&b, "  },\n  obstacles = {\n");
    for (int i = 0; i < s->n_obstacles; i++) {
        const cf_obstacle *o = &s->obstacles[i];
        put(&b, "    {\n");
        put_str(&b, 6, "type", obstacle_names[o->type]);
        switch (o->type) {
        case CF_OBSTACLE_PLANE:
            put_vec(&b, 6, "point", o->point, 3);
            put_vec(&b, 6, "normal", o->normal, 3);
            break;
        case CF_OBSTACLE_SPHERE:
        case CF_OBSTACLE_BOX:
            put_vec(&b, 6, "center", o->center, 3);
            if (o->type == CF_OBSTACLE_SPHERE)
                put_num(&b, 6, "radius", o->radius);
            else
                put_vec(&b, 6, "half_extents", o->half_extents, 3);
            put_vec(&b, 6, "velocity", o->velocity, 3);
            break;
        case CF_OBSTACLE_MESH:
            put_str(&b, 6, "file", o->file);
            put_num(&b, 6, "scale", o->scale);
            put_vec(&b, 6, "orientation", o->orientation, 4);
            put_vec(&b, 6, "position", o->position, 3);
            break;
        }
        put_num(&b, 6, "friction", o->friction);
        put_num(&b, 6, "restitution", o->restitution);
        put(&b, "    },\n");
    }
    put(&b, "  },\n  solver = {\n");
    put_settings(&b, 4, s, "solver");
    put(&b, "  },\n  output = {\n");
    put_str(&b, 4, "file", sc->output.file);
    put_num(&b, 4, "frame_interval", sc->output.frame_interval);
    put(&b, "    cracks = %s,\n", sc->output.cracks ? "true" : "false");
    put(&b, "    fields = %s,\n", sc->output.fields ? "true" : "false");
    put(&b, "  },\n}\n");
    if (b.oom) {
        free(b.p);
        return NULL;
    }
    return b.p;
}

/* ---------------------------------------------------------------- API */

static void *budget_alloc(void *ud, void *ptr, size_t osize, size_t nsize)
{
    script_budget *b = ud;
    size_t old = ptr ? osize : 0;
    if (nsize == 0) {
        b->bytes -= old;
        free(ptr);
        return NULL;
    }
    if (nsize > old && b->bytes + (nsize - old) > (size_t)SCENE_MAX_BYTES) {
        b->refused_by_limit = 1;
        return NULL; /* Lua raises "not enough memory" */
    }
    void *p = realloc(ptr, nsize);
    if (p)
        b->bytes = b->bytes - old + nsize;
    else
        b->refused_by_limit = 0;
    return p;
}

static void budget_hook(lua_State *L, lua_Debug *ar)
{
    (void)ar;
    void *ud;
    lua_getallocf(L, &ud);
    script_budget *b = ud;
    b->instructions += SCENE_HOOK_EVERY;
    if (b->instructions > SCENE_MAX_INSTRUCTIONS)
        luaL_error(L, "the script ran more than %d million Lua instructions (an endless "
                      "loop?): a scene only builds a table",
                   (int)(SCENE_MAX_INSTRUCTIONS / 1000000));
}

/* The script's chunk (or the error message) and the load's status.
 * luaL_loadfilex pushes the chunk's name and its error messages outside
 * the parser's protection: run unprotected, a memory error there would end
 * in Lua's panic handler, which aborts. */
static int load_protected(lua_State *L)
{
    loader *ld = lua_touserdata(L, 1);
    int rc = ld->text ? luaL_loadbufferx(L, ld->text, strlen(ld->text), ld->file, "t")
                      : luaL_loadfilex(L, ld->file, "t");
    lua_pushinteger(L, rc);
    return 2;
}

static cf_status load(loader *ld)
{
    lua_State *L = ld->L;
    int rc;
    if (!ld->text) {
        FILE *f = fopen(ld->file, "r");
        if (!f)
            return fail(ld, cf_status_of_errno(errno, CF_ERR_FILE_OPEN),
                        "cannot open the scene file: %s", strerror(errno));
        fclose(f);
    }

    lua_pushcfunction(L, open_sandbox);
    if (lua_pcall(L, 0, 0, 0) != LUA_OK)
        return fail(ld, CF_ERR_NOMEM, "out of memory setting up the Lua state");

    /* Mode "t": precompiled chunks bypass the parser's checks and can crash
     * the VM, so only source text is accepted. */
    lua_pushcfunction(L, load_protected);
    lua_pushlightuserdata(L, ld);
    errno = 0;
    rc = lua_pcall(L, 1, 2, 0);
    if (rc == LUA_ERRMEM)
        return memory_failure(ld, "loading the script");
    if (rc != LUA_OK)
        return lua_failure(ld, CF_ERR_SCENE_SYNTAX, NULL);
    rc = (int)lua_tointeger(L, -1);
    lua_pop(L, 1);
    if (rc == LUA_ERRFILE && errno == ENOMEM) /* its fopen could not allocate */
        return fail(ld, CF_ERR_NOMEM, "out of memory opening the scene file");
    if (rc == LUA_ERRFILE)
        return lua_failure(ld, CF_ERR_FILE_OPEN, NULL);
    if (rc == LUA_ERRMEM)
        return memory_failure(ld, "while parsing");
    if (rc != LUA_OK)
        return lua_failure(ld, CF_ERR_SCENE_SYNTAX,
                           lua_type(L, -1) == LUA_TSTRING &&
                                   strstr(lua_tostring(L, -1), "binary chunk")
                               ? " (scenes must be Lua source text)"
                               : NULL);
    rc = lua_pcall(L, 0, 1, 0);
    if (rc == LUA_ERRMEM)
        return memory_failure(ld, "running the script");
    if (rc != LUA_OK) {
        const char *msg = lua_tostring(L, -1);
        return lua_failure(ld, CF_ERR_SCENE_SYNTAX,
                           msg && strstr(msg, "(global '")
                               ? " (scenes run sandboxed: only the base, string, table and "
                                 "math libraries are available)"
                               : NULL);
    }
    if (!lua_istable(L, -1))
        return fail(ld, CF_ERR_SCENE_TYPE, "the script must return a table, got %s",
                    luaL_typename(L, -1));

    lua_pushcfunction(L, build_protected);
    lua_pushlightuserdata(L, ld);
    lua_pushvalue(L, -3);
    rc = lua_pcall(L, 2, 0, 0);
    if (rc == LUA_ERRMEM)
        return memory_failure(ld, "while reading the scene");
    if (rc != LUA_OK)
        return lua_failure(ld, CF_ERR_SCENE_SYNTAX, NULL);
    if (ld->status != CF_OK)
        return ld->status;

    ld->sc->resolved = resolved_text(ld->sc);
    if (!ld->sc->resolved)
        return fail(ld, CF_ERR_NOMEM, "out of memory for the resolved scene");
    return CF_OK;
}

/* The loader behind cf_scene_load and cf_scene_load_text: `text` NULL
 * reads the file `path`, otherwise `path` only names the text in messages. */
static cf_status load_scene(const char *path, const char *text, const char *const *overrides,
                            int n_overrides, const char *mesh_dir, cf_scene *out, cf_error *err)
{
    loader ld;
    const char *slash;
    cf_status st;

    assert(path && out && (n_overrides == 0 || overrides));
    memset(out, 0, sizeof *out);
    memset(&ld, 0, sizeof ld);
    ld.file = path;
    ld.text = text;
    ld.mesh_dir = mesh_dir;
    ld.overrides = overrides;
    ld.n_overrides = n_overrides;
    ld.sc = out;
    ld.s = &out->world;
    ld.err = err;

    slash = text ? NULL : strrchr(path, '/');
    if (!slash)
        snprintf(ld.dir, sizeof ld.dir, ".");
    else if (slash == path)
        snprintf(ld.dir, sizeof ld.dir, "/");
    else if ((size_t)(slash - path) < sizeof ld.dir)
        snprintf(ld.dir, sizeof ld.dir, "%.*s", (int)(slash - path), path);
    else
        return fail(&ld, CF_ERR_FILE_OPEN, "scene path too long");

    script_budget budget = {0, 0, 0};
    ld.L = lua_newstate(budget_alloc, &budget);
    if (!ld.L)
        return fail(&ld, CF_ERR_NOMEM, "out of memory creating a Lua state");
    lua_sethook(ld.L, budget_hook, LUA_MASKCOUNT, SCENE_HOOK_EVERY);
    st = load(&ld);
    lua_close(ld.L);
    if (st != CF_OK)
        cf_scene_free(out);
    return st;
}

cf_status cf_scene_load(const char *path, const char *const *overrides, int n_overrides,
                        const char *mesh_dir, cf_scene *out, cf_error *err)
{
    return load_scene(path, NULL, overrides, n_overrides, mesh_dir, out, err);
}

cf_status cf_scene_load_text(const char *name, const char *text, const char *const *overrides,
                             int n_overrides, const char *mesh_dir, cf_scene *out, cf_error *err)
{
    assert(text);
    return load_scene(name, text, overrides, n_overrides, mesh_dir, out, err);
}

void cf_scene_free(cf_scene *s)
{
    if (!s)
        return;
    free(s->world.bodies);
    free(s->sources);
    free(s->world.obstacles);
    free(s->world.boundaries);
    free(s->resolved);
    memset(s, 0, sizeof *s);
}

cf_output_settings cf_default_output(void)
{
    cf_output_settings o;
    memset(&o, 0, sizeof o);
    o.frame_interval = 0.01;
    o.fields = 1;
    return o;
}

cf_scene cf_default_scene(void)
{
    cf_scene s;
    memset(&s, 0, sizeof s);
    snprintf(s.name, sizeof s.name, "scene");
    s.duration = 1.0;
    s.world = cf_default_world_def();
    s.output = cf_default_output();
    return s;
}

cf_status cf_scene_check(const cf_scene *s, cf_error *err)
{
    if (!(s->duration > 0))
        return cf_error_set(err, CF_ERR_SCENE_VALUE, "'duration' must be > 0, got %.17g",
                            s->duration);
    if (s->world.solver.dt_rigid > s->duration)
        return cf_error_set(err, CF_ERR_SCENE_VALUE,
                            "'solver.dt_rigid' (%g s) exceeds 'duration' (%g s): the run is "
                            "whole rigid steps; lower solver.dt_rigid to at most the duration",
                            s->world.solver.dt_rigid, s->duration);
    if (!(s->output.frame_interval > 0))
        return cf_error_set(err, CF_ERR_SCENE_VALUE,
                            "'output.frame_interval' must be > 0, got %.17g",
                            s->output.frame_interval);
    return CF_OK;
}
