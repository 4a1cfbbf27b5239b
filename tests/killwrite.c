/* A process that dies in the middle of a write, for tests/sigkill.sh
 * (docs/reliability.md).  Loaded with LD_PRELOAD, it counts the calls to
 * pwrite (HDF5's default file driver writes through it, and
 * nothing else of the run does) and sends the process SIGKILL in place of a
 * chosen one, so the kill falls inside an HDF5 flush, between two of its
 * metadata writes: the moment a timed kill hits only now and then.  Not
 * part of the engine and not installed.
 *
 *   COHFRAC_KILL_AT_WRITE=N     call N (1-based) is not made: SIGKILL
 *   COHFRAC_KILL_WRITE_COUNT=F  at exit, the number of calls made, in F
 */
#define _GNU_SOURCE

#include <dlfcn.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>
#include <unistd.h>

static long kill_at;
static long calls;

__attribute__((constructor)) static void start(void)
{
    const char *at = getenv("COHFRAC_KILL_AT_WRITE");
    kill_at = at ? atol(at) : 0;
}

__attribute__((destructor)) static void report(void)
{
    const char *path = getenv("COHFRAC_KILL_WRITE_COUNT");
    FILE *f = path ? fopen(path, "w") : NULL;
    if (f) {
        fprintf(f, "%ld\n", calls);
        fclose(f);
    }
}

/* Called before each write: the counting and the kill. */
static void before_write(void)
{
    if (__atomic_add_fetch(&calls, 1, __ATOMIC_SEQ_CST) == kill_at)
        raise(SIGKILL);
}

/* HDF5's file driver calls pwrite (Debian's libhdf5 on 64-bit, where
 * off_t is 64 bits, has no pwrite64 to catch). */
ssize_t pwrite(int fd, const void *buf, size_t n, off_t off)
{
    typedef ssize_t (*pwrite_fn)(int, const void *, size_t, off_t);
    static pwrite_fn real;
    if (!real) { /* copied bytewise: ISO C has no cast to a function pointer */
        void *p = dlsym(RTLD_NEXT, "pwrite");
        memcpy(&real, &p, sizeof real);
    }
    before_write();
    return real(fd, buf, n, off);
}
