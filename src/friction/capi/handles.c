/* The C API's live handles: every configuration, result, error and law
 * handle the library gave out and the host has not freed, with its kind.
 *
 * A host that frees a handle twice, or uses one after freeing it, used to
 * kill itself inside the library (the second free corrupted the heap).  A
 * magic number inside the handle, cleared on free, would be read from freed
 * memory, which the allocator may have reused or given back to the system;
 * this table is looked up instead, so a freed handle is never touched.  A
 * handle that is not in the table (freed, never given out, or of another
 * kind) is refused with an error by the calls that take it, and ignored by
 * the frees.  What cannot be told apart: a freed handle whose address the
 * allocator has given to a new handle of the same kind (friction.h says so).
 *
 * An open-addressing hash set under a mutex: a lookup is a few loads, far
 * below any call's own cost.  It grows with the handles alive at once. */
#include <pthread.h>
#include <stdint.h>
#include <stdlib.h>

struct entry {
    uintptr_t address; /* 0: empty; 1: removed (addresses of handles are aligned, never 1) */
    int kind;
};

static pthread_mutex_t table_mutex = PTHREAD_MUTEX_INITIALIZER;
static struct entry *table = NULL;
static size_t capacity = 0; /* a power of two */
static size_t used = 0;     /* entries not empty (live and removed) */

static size_t slot_of(uintptr_t address, size_t mask)
{
    uint64_t h = (uint64_t)address * 0x9e3779b97f4a7c15ull; /* Fibonacci hashing */
    return (size_t)(h >> 17) & mask;
}

/* Rebuild the table at new_capacity without its removed entries; 0 on failure. */
static int rebuild(size_t new_capacity)
{
    struct entry *fresh = calloc(new_capacity, sizeof *fresh);
    if (fresh == NULL) return 0;
    size_t live = 0;
    for (size_t k = 0; k < capacity; ++k) {
        if (table[k].address <= 1) continue;
        size_t s = slot_of(table[k].address, new_capacity - 1);
        while (fresh[s].address != 0) s = (s + 1) & (new_capacity - 1);
        fresh[s] = table[k];
        ++live;
    }
    free(table);
    table = fresh;
    capacity = new_capacity;
    used = live;
    return 1;
}

/* The slot of a live address of this kind, or -1. */
static long find(uintptr_t address, int kind)
{
    if (capacity == 0 || address <= 1) return -1;
    size_t s = slot_of(address, capacity - 1);
    while (table[s].address != 0) {
        if (table[s].address == address) return table[s].kind == kind ? (long)s : -1;
        s = (s + 1) & (capacity - 1);
    }
    return -1;
}

/* Record a new handle; 0 if the table could not grow (out of memory). */
int friction_handle_add(const void *handle, int kind)
{
    uintptr_t address = (uintptr_t)handle;
    int ok = 1;
    pthread_mutex_lock(&table_mutex);
    if (4 * (used + 1) > 3 * capacity) {
        /* Rebuilt at most half full with the live ones, so that many handles
         * made and freed in turn do not grow it. */
        size_t live = 0, size = 64;
        for (size_t k = 0; k < capacity; ++k) live += table[k].address > 1;
        while (4 * (live + 1) > 2 * size) size *= 2;
        ok = rebuild(size);
    }
    if (ok) {
        size_t s = slot_of(address, capacity - 1);
        while (table[s].address > 1) s = (s + 1) & (capacity - 1);
        if (table[s].address == 0) ++used;
        table[s].address = address;
        table[s].kind = kind;
    }
    pthread_mutex_unlock(&table_mutex);
    return ok;
}

/* Take a handle out before it is freed: 1 if it was live and of this kind. */
int friction_handle_remove(const void *handle, int kind)
{
    pthread_mutex_lock(&table_mutex);
    long s = find((uintptr_t)handle, kind);
    if (s >= 0) table[s].address = 1;
    pthread_mutex_unlock(&table_mutex);
    return s >= 0;
}

/* 1 if the handle is live and of this kind. */
int friction_handle_live(const void *handle, int kind)
{
    pthread_mutex_lock(&table_mutex);
    long s = find((uintptr_t)handle, kind);
    pthread_mutex_unlock(&table_mutex);
    return s >= 0;
}
