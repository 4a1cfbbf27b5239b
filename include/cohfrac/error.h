/* cohfrac — error codes and the error record every fallible call fills.
 *
 * Every error has a named code from the one X-macro list below, a process
 * exit code, and a short meaning.  Functions that can fail return a
 * cf_status and, when given a non-NULL cf_error*, write a message into it
 * that names the file and line, element or key, says what is wrong and what
 * to do.  Asserts are for programmer errors only.
 *
 * Process exit codes (the `cohfrac` program):
 *   0  success
 *   1  usage error (bad command line)
 *   2  bad input (mesh, surface or scene file)
 *   3  the simulation diverged (NaN, inverted tets, or energy growth with
 *      no work input); the output file is closed and readable up to the
 *      last frame
 *   4  output could not be written
 *   5  a required external program or resource failed (tetgen, gmsh, memory)
 *   130, 143  interrupted by SIGINT, SIGTERM (128 + the signal): the current
 *      frame was finished and the output file closed, readable
 */
#ifndef COHFRAC_ERROR_H
#define COHFRAC_ERROR_H

#include <stddef.h>

/*  X(name, exit code, meaning) */
#define CF_ERROR_LIST(X)                                                       \
    X(CF_OK, 0, "success")                                                     \
    X(CF_ERR_USAGE, 1, "bad command-line usage")                               \
    X(CF_ERR_FILE_OPEN, 2, "input file missing or unreadable")                 \
    X(CF_ERR_MESH_PARSE, 2, "malformed mesh or surface file")                  \
    X(CF_ERR_MESH_INDEX, 2, "element refers to a node that does not exist")    \
    X(CF_ERR_MESH_INVERTED, 2, "inverted or degenerate tetrahedron")           \
    X(CF_ERR_MESH_FORMAT, 2, "mesh file version or content not supported")     \
    X(CF_ERR_SURFACE_INTERSECT, 2, "surface intersects itself and could not be repaired") \
    X(CF_ERR_SCENE_SYNTAX, 2, "scene script does not parse or fails to run")   \
    X(CF_ERR_SCENE_KEY, 2, "unknown or missing key in scene")                  \
    X(CF_ERR_SCENE_TYPE, 2, "scene value has the wrong type")                  \
    X(CF_ERR_SCENE_VALUE, 2, "scene value out of range")                       \
    X(CF_ERR_SCENE_OVERRIDE, 2, "malformed --set override")                    \
    X(CF_ERR_DIVERGED, 3, "simulation diverged")                               \
    X(CF_ERR_OUTPUT, 4, "output file could not be written")                    \
    X(CF_ERR_EXTERNAL, 5, "external program failed")                           \
    X(CF_ERR_NOMEM, 5, "out of memory")                                      \
    X(CF_ERR_INTERRUPTED, 130, "interrupted by a signal")

typedef enum {
#define CF_X_ENUM(name, code, text) name,
    CF_ERROR_LIST(CF_X_ENUM)
#undef CF_X_ENUM
    CF_STATUS_COUNT
} cf_status;

/* The message buffer of a failed call.  `code` repeats the return value. */
typedef struct cf_error {
    cf_status code;
    char msg[1024];
} cf_error;

/* Name of a status ("CF_ERR_SCENE_KEY"), its meaning, its process exit code. */
const char *cf_status_name(cf_status s);
const char *cf_status_meaning(cf_status s);
int cf_status_exit_code(cf_status s);

/* The status of a call that failed with errno `e`: CF_ERR_NOMEM for ENOMEM
 * (fopen, realpath and the like allocate: out of memory is not a problem
 * with the file), `otherwise` for anything else. */
cf_status cf_status_of_errno(int e, cf_status otherwise);

/* Fill `err` (may be NULL) with code and a printf-style message; returns code. */
cf_status cf_error_set(cf_error *err, cf_status code, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

#endif
