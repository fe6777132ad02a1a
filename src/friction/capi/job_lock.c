/* One job at a time in a process (friction_run_job, friction_run_config).
 *
 * A job uses state that is the whole process's: HDF5 (a build without its
 * thread-safe option, as Debian's and ours are), FFTW's planner, MPI and a
 * sweep's signal handlers.  Two jobs at once on two threads of a host (a
 * Python program's threads: ctypes lets them call at once) reported false
 * errors and crashed the host.  So a job waits for the one running on
 * another thread to finish; one started on the thread already running a job
 * (from that job's report callback) cannot wait for itself and is refused.
 * The in-memory computations (friction_compute, friction_afm_line) use none
 * of that state and stay free to run at once.
 *
 * Reading a namelist file (friction_config_read) takes the same lock: the
 * Fortran runtime's file units are shared by the process, and two threads
 * reading at once got false "cannot open the file" errors and then
 * corrupted the heap.  A read on the thread that runs a job (from its
 * callback) already holds it.
 *
 * A stop request (friction_job_stop) is for the job running now: a flag
 * that a job clears when it begins and asks between its pieces of work.
 *
 * A process forked while a job or a read ran in its parent (Python's
 * multiprocessing with fork, beside a job on another thread) inherits the
 * lock held by a thread it does not have: its first job waited forever.
 * Its HDF5 and Fortran runtime are the parent's, caught half-way, so it
 * must not use them either: after such a fork the child's lock is new and
 * its jobs and reads are refused.  A fork between jobs changes nothing. */
#include <pthread.h>
#include <stdatomic.h>

static pthread_mutex_t job_mutex = PTHREAD_MUTEX_INITIALIZER;
static _Thread_local int job_running = 0;   /* this thread holds job_mutex */
static atomic_int stop_asked = 0;           /* lock-free: safe in a signal handler */
static int forked_mid_job = 0;              /* this process was forked while the lock was held */

static void after_fork_in_child(void)
{
    if (pthread_mutex_trylock(&job_mutex) == 0) {
        pthread_mutex_unlock(&job_mutex);
        return;
    }
    forked_mid_job = 1;
    pthread_mutex_init(&job_mutex, NULL);
    job_running = 0;
}

__attribute__((constructor)) static void watch_forks(void)
{
    pthread_atfork(NULL, NULL, after_fork_in_child);
}

/* 0: the calling thread may run its job (after waiting for another's);
 * 1: it is running one already, and must not start another; 2: the
 * process was forked while its parent ran a job (see above). */
int friction_job_begin(void)
{
    if (forked_mid_job) return 2;
    if (job_running) return 1;
    pthread_mutex_lock(&job_mutex);
    job_running = 1;
    atomic_store(&stop_asked, 0);
    return 0;
}

/* After a job that friction_job_begin let run. */
void friction_job_end(void)
{
    job_running = 0;
    pthread_mutex_unlock(&job_mutex);
}

/* Around a file read: 1 if the lock was taken (release it with
 * friction_read_end), 0 if this thread holds it already for its job, -1 if
 * the read must not run (a process forked while its parent ran a job). */
int friction_read_begin(void)
{
    if (forked_mid_job) return -1;
    if (job_running) return 0;
    pthread_mutex_lock(&job_mutex);
    return 1;
}

void friction_read_end(void)
{
    pthread_mutex_unlock(&job_mutex);
}

/* friction.h: ask the running job to stop at its next safe point. */
void friction_job_stop(void)
{
    atomic_store(&stop_asked, 1);
}

/* 1 once friction_job_stop was called during the running job. */
int friction_job_stop_asked(void)
{
    return atomic_load(&stop_asked);
}
