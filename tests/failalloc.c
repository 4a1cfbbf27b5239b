/* An allocator that fails on purpose, for tests/failalloc.sh
 * (docs/reliability.md).  Loaded with LD_PRELOAD in front of glibc, it
 * counts every malloc, calloc, realloc, posix_memalign, aligned_alloc,
 * memalign, valloc and pvalloc made after its constructor ran (the ones the
 * dynamic loader and earlier constructors make cannot fail in a way the
 * program could handle) and makes chosen ones return NULL with errno ENOMEM.
 * Not part of the engine and not installed.
 *
 *   COHFRAC_FAIL_ALLOC_AT=N      call N (1-based) fails ...
 *   COHFRAC_FAIL_ALLOC_COUNT=k   ... and the k-1 after it (default 1), or
 *                                'all': every call from N on
 *   COHFRAC_FAIL_ALLOC_REPORT=F  a report in file F, for a test to tell
 *                                how a run went and whose failure it was:
 *                                at each failed call, F becomes "failed call
 *                                N: KIND of S bytes, from:" and its stack;
 *                                killed by SIGSEGV, SIGBUS, SIGFPE, SIGILL or
 *                                SIGABRT, "signal S after C calls, K failed,
 *                                in:" and the stack where it came follow; at
 *                                exit, "calls T failed K first N kind KIND
 *                                size S".  (F '-': stderr, the last two only.)
 *   COHFRAC_FAIL_ALLOC_BACKTRACE=1  print the stack of the first failed
 *                                call to stderr (to find where it was)
 *   COHFRAC_FAIL_ALLOC_SKIP=S    calls made directly from a loaded object
 *                                whose path contains S (e.g. "libgomp")
 *                                are neither counted nor failed
 *   COHFRAC_FAIL_ALLOC_ONLY=S    only those calls are counted and failed
 *   COHFRAC_FAIL_ALLOC_SITES=F   for a sweep that fails every call site
 *                                once: append to file F "site N" and the
 *                                three callers of each call whose three
 *                                callers (one of them in the program
 *                                itself) were not seen before; N is the
 *                                call's number, to give to _AT (slow: a
 *                                backtrace per call)
 *
 * A request for 0 bytes (malloc(0), realloc(p, 0)) is counted but never
 * failed: glibc never fails it, and realloc(p, 0) frees p.  The failure then
 * moves on to the next request for memory, so "call N fails" means the
 * first request of at least one byte numbered N or later.
 *
 * The real allocator is reached through glibc's own entry points
 * (__libc_malloc ...), not dlsym(RTLD_NEXT), which may itself allocate and
 * so recurse.  The counter is atomic: Bullet, libgomp and HDF5 allocate
 * from several threads.  Nothing here allocates after the constructor. */
#define _GNU_SOURCE
#include <errno.h>
#include <execinfo.h>
#include <fcntl.h>
#include <link.h>
#include <signal.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

extern void *__libc_malloc(size_t size);
extern void *__libc_calloc(size_t n, size_t size);
extern void *__libc_realloc(void *p, size_t size);
extern void *__libc_memalign(size_t align, size_t size);

#define ALL_AFTER ((unsigned long long)-1)

static atomic_int armed;               /* set at the end of the constructor */
static atomic_ullong calls;            /* counted calls so far */
static unsigned long long fail_at;     /* 0: never fail */
static atomic_ullong fails_left;       /* ALL_AFTER: every call from fail_at on */
static atomic_ullong failed;           /* calls made to fail */
static atomic_ullong first_failed;     /* the number of the first failed call */
static size_t first_size;
static const char *first_kind = "none";
static int want_backtrace;
static const char *report_path;
static atomic_flag report_busy = ATOMIC_FLAG_INIT;

static void on_crash(int sig);
static void report_failure(unsigned long long n, const char *kind, size_t size);

/* The address ranges (loaded segments) of the objects named by
 * COHFRAC_FAIL_ALLOC_SKIP or _ONLY, found once by the constructor. */
static struct {
    uintptr_t lo, hi;
} ranges[16];
static int n_ranges;
static int only; /* 1: _ONLY (count calls from the ranges), 0: _SKIP */
static int filtering;

