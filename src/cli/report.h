/* Report files for the studies (`compare`, `stability`; their directories
 * come from cf_mkdirs in file_text.h): whole-or-nothing text files, and the matplotlib
 * plots made by the helpers of the Python package (python/cohfrac) with Debian's
 * python3. */
#ifndef COHFRAC_REPORT_H
#define COHFRAC_REPORT_H

#include <stddef.h>
#include <stdio.h>

#include "cohfrac/error.h"

/* A text file written to DIR/NAME.tmp and renamed to DIR/NAME on close, so
 * the final name only ever holds a whole file. */
typedef struct cf_outfile {
    FILE *f;
    char tmp[1100], final[1100];
} cf_outfile;

/* Errors: CF_ERR_OUTPUT. */
cf_status cf_out_open(cf_outfile *o, const char *dir, const char *name, cf_error *err);
cf_status cf_out_close(cf_outfile *o, cf_error *err);

/* Run the package's <script> (or `script_path` when not NULL; else the
 * installed package found from the executable's bin/, then the source
 * tree's python/cohfrac) with /usr/bin/python3 and the NULL-ended
 * `args`.  Returns the script's exit status, or -1 (with a warning on
 * stderr) when it was not found, could not start or was killed. */
int cf_run_helper(const char *script, const char *script_path, const char *const *args);

/* cf_run_helper for a plot: returns 1 when it exited with 0; otherwise
 * warns on stderr (exit status 3 from the script means matplotlib is
 * missing) that only `others` were written, and returns 0. */
int cf_report_plot(const char *script, const char *script_path, const char *const *args,
                   const char *others);

/* For a report's header: "CPU model, N cores, Linux release, Debian
 * version" into out (at most max bytes), and today's date (UTC,
 * YYYY-MM-DD) into date. */
void cf_report_stamp(char *out, size_t max, char date[32]);

#endif
