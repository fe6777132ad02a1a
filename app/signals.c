/* SIGTERM and SIGINT (Ctrl-C, a cluster's wall-time limit) during a sweep:
 * the handler only sets a flag, which the sweep checks between points, so a
 * point in progress finishes and the file and checkpoints stay consistent.
 * SIGPIPE (stderr a pipe whose reader ended: `2>&1 | head`) and SIGXFSZ (a
 * file-size limit, `ulimit -f`) are ignored, so the write fails with EPIPE or
 * EFBIG instead and is reported as an I/O error, as a full disk is. */
#include <signal.h>
#include <string.h>

static volatile sig_atomic_t interrupted = 0;

static void note_signal(int signal_number) { (void)signal_number; interrupted = 1; }

void friction_catch_signals(void) {
    struct sigaction action;
    memset(&action, 0, sizeof action);
    action.sa_handler = note_signal;
    sigemptyset(&action.sa_mask);
    sigaction(SIGTERM, &action, NULL);
    sigaction(SIGINT, &action, NULL);
}

int friction_interrupted(void) { return (int)interrupted; }

void friction_ignore_write_signals(void) {
    struct sigaction action;
    memset(&action, 0, sizeof action);
    action.sa_handler = SIG_IGN;
    sigemptyset(&action.sa_mask);
    sigaction(SIGPIPE, &action, NULL);
    sigaction(SIGXFSZ, &action, NULL);
}
