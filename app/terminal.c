/* Whether standard error is a terminal: progress is redrawn in place there,
 * and written as plain lines to a batch job's log otherwise. */
#include <unistd.h>

int friction_stderr_is_terminal(void) { return isatty(STDERR_FILENO); }

/* Write all of buf to file descriptor fd (1 or 2) with write(2): 0, or the
 * errno of the failure (EPIPE for a pipe whose reader ended, EBADF for a
 * closed descriptor, ENOSPC for /dev/full or a full disk), with its text in
 * message.  gfortran's own write and flush to output_unit and error_unit
 * report success on all of these. */
#include <errno.h>
#include <stdio.h>
#include <string.h>

int friction_write_fd(int fd, const char *buf, size_t n, char *message, size_t length)
{
    size_t done = 0;
    while (done < n) {
        ssize_t wrote = write(fd, buf + done, n - done);
        if (wrote < 0 && errno == EINTR) continue;
        if (wrote <= 0) {
            int code = wrote < 0 ? errno : EIO;
            snprintf(message, length, "%s", strerror(code));
            return code;
        }
        done += (size_t)wrote;
    }
    return 0;
}
