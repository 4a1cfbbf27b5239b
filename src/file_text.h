/* Reading files whole: inputs (meshes, surfaces) and the logs of the
 * external meshers. */
#ifndef COHFRAC_FILE_TEXT_H
#define COHFRAC_FILE_TEXT_H

#include <stddef.h>

/* The whole file at `path` in a NUL-terminated buffer the caller frees;
 * its length (without the NUL) into *len when len is not NULL.  NULL on
 * failure with errno set (ENOENT..., ENOMEM, EIO). */
char *cf_file_read(const char *path, size_t *len);

/* The last lines of a log file (at most max - 1 bytes, from a line start)
 * into out, for error messages; "" when it cannot be read. */
void cf_file_log_tail(const char *path, char *out, size_t max);

#endif
