#include "file_text.h"

#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>

char *cf_file_read(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    size_t cap = 1 << 16, n = 0;
    char *buf = malloc(cap);
    while (buf) {
        if (n + 1 >= cap) {
            char *nb = cap <= SIZE_MAX / 2 ? realloc(buf, cap * 2) : NULL;
            if (!nb) {
                free(buf);
                buf = NULL;
                errno = ENOMEM;
                break;
            }
            buf = nb, cap *= 2;
        }
        size_t got = fread(buf + n, 1, cap - n - 1, f);
        n += got;
        if (got == 0)
            break;
    }
    if (buf && ferror(f)) {
        free(buf);
        buf = NULL;
        errno = EIO;
    }
    fclose(f);
    if (buf) {
        buf[n] = '\0';
        if (len)
            *len = n;
    }
    return buf;
}

void cf_file_log_tail(const char *path, char *out, size_t max)
{
    out[0] = '\0';
    FILE *f = fopen(path, "rb");
    if (!f)
        return;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    long from = n > (long)max - 1 ? n - (long)max + 1 : 0;
    fseek(f, from, SEEK_SET);
    size_t got = fread(out, 1, max - 1, f);
    out[got] = '\0';
    fclose(f);
    char *nl = from > 0 ? strchr(out, '\n') : NULL;
    if (nl)
        memmove(out, nl + 1, strlen(nl + 1) + 1);
}

cf_status cf_mkdirs(const char *path, const char *what, cf_error *err)
{
    char d[4096];
    if (snprintf(d, sizeof d, "%s", path) >= (int)sizeof d)
        return cf_error_set(err, CF_ERR_OUTPUT, "%s name too long: %s", what, path);
    for (char *p = d + 1;; p++) {
        if (*p == '/' || *p == '\0') {
            char c = *p;
            *p = '\0';
            struct stat sb;
            if (mkdir(d, 0777) != 0 && errno != EEXIST)
                return cf_error_set(err, CF_ERR_OUTPUT, "cannot create %s %s (%s)", what, d,
                                    strerror(errno));
            if (stat(d, &sb) != 0 || !S_ISDIR(sb.st_mode))
                return cf_error_set(err, CF_ERR_OUTPUT,
                                    "%s is not a directory; give another %s", d, what);
            *p = c;
            if (!c)
                break;
        }
    }
    return CF_OK;
}
