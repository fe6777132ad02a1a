/* Whether standard error is a terminal: progress is redrawn in place there,
 * and written as plain lines to a batch job's log otherwise. */
#include <unistd.h>

int friction_stderr_is_terminal(void) { return isatty(STDERR_FILENO); }

/* Process id, to make temporary output names unique. */
int friction_process_id(void) { return (int)getpid(); }
