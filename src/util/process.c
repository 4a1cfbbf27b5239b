/* Running external programs: see process.h. */
#define _GNU_SOURCE
#include "process.h"

#include <errno.h>
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>

extern char **environ;

int cf_spawn(char *const argv[], const char *log, pid_t *pid)
{
    if (!log)
        return posix_spawnp(pid, argv[0], NULL, NULL, argv, environ);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&fa, 1, log, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&fa, 1, 2);
    int rc = posix_spawnp(pid, argv[0], &fa, NULL, argv, environ);
    posix_spawn_file_actions_destroy(&fa);
    return rc;
}

pid_t cf_wait(pid_t pid, int *status, struct rusage *ru)
{
    pid_t got;
    while ((got = wait4(pid, status, 0, ru)) < 0 && errno == EINTR)
        ;
    return got;
}
