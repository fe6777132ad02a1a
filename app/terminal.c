/* Whether standard error is a terminal: progress is redrawn in place there,
 * and written as plain lines to a batch job's log otherwise. */
#include <unistd.h>

int friction_stderr_is_terminal(void) { return isatty(STDERR_FILENO); }
