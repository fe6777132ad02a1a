/* Memory backed at once: a large array's pages in one request to the
 * kernel instead of one trap per page at its first touch.  Each such trap
 * costs some 2 microseconds in a virtual machine, 8 ms for the 15 MB of a
 * graphite table's cells (docs/speed.md). */
#include <errno.h>
#include <stddef.h>
#include <stdint.h>
#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif

/* Linux 5.14's value, for headers older than the kernel that runs us. */
#if defined(__linux__) && !defined(MADV_POPULATE_WRITE)
#define MADV_POPULATE_WRITE 23
#endif

/* Backs the whole pages within [p, p + bytes) with memory now, as writing
 * to each would.  Their contents do not change: pages new to the process
 * are zero either way, and memory the allocator reuses keeps its values.
 * Where the kernel lacks the request (Linux before 5.14, another system)
 * or refuses it, nothing happens, and the pages come at their first touch
 * as they would have; errno is left as it was. */
void friction_populate(void *p, size_t bytes)
{
#if defined(__linux__)
  long size = sysconf(_SC_PAGESIZE);
  if (p == NULL || size <= 0) return;
  uintptr_t page = (uintptr_t)size;
  uintptr_t first = ((uintptr_t)p + page - 1) & ~(page - 1);
  uintptr_t end = ((uintptr_t)p + bytes) & ~(page - 1);
  int saved = errno;
  if (end > first) (void)madvise((void *)first, end - first, MADV_POPULATE_WRITE);
  errno = saved;
#else
  (void)p;
  (void)bytes;
#endif
}
