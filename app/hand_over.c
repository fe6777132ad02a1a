/* The serial program's hand-over to the parallel one (app/cli.f90,
 * hand_over): the program `name` in this program's own directory
 * (/proc/self/exe, so it works in the build tree, an installation, or a
 * copy moved elsewhere with its sibling) replaces this process, with the
 * same arguments and environment, and so keeps the process id the
 * launcher knows.  Returns only when it could not, with the path tried and
 * the reason in `message`. */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* This process's arguments as the kernel keeps them (NUL-separated). */
static char **own_arguments(char *program, char **kept)
{
    int fd = open("/proc/self/cmdline", O_RDONLY | O_CLOEXEC);
    if (fd < 0) return NULL;
    size_t size = 0, room = 4096;
    char *text = malloc(room);
    for (;;) {
        if (text == NULL) break;
        ssize_t got = read(fd, text + size, room - size);
        if (got < 0 && errno == EINTR) continue;
        if (got <= 0) break;
        size += (size_t)got;
        if (size == room) {
            char *more = realloc(text, room *= 2);
            if (more == NULL) { free(text); text = NULL; break; }
            text = more;
        }
    }
    close(fd);
    if (text == NULL || size == 0) { free(text); return NULL; }
    size_t count = 0;
    for (size_t k = 0; k < size; k++) count += text[k] == '\0';
    char **argv = calloc(count + 2, sizeof *argv);
    if (argv == NULL) { free(text); return NULL; }
    size_t n = 0;
    for (size_t k = 0; k < size && n < count; n++) {
        argv[n] = text + k;
        k += strlen(text + k) + 1;
    }
    argv[0] = program;   /* the parallel program's own name, as ps shows it */
    argv[n] = NULL;
    *kept = text;
    return argv;
}

void friction_hand_over(const char *name, char *message, int length)
{
    char path[PATH_MAX];
    const char *marker = "FRICTION_HANDED_OVER";
    ssize_t n = readlink("/proc/self/exe", path, sizeof path - 1);
    if (length <= 0) return;
    message[0] = '\0';
    if (n <= 0) {
        snprintf(message, (size_t)length, "this program's own path is unknown (/proc/self/exe: %s)",
                 strerror(errno));
        return;
    }
    path[n] = '\0';
    char *slash = strrchr(path, '/');
    size_t dir = slash ? (size_t)(slash - path) + 1 : 0;
    if (dir + strlen(name) + 1 > sizeof path) {
        snprintf(message, (size_t)length, "the path of %s is too long", name);
        return;
    }
    strcpy(path + dir, name);
    /* A serial program installed under the parallel one's name would hand
     * over to itself for ever: the marker stops the second hand-over. */
    if (getenv(marker) != NULL) {
        snprintf(message, (size_t)length, "%s is itself a serial program (handed over to already)", path);
        return;
    }
    char *text = NULL;
    char **argv = own_arguments(path, &text);
    if (argv == NULL) {
        snprintf(message, (size_t)length, "this program's arguments are unknown (/proc/self/cmdline)");
        return;
    }
    setenv(marker, "1", 1);
    execv(path, argv);
    int why = errno;
    unsetenv(marker);
    free(argv);
    free(text);
    snprintf(message, (size_t)length, "%s: %s", path, strerror(why));
}
