/* Files: reading inputs (meshes, surfaces) and the logs of the external
 * meshers whole; making the directories outputs go to. */
#ifndef COHFRAC_FILE_TEXT_H
#define COHFRAC_FILE_TEXT_H

#include <stddef.h>

#include "cohfrac/error.h"

/* The whole file at `path` in a NUL-terminated buffer the caller frees;
 * its length (without the NUL) into *len when len is not NULL.  NULL on
 * failure with errno set (ENOENT..., ENOMEM, EIO). */
char *cf_file_read(const char *path, size_t *len);

/* The last lines of a log file (at most max - 1 bytes, from a line start)
 * into out, for error messages; "" when it cannot be read. */
void cf_file_log_tail(const char *path, char *out, size_t max);

/* mkdir -p `path`; `what` names it in errors ("mesh cache directory").
 * Errors: CF_ERR_OUTPUT (too long, cannot be created, or something that is
 * not a directory is in the way). */
cf_status cf_mkdirs(const char *path, const char *what, cf_error *err);

#endif
