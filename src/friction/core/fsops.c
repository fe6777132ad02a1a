/* File-system calls Fortran lacks, for publishing output safely (core/files.f90):
 * the type of what is at a path (without following a symbolic link), whether
 * two paths are one file, a hard link that fails when the target exists, a
 * rename that never replaces, removal, and truncation.  Each returns 0 or the
 * errno of the failure, and friction_error_text says what an errno means. */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <sys/syscall.h>
#include <unistd.h>

/* What is at path, the link itself when follow is 0: 0 nothing, 1 a regular
 * file, 2 a directory, 3 a symbolic link, 5 a pipe (FIFO), 4 anything else (a
 * device or socket), -1 cannot tell (permission, a path too long, ...). */
int friction_path_kind(const char *path, int follow)
{
    struct stat s;
    int status = follow ? stat(path, &s) : lstat(path, &s);
    if (status != 0) return (errno == ENOENT || errno == ENOTDIR) ? 0 : -1;
    if (S_ISREG(s.st_mode)) return 1;
    if (S_ISDIR(s.st_mode)) return 2;
    if (S_ISLNK(s.st_mode)) return 3;
    if (S_ISFIFO(s.st_mode)) return 5;
    return 4;
}

/* 1 when both paths exist and are the same file (device and inode, links
 * followed), else 0. */
int friction_same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    if (stat(a, &sa) != 0 || stat(b, &sb) != 0) return 0;
    return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

/* A second name for an existing file; fails with EEXIST if `to` exists, so
 * a file appears under `to` only if nothing was there at that moment. */
int friction_link(const char *from, const char *to)
{
    return link(from, to) == 0 ? 0 : errno;
}

/* The errno value of an existing target (EEXIST). */
int friction_errno_exists(void) { return EEXIST; }

/* rename(2) that fails with EEXIST instead of replacing (Linux renameat2
 * RENAME_NOREPLACE); EINVAL or ENOSYS where the file system or kernel lacks it. */
int friction_rename_noreplace(const char *from, const char *to)
{
#ifdef SYS_renameat2
    return syscall(SYS_renameat2, AT_FDCWD, from, AT_FDCWD, to, 1u /* RENAME_NOREPLACE */) == 0 ? 0 : errno;
#else
    (void)from;
    (void)to;
    return ENOSYS;
#endif
}

/* rename(2), replacing `to`. */
int friction_rename(const char *from, const char *to)
{
    return rename(from, to) == 0 ? 0 : errno;
}

int friction_unlink(const char *path)
{
    return unlink(path) == 0 ? 0 : errno;
}

/* Cut a file to no bytes: gives back the space of a file that could not be
 * written whole (a full disk), so its writer can close it. */
int friction_truncate(const char *path)
{
    return truncate(path, 0) == 0 ? 0 : errno;
}

double friction_disk_free_bytes(const char *path);

/* Bytes the process's file-size limit (RLIMIT_FSIZE, `ulimit -f`) still
 * lets the file at path grow by (its whole size when it does not exist);
 * -1 without a limit.  A write beyond it fails with EFBIG (SIGXFSZ is
 * ignored by the program), as a full disk's fails with ENOSPC. */
double friction_size_limit_room(const char *path)
{
    struct rlimit limit;
    if (getrlimit(RLIMIT_FSIZE, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return -1.0;
    struct stat st;
    double size = stat(path, &st) == 0 && S_ISREG(st.st_mode) ? (double)st.st_size : 0.0;
    double room = (double)limit.rlim_cur - size;
    return room > 0.0 ? room : 0.0;
}

/* Bytes an unprivileged writer may still write on the file system that
 * holds path (or its directory, when path does not exist yet), or into the
 * file at path under the file-size limit, whichever is less; -1 unknown. */
double friction_free_bytes(const char *path)
{
    double disk = friction_disk_free_bytes(path);
    double limit = friction_size_limit_room(path);
    if (limit >= 0.0 && (disk < 0.0 || limit < disk)) return limit;
    return disk;
}

/* The file system's part of friction_free_bytes. */
double friction_disk_free_bytes(const char *path)
{
    struct statvfs s;
    if (statvfs(path, &s) != 0) {
        char directory[4096];
        const char *slash = strrchr(path, '/');
        if (slash == NULL) {
            snprintf(directory, sizeof directory, ".");
        } else {
            size_t n = (size_t)(slash - path);
            if (n == 0) n = 1;
            if (n >= sizeof directory) return -1.0;
            memcpy(directory, path, n);
            directory[n] = '\0';
        }
        if (statvfs(directory, &s) != 0) return -1.0;
    }
    return (double)s.f_bavail * (double)s.f_frsize;
}

/* Write `length` bytes to a new file at path (replacing one there), every
 * step checked: open, write, flush, fsync (unless `sync` is 0: the caller
 * syncs many files at once, friction_sync_files) and close.  (gfortran's
 * formatted and stream writes lose ENOSPC: its flush and close report
 * success on a full disk, leaving an empty file.)  On failure the file is
 * removed and the errno returned. */
int friction_write_file(const char *path, const char *data, long length, int sync)
{
    int code = 0;
    FILE *file = fopen(path, "wb");
    if (file == NULL) return errno;
    if (length > 0 && fwrite(data, 1, (size_t)length, file) != (size_t)length) code = errno;
    if (code == 0 && fflush(file) != 0) code = errno;
    if (code == 0 && sync && fsync(fileno(file)) != 0 && errno != EINVAL && errno != EROFS) code = errno;
    if (fclose(file) != 0 && code == 0) code = errno;
    if (code == 0) return 0;
    unlink(path);
    return code;
}

/* The text of errno `code`, NUL-terminated in buffer (of `size` bytes). */
void friction_error_text(int code, char *buffer, int size)
{
    if (size <= 0) return;
    snprintf(buffer, (size_t)size, "%s", strerror(code));
}

/* Everything written to the file system that holds `path` (an existing
 * file) on disk: one syncfs(2) for many files written without their own
 * fsync.  0 or the errno of the failure. */
int friction_sync_files(const char *path)
{
    int fd = open(path, O_RDONLY);
    if (fd < 0) return errno;
    int code = syncfs(fd) == 0 ? 0 : errno;
    close(fd);
    return code;
}