/* _SITES: the program's and this library's own segments, and the stacks
 * seen (a hash of three return addresses; open addressing, no allocation). */
typedef struct {
    uintptr_t lo, hi;
} range;
static range exe[8], self[8];
static int n_exe, n_self;
static int sites_fd = -1;
static uint64_t seen[1 << 16];
static atomic_flag sites_busy = ATOMIC_FLAG_INIT;

static int in(const range *r, int n, const void *p)
{
    for (int i = 0; i < n; i++)
        if ((uintptr_t)p >= r[i].lo && (uintptr_t)p < r[i].hi)
            return 1;
    return 0;
}

static int find_own(struct dl_phdr_info *info, size_t size, void *unused)
{
    (void)size, (void)unused;
    int program = !info->dlpi_name || !*info->dlpi_name;
    int mine = info->dlpi_name && strstr(info->dlpi_name, "failalloc");
    for (int i = 0; i < info->dlpi_phnum; i++) {
        const ElfW(Phdr) *ph = &info->dlpi_phdr[i];
        range r = {info->dlpi_addr + ph->p_vaddr, info->dlpi_addr + ph->p_vaddr + ph->p_memsz};
        if (ph->p_type != PT_LOAD)
            continue;
        if (program && n_exe < 8)
            exe[n_exe++] = r;
        else if (mine && n_self < 8)
            self[n_self++] = r;
    }
    return 0;
}

/* _SITES: note call n when its three callers are new and one of them is
 * the program's. */
static void note_site(unsigned long long n)
{
    void *frames[16];
    int depth = backtrace(frames, 16), k = 0;
    while (k < depth && in(self, n_self, frames[k]))
        k++;
    if (depth - k < 1)
        return;
    int m = depth - k < 3 ? depth - k : 3, ours = 0;
    uint64_t h = 1469598103934665603ULL;
    for (int i = 0; i < m; i++) {
        ours |= in(exe, n_exe, frames[k + i]);
        h = (h ^ (uint64_t)(uintptr_t)frames[k + i]) * 1099511628211ULL;
    }
    if (!ours)
        return;
    h |= 1; /* 0 marks an empty slot */
    while (atomic_flag_test_and_set(&sites_busy))
        ;
    size_t slot = (size_t)(h >> 20) & ((sizeof seen / sizeof seen[0]) - 1);
    int fresh = 0;
    for (size_t probe = 0; probe < sizeof seen / sizeof seen[0]; probe++) {
        size_t j = (slot + probe) & ((sizeof seen / sizeof seen[0]) - 1);
        if (seen[j] == h)
            break;
        if (seen[j] == 0) {
            seen[j] = h;
            fresh = 1;
            break;
        }
    }
    if (fresh) {
        char line[48];
        int len = snprintf(line, sizeof line, "site %llu\n", n);
        if (len > 0 && write(sites_fd, line, (size_t)len) < 0) { /* lost */ }
        backtrace_symbols_fd(frames + k, m, sites_fd);
    }
    atomic_flag_clear(&sites_busy);
}

static int add_ranges(struct dl_phdr_info *info, size_t size, void *name)
{
    (void)size;
    if (!info->dlpi_name || !strstr(info->dlpi_name, (const char *)name))
        return 0;
    for (int i = 0; i < info->dlpi_phnum && n_ranges < 16; i++) {
        const ElfW(Phdr) *ph = &info->dlpi_phdr[i];
        if (ph->p_type != PT_LOAD)
            continue;
        ranges[n_ranges].lo = info->dlpi_addr + ph->p_vaddr;
        ranges[n_ranges].hi = info->dlpi_addr + ph->p_vaddr + ph->p_memsz;
        n_ranges++;
    }
    return 0;
}

/* Whether a call made from `caller` is left alone by the filter. */
static int filtered_out(const void *caller)
{
    if (!filtering)
        return 0;
    uintptr_t a = (uintptr_t)caller;
    int inside = 0;
    for (int i = 0; i < n_ranges; i++)
        inside |= a >= ranges[i].lo && a < ranges[i].hi;
    return only ? !inside : inside;
}

