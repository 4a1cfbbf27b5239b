/* Report files for the studies (see report.h). */
#include "report.h"

#include "file_text.h"
#include "process.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/utsname.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

cf_status cf_out_open(cf_outfile *o, const char *dir, const char *name, cf_error *err)
{
    snprintf(o->final, sizeof o->final, "%s/%s", dir, name);
    snprintf(o->tmp, sizeof o->tmp, "%s/%s.%ld.tmp", dir, name, (long)getpid());
    o->f = fopen(o->tmp, "w");
    if (!o->f)
        return cf_error_set(err, cf_status_of_errno(errno, CF_ERR_OUTPUT),
                            "cannot write %s: %s", o->tmp, strerror(errno));
    return CF_OK;
}

/* Close and move into place: the final name only ever holds a whole file. */
cf_status cf_out_close(cf_outfile *o, cf_error *err)
{
    int bad = ferror(o->f);
    bad |= fclose(o->f) != 0;
    o->f = NULL;
    if (bad || rename(o->tmp, o->final) != 0) {
        int e = errno;
        remove(o->tmp);
        return cf_error_set(err, CF_ERR_OUTPUT, "cannot write %s: %s", o->final, strerror(e));
    }
    return CF_OK;
}

/* The Python helpers the program runs, modules of the Python package
 * cohfrac, where the build put them: the source tree's python/cohfrac
 * (build tree), and the install's site directory relative to the
 * executable's bin/ (CMakeLists.txt sets both). */
#ifndef COHFRAC_TOOLS_DIR
#define COHFRAC_TOOLS_DIR "python/cohfrac"
#endif
#ifndef COHFRAC_INSTALLED_PYTHON
#define COHFRAC_INSTALLED_PYTHON "../lib/python3/dist-packages/cohfrac"
#endif

/* The script: the given path; else in the installed package beside the
 * executable; else the source tree's python/cohfrac the program was
 * built from; so it is found from any working directory. */
static int find_script(const char *script, const char *given, char *out, size_t n)
{
    if (given) {
        snprintf(out, n, "%s", given);
        return access(out, R_OK) == 0;
    }
    char exe[900];
    ssize_t len = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (len > 0) {
        exe[len] = 0;
        char *slash = strrchr(exe, '/');
        if (slash)
            *slash = 0;
        snprintf(out, n, "%s/%s/%s", exe, COHFRAC_INSTALLED_PYTHON, script);
        if (access(out, R_OK) == 0)
            return 1;
    }
    snprintf(out, n, "%s/%s", COHFRAC_TOOLS_DIR, script);
    return access(out, R_OK) == 0;
}

int cf_run_helper(const char *script, const char *script_path, const char *const *args)
{
    char path[1024];
    if (!find_script(script, script_path, path, sizeof path)) {
        fprintf(stderr, "cohfrac: warning: %s not found (looked beside the program in %s and "
                        "in %s)\n",
                script, COHFRAC_INSTALLED_PYTHON, COHFRAC_TOOLS_DIR);
        return -1;
    }
    const char *py = access("/usr/bin/python3", X_OK) == 0 ? "/usr/bin/python3" : "python3";
    char *argv[24];
    int n = 0;
    argv[n++] = (char *)py;
    argv[n++] = path;
    for (int i = 0; args[i] && n < 23; i++)
        argv[n++] = (char *)args[i];
    argv[n] = NULL;
    pid_t pid;
    int rc = cf_spawn(argv, NULL, &pid);
    int status = 0;
    if (rc == 0 && cf_wait(pid, &status, NULL) < 0)
        rc = errno;
    if (rc != 0) {
        fprintf(stderr, "cohfrac: warning: cannot run python3 (%s): install python3\n",
                strerror(rc));
        return -1;
    }
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

int cf_report_plot(const char *script, const char *script_path, const char *const *args,
                   const char *others)
{
    int status = cf_run_helper(script, script_path, args);
    if (status == 0)
        return 1;
    if (status < 0)
        fprintf(stderr, "cohfrac: warning: no plot; %s are written\n", others);
    else if (status == 3)
        fprintf(stderr, "cohfrac: warning: matplotlib is missing (install the Debian package "
                        "python3-matplotlib): no plot; %s are written\n", others);
    else
        fprintf(stderr, "cohfrac: warning: %s failed (status %d): no plot (needs "
                        "python3-matplotlib); %s are written\n", script, status, others);
    return 0;
}

void cf_report_stamp(char *out, size_t max, char date[32])
{
    time_t now = time(NULL);
    strftime(date, 32, "%Y-%m-%d", gmtime(&now));
    char cpu[256] = "unknown CPU", deb[64] = "?";
    char *info = cf_file_read("/proc/cpuinfo", NULL);
    const char *m = info ? strstr(info, "model name") : NULL;
    if (m && (m = strchr(m, ':')))
        sscanf(m + 1, " %255[^\n]", cpu);
    free(info);
    char *d = cf_file_read("/etc/debian_version", NULL);
    if (d)
        sscanf(d, "%63s", deb);
    free(d);
    struct utsname u;
    if (uname(&u) != 0)
        snprintf(u.release, sizeof u.release, "?");
    snprintf(out, max, "%s, %ld cores, Linux %s, Debian %s", cpu, sysconf(_SC_NPROCESSORS_ONLN),
             u.release, deb);
}
