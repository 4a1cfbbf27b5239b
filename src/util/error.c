#include "cohfrac/error.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>

static const char *const names[] = {
#define CF_X_NAME(name, code, text) #name,
    CF_ERROR_LIST(CF_X_NAME)
#undef CF_X_NAME
};
static const char *const meanings[] = {
#define CF_X_TEXT(name, code, text) text,
    CF_ERROR_LIST(CF_X_TEXT)
#undef CF_X_TEXT
};
static const int exit_codes[] = {
#define CF_X_CODE(name, code, text) code,
    CF_ERROR_LIST(CF_X_CODE)
#undef CF_X_CODE
};

const char *cf_status_name(cf_status s)
{
    return (s >= 0 && s < CF_STATUS_COUNT) ? names[s] : "CF_ERR_UNKNOWN";
}

const char *cf_status_meaning(cf_status s)
{
    return (s >= 0 && s < CF_STATUS_COUNT) ? meanings[s] : "unknown error";
}

int cf_status_exit_code(cf_status s)
{
    return (s >= 0 && s < CF_STATUS_COUNT) ? exit_codes[s] : 5;
}

cf_status cf_error_set(cf_error *err, cf_status code, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        err->code = code;
        va_start(ap, fmt);
        vsnprintf(err->msg, sizeof err->msg, fmt, ap);
        va_end(ap);
    }
    return code;
}

cf_status cf_status_of_errno(int e, cf_status otherwise)
{
    return e == ENOMEM ? CF_ERR_NOMEM : otherwise;
}