static unsigned long long env_number(const char *name, unsigned long long fallback)
{
    const char *s = getenv(name);
    if (!s || !*s)
        return fallback;
    if (!strcmp(s, "all"))
        return ALL_AFTER;
    char *end;
    unsigned long long v = strtoull(s, &end, 10);
    return *end ? fallback : v;
}

__attribute__((constructor)) static void failalloc_init(void)
{
    fail_at = env_number("COHFRAC_FAIL_ALLOC_AT", 0);
    atomic_store(&fails_left, env_number("COHFRAC_FAIL_ALLOC_COUNT", 1));
    const char *bt = getenv("COHFRAC_FAIL_ALLOC_BACKTRACE");
    want_backtrace = bt && *bt && strcmp(bt, "0");
    const char *skip = getenv("COHFRAC_FAIL_ALLOC_SKIP"), *keep = getenv("COHFRAC_FAIL_ALLOC_ONLY");
    const char *name = keep && *keep ? keep : skip && *skip ? skip : NULL;
    if (name) {
        /* Objects loaded later (dlopen) are not looked for: the program's
         * libraries are all loaded by now. */
        only = name == keep;
        filtering = 1;
        dl_iterate_phdr(add_ranges, (void *)name);
    }
    const char *sites = getenv("COHFRAC_FAIL_ALLOC_SITES");
    if (sites && *sites) {
        dl_iterate_phdr(find_own, NULL);
        sites_fd = open(sites, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    }
    report_path = getenv("COHFRAC_FAIL_ALLOC_REPORT");
    if (report_path && !*report_path)
        report_path = NULL;
    if (want_backtrace || report_path || sites_fd >= 0) {
        /* The first backtrace() loads libgcc_s, which allocates: do it now,
         * before counting, not inside a failing call. */
        void *frames[4];
        backtrace(frames, 4);
    }
    if (report_path) {
        /* Once, and left to the default action after: the signal then
         * ends the process as it would have without us. */
        static const int sigs[] = {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT};
        /* On a stack of its own (the main thread's): a crash may be a
         * stack overflow, an endless recursion in an error path. */
        static char altstack[256 * 1024];
        stack_t ss = {.ss_sp = altstack, .ss_size = sizeof altstack, .ss_flags = 0};
        int alt = sigaltstack(&ss, NULL) == 0;
        struct sigaction sa;
        memset(&sa, 0, sizeof sa);
        sa.sa_handler = on_crash;
        sa.sa_flags = SA_RESETHAND | (alt ? SA_ONSTACK : 0);
        sigemptyset(&sa.sa_mask);
        for (size_t i = 0; i < sizeof sigs / sizeof sigs[0]; i++)
            sigaction(sigs[i], &sa, NULL);
    }
    atomic_store(&armed, 1);
}

/* Whether this call (asking for `size` bytes, made from `caller`) is to
 * fail. */
static int should_fail(const char *kind, size_t size, const void *caller)
{
    if (!atomic_load_explicit(&armed, memory_order_relaxed) || filtered_out(caller))
        return 0;
    unsigned long long n = atomic_fetch_add(&calls, 1) + 1;
    if (sites_fd >= 0)
        note_site(n);
    if (fail_at == 0 || n < fail_at || size == 0)
        return 0;
    unsigned long long left = atomic_load(&fails_left);
    do {
        if (left == 0)
            return 0;
        if (left == ALL_AFTER)
            break;
    } while (!atomic_compare_exchange_weak(&fails_left, &left, left - 1));
    unsigned long long zero = 0;
    if (atomic_compare_exchange_strong(&first_failed, &zero, n)) {
        first_size = size;
        first_kind = kind;
        if (want_backtrace) {
            static const char head[] = "failalloc: the first failed allocation:\n";
            void *frames[64];
            int depth = backtrace(frames, 64);
            if (write(2, head, sizeof head - 1) < 0) { /* nothing to do */ }
            backtrace_symbols_fd(frames, depth, 2);
        }
    }
    report_failure(n, kind, size);
    atomic_fetch_add(&failed, 1);
    errno = ENOMEM;
    return 1;
}

/* Who called the allocator: the object the call came from. */
#define CALLER __builtin_return_address(0)

void *malloc(size_t size)
{
    return should_fail("malloc", size, CALLER) ? NULL : __libc_malloc(size);
}

void *calloc(size_t n, size_t size)
{
    /* n * size may overflow: glibc then fails with ENOMEM itself. */
    size_t bytes = (size && n > (size_t)-1 / size) ? (size_t)-1 : n * size;
    return should_fail("calloc", bytes, CALLER) ? NULL : __libc_calloc(n, size);
}

void *realloc(void *p, size_t size)
{
    /* A failed realloc leaves p as it was, as glibc does. */
    return should_fail("realloc", size, CALLER) ? NULL : __libc_realloc(p, size);
}

void *memalign(size_t align, size_t size)
{
    return should_fail("memalign", size, CALLER) ? NULL : __libc_memalign(align, size);
}

void *aligned_alloc(size_t align, size_t size)
{
    return should_fail("aligned_alloc", size, CALLER) ? NULL : __libc_memalign(align, size);
}

void *valloc(size_t size)
{
    return should_fail("valloc", size, CALLER) ? NULL : __libc_memalign((size_t)sysconf(_SC_PAGESIZE), size);
}

void *pvalloc(size_t size)
{
    size_t page = (size_t)sysconf(_SC_PAGESIZE);
    size_t rounded = size > (size_t)-1 - page ? (size_t)-1 : (size + page - 1) / page * page;
    return should_fail("pvalloc", rounded, CALLER) ? NULL : __libc_memalign(page, rounded);
}

int posix_memalign(void **out, size_t align, size_t size)
{
    if (align < sizeof(void *) || (align & (align - 1)))
        return EINVAL;
    /* posix_memalign reports through its result and leaves errno alone. */
    int saved = errno;
    if (should_fail("posix_memalign", size, CALLER)) {
        errno = saved;
        return ENOMEM;
    }
    void *p = __libc_memalign(align, size);
    if (!p) {
        errno = saved;
        return ENOMEM;
    }
    *out = p;
    return 0;
}

/* The report file, emptied (`flags` O_TRUNC) or added to (O_APPEND); its
 * lines are written with write() and backtrace_symbols_fd, neither of
 * which allocates (backtrace was called once by the constructor). */
static int open_report(int flags)
{
    return strcmp(report_path, "-") ? open(report_path, O_WRONLY | O_CREAT | flags, 0644) : 2;
}

static void say(int fd, const char *text)
{
    if (write(fd, text, strlen(text)) < 0) { /* the test sees no report */ }
}

/* Written at the failure itself, not at exit: a library may end the
 * process with _exit or a signal after it (one thread at a time; another
 * failing meanwhile is left out). */
static void report_failure(unsigned long long n, const char *kind, size_t size)
{
    if (!report_path || !strcmp(report_path, "-") || atomic_flag_test_and_set(&report_busy))
        return;
    int fd = open_report(O_TRUNC);
    if (fd >= 0) {
        char line[128];
        snprintf(line, sizeof line, "failed call %llu: %s of %zu bytes, from:\n", n, kind, size);
        say(fd, line);
        void *frames[24];
        backtrace_symbols_fd(frames, backtrace(frames, 24), fd);
        close(fd);
    }
    atomic_flag_clear(&report_busy);
}

/* The crash: which signal, and where. */
static void on_crash(int sig)
{
    int fd = open_report(O_APPEND);
    if (fd < 0)
        return;
    char line[128];
    snprintf(line, sizeof line, "signal %d after %llu calls, %llu failed, in:\n", sig,
             atomic_load(&calls), atomic_load(&failed));
    say(fd, line);
    void *frames[32];
    backtrace_symbols_fd(frames, backtrace(frames, 32), fd);
    if (fd != 2)
        close(fd);
}

/* The report, written without stdio's buffers (which allocate). */
__attribute__((destructor)) static void failalloc_report(void)
{
    if (!report_path)
        return;
    char line[256];
    int len = snprintf(line, sizeof line, "calls %llu failed %llu first %llu kind %s size %zu\n",
                       atomic_load(&calls), atomic_load(&failed), atomic_load(&first_failed),
                       first_kind, first_size);
    if (len < 0)
        return;
    int fd = open_report(O_APPEND);
    if (fd < 0)
        return;
    say(fd, line);
    if (fd != 2)
        close(fd);
}
