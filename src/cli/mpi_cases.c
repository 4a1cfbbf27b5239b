/* cohfrac — independent cases over MPI ranks (mpi_cases.h). */
#include "mpi_cases.h"

#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#ifdef COHFRAC_HAVE_MPI
#include <mpi.h>
#endif

static int g_rank = 0, g_size = 1, g_local = 1;
#ifdef COHFRAC_HAVE_MPI
static int g_started = 0;
#endif

/* The number of ranks the launcher's environment declares (Open MPI,
 * MPICH/Slurm PMI), 0 when none; -1: an MPI launch of unknown size (PMIx). */
static int launch_size(void)
{
    const char *names[] = {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"};
    for (int i = 0; i < 2; i++) {
        const char *v = getenv(names[i]);
        if (v && atoi(v) > 0)
            return atoi(v);
    }
    return getenv("PMIX_RANK") ? -1 : 0;
}

int cf_mpi_start(int *argc, char ***argv, cf_error *err)
{
    int declared = launch_size();
    if (declared == 0 || declared == 1)
        return 1;
#ifdef COHFRAC_HAVE_MPI
    int provided = 0;
    /* Serialized: on rank 0 the coordinator thread makes every MPI call
     * between start and finish, the main thread none. */
    if (MPI_Init_thread(argc, argv, MPI_THREAD_SERIALIZED, &provided) != MPI_SUCCESS ||
        provided < MPI_THREAD_SERIALIZED) {
        cf_error_set(err, CF_ERR_EXTERNAL,
                     "MPI did not start with thread support (MPI_THREAD_SERIALIZED): run "
                     "without mpirun, or with an MPI that provides it");
        return -1;
    }
    g_started = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &g_rank);
    MPI_Comm_size(MPI_COMM_WORLD, &g_size);
    MPI_Comm node;
    MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, g_rank, MPI_INFO_NULL, &node);
    MPI_Comm_size(node, &g_local);
    MPI_Comm_free(&node);
    return g_size;
#else
    (void)argc, (void)argv;
    cf_error_set(err, CF_ERR_USAGE,
                 "started as one of %d MPI ranks, but this cohfrac was built without MPI: "
                 "every rank would run every case.  Install Debian's libopenmpi-dev and "
                 "rebuild (make), or run without mpirun (-j for local jobs)",
                 declared);
    return -1;
#endif
}

int cf_mpi_rank(void) { return g_rank; }
int cf_mpi_size(void) { return g_size; }
int cf_mpi_local_size(void) { return g_local; }

void cf_mpi_finish(void)
{
#ifdef COHFRAC_HAVE_MPI
    if (g_started)
        MPI_Finalize();
    g_started = 0;
#endif
}

/* The shared queue: cases handed out in `order`, results gathered. */
typedef struct queue {
    pthread_mutex_t lock;
    const int *order;
    int n, next, len;
    double *results;
    cf_case_done_fn done;
    void *user;
} queue;

static int take(queue *q)
{
    pthread_mutex_lock(&q->lock);
    int i = q->next < q->n ? q->order[q->next++] : -1;
    pthread_mutex_unlock(&q->lock);
    return i;
}

static void finish(queue *q, int index, const double *result, int rank)
{
    pthread_mutex_lock(&q->lock);
    memcpy(&q->results[(size_t)index * q->len], result, (size_t)q->len * sizeof *result);
    if (q->done)
        q->done(index, result, rank, q->user);
    pthread_mutex_unlock(&q->lock);
}

#ifdef COHFRAC_HAVE_MPI
enum { TAG_ASK = 71, TAG_CASE = 72 };

/* Wait for a request without spinning: a blocking MPI receive busy-polls a
 * core that rank 0's own case needs. */
static int wait_request(MPI_Request *r, MPI_Status *s)
{
    const struct timespec nap = {0, 2000000}; /* 2 ms */
    for (;;) {
        int flag = 0;
        if (MPI_Test(r, &flag, s) != MPI_SUCCESS)
            return -1;
        if (flag)
            return 0;
        nanosleep(&nap, NULL);
    }
}

/* Rank 0's coordinator: every other rank asks with [finished index or -1,
 * its result]; the answer is the next index, -1 when none is left. */
typedef struct coordinator {
    queue *q;
    int failed;
} coordinator;

static void *coordinate(void *arg)
{
    coordinator *c = arg;
    queue *q = c->q;
    double *msg = malloc((size_t)(q->len + 1) * sizeof *msg);
    int active = g_size - 1;
    while (msg && active > 0) {
        MPI_Request r;
        MPI_Status s;
        if (MPI_Irecv(msg, q->len + 1, MPI_DOUBLE, MPI_ANY_SOURCE, TAG_ASK, MPI_COMM_WORLD,
                      &r) != MPI_SUCCESS ||
            wait_request(&r, &s) != 0)
            break;
        if (msg[0] >= 0)
            finish(q, (int)msg[0], msg + 1, s.MPI_SOURCE);
        int next = take(q);
        if (MPI_Send(&next, 1, MPI_INT, s.MPI_SOURCE, TAG_CASE, MPI_COMM_WORLD) != MPI_SUCCESS)
            break;
        active -= next < 0;
    }
    c->failed = !msg || active > 0;
    free(msg);
    return NULL;
}

static cf_status worker(int len, cf_case_run_fn run, void *user, cf_error *err)
{
    double *msg = calloc((size_t)len + 1, sizeof *msg);
    if (!msg)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    msg[0] = -1;
    for (;;) {
        int next;
        if (MPI_Send(msg, len + 1, MPI_DOUBLE, 0, TAG_ASK, MPI_COMM_WORLD) != MPI_SUCCESS ||
            MPI_Recv(&next, 1, MPI_INT, 0, TAG_CASE, MPI_COMM_WORLD, MPI_STATUS_IGNORE) !=
                MPI_SUCCESS) {
            free(msg);
            return cf_error_set(err, CF_ERR_EXTERNAL, "rank %d lost rank 0", g_rank);
        }
        if (next < 0)
            break;
        run(next, msg + 1, user);
        msg[0] = next;
    }
    free(msg);
    return CF_OK;
}
#endif

cf_status cf_mpi_cases(int n, const int *order, int len, double *results, cf_case_run_fn run,
                       cf_case_done_fn done, void *user, cf_error *err)
{
#ifdef COHFRAC_HAVE_MPI
    if (g_size > 1 && g_rank > 0)
        return worker(len, run, user, err);
#endif
    queue q = {.order = order, .n = n, .len = len, .results = results, .done = done,
               .user = user};
    double *one = malloc(((size_t)len + 1) * sizeof *one);
    if (!one || pthread_mutex_init(&q.lock, NULL) != 0) {
        free(one);
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    }
    cf_status st = CF_OK;
#ifdef COHFRAC_HAVE_MPI
    coordinator c = {&q, 0};
    pthread_t th;
    int threaded = g_size > 1;
    if (threaded && pthread_create(&th, NULL, coordinate, &c) != 0)
        st = cf_error_set(err, CF_ERR_EXTERNAL, "cannot start the coordinator thread");
#endif
    for (int i; st == CF_OK && (i = take(&q)) >= 0;) {
        run(i, one, user);
        finish(&q, i, one, 0);
    }
#ifdef COHFRAC_HAVE_MPI
    if (threaded && st == CF_OK) {
        pthread_join(th, NULL);
        if (c.failed)
            st = cf_error_set(err, CF_ERR_EXTERNAL,
                              "rank 0 lost the other ranks (an MPI call failed)");
    }
#endif
    pthread_mutex_destroy(&q.lock);
    free(one);
    return st;
}
