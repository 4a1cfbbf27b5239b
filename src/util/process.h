/* Running external programs: tetgen, gmsh, python3 for the plots, and the
 * `cohfrac run` processes of a study. */
#ifndef COHFRAC_PROCESS_H
#define COHFRAC_PROCESS_H

#include <sys/resource.h>
#include <sys/types.h>

/* Start argv[0] (looked up in PATH unless it holds a '/').  With `log` not
 * NULL its stdin is /dev/null and its stdout and stderr go to `log`
 * (truncated); with NULL it inherits all three.  Returns 0 and the child's
 * pid in *pid, or posix_spawn's error number. */
int cf_spawn(char *const argv[], const char *log, pid_t *pid);

/* Wait for child `pid` (-1: any child), again when a signal interrupts the
 * wait; its wait status into *status and, when `ru` is not NULL, its
 * resource usage (wait4).  Returns the child's pid, or -1 with errno set. */
pid_t cf_wait(pid_t pid, int *status, struct rusage *ru);

#endif
