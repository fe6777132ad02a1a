/* Random streams for the thermal tip: GSL's taus2 generator, seeded from a
 * hash of (seed, line, trip, realization).  See friction_random (random.f90)
 * for the why; here is what Fortran should not do itself: unsigned 64-bit
 * arithmetic (splitmix64) and the generator's state.
 *
 * GSL seeds every generator of this kind from 32 bits (gsl_rng_set), so
 * hashed tuples would collide by the birthday bound after ~1e5 streams; a
 * map of 128 x 128 lines, 2 trips and a few realizations has more.  The
 * 88-bit state of taus2 is therefore written directly from 64 hashed bits:
 * the state layout below is GSL's (rng/taus.c, unchanged since GSL 1.0), and
 * friction_rng_new checks it twice (the type's state size, and the first
 * output against our own step of the recurrence) before it hands out a
 * stream, so a GSL with another layout gives an error, never a wrong stream.
 *
 * Streams are allocated with malloc here, not gsl_rng_alloc: no path goes
 * through GSL's process-wide error handler, and each stream owns its state,
 * so streams on different threads share nothing. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <gsl/gsl_rng.h>
#include <gsl/gsl_randist.h>

/* GSL's taus2 state (rng/taus.c). */
typedef struct {
    unsigned long int s1, s2, s3;
} friction_taus_state;

#define FRICTION_GOLDEN 0x9e3779b97f4a7c15ULL

/* splitmix64's finaliser (Steele, Lea, Flood 2014): a bijection of 64-bit
 * words with full avalanche. */
static uint64_t mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

/* The tuple's 64-bit hash.  Each component enters through a bijection of
 * the hash so far (xor, then mix64), with its own additive constant, so two
 * tuples that differ in one component never collide, and tuples that differ
 * otherwise collide with probability 2^-64.  The order of the components
 * matters: (line, trip) = (1, 2) and (2, 1) are different streams. */
uint64_t friction_rng_hash(int64_t seed, int64_t line, int64_t trip, int64_t realization)
{
    uint64_t h = mix64((uint64_t)seed + FRICTION_GOLDEN);
    h = mix64(h ^ ((uint64_t)line + 2 * FRICTION_GOLDEN));
    h = mix64(h ^ ((uint64_t)trip + 3 * FRICTION_GOLDEN));
    h = mix64(h ^ ((uint64_t)realization + 4 * FRICTION_GOLDEN));
    return h;
}

/* One step of the taus2 recurrence on a copy of the state (L'Ecuyer 1996,
 * as GSL writes it), to check that the state is where we think it is. */
#define FRICTION_MASK 0xffffffffUL
#define FRICTION_TAUSWORTHE(s, a, b, c, d) \
    ((((s) & (c)) << (d)) & FRICTION_MASK) ^ (((((s) << (a)) & FRICTION_MASK) ^ (s)) >> (b))

static unsigned long taus2_next(friction_taus_state *s)
{
    s->s1 = FRICTION_TAUSWORTHE(s->s1, 13, 19, 4294967294UL, 12);
    s->s2 = FRICTION_TAUSWORTHE(s->s2, 2, 25, 4294967288UL, 4);
    s->s3 = FRICTION_TAUSWORTHE(s->s3, 3, 11, 4294967280UL, 17);
    return s->s1 ^ s->s2 ^ s->s3;
}

/* A new taus2 stream for the tuple, or NULL when memory runs out or the
 * GSL at hand does not lay out taus2 as expected. */
gsl_rng *friction_rng_new(int64_t seed, int64_t line, int64_t trip, int64_t realization)
{
    const gsl_rng_type *type = gsl_rng_taus2;
    friction_taus_state mine;
    gsl_rng *r;
    uint64_t h, h2;
    int i;

    if (type->size != sizeof(friction_taus_state)) return NULL;
    r = malloc(sizeof *r);
    if (r == NULL) return NULL;
    r->type = type;
    r->state = malloc(type->size);
    if (r->state == NULL) {
        free(r);
        return NULL;
    }
    h = friction_rng_hash(seed, line, trip, realization);
    h2 = mix64(h + FRICTION_GOLDEN);
    /* 32-bit words, with taus2's own lower bounds (s1 >= 2, s2 >= 8,
     * s3 >= 16: below them a component is stuck at zero), as gsl_rng_set. */
    mine.s1 = (unsigned long)(h & 0xffffffffULL);
    mine.s2 = (unsigned long)(h >> 32);
    mine.s3 = (unsigned long)(h2 & 0xffffffffULL);
    if (mine.s1 < 2UL) mine.s1 += 2UL;
    if (mine.s2 < 8UL) mine.s2 += 8UL;
    if (mine.s3 < 16UL) mine.s3 += 16UL;
    memcpy(r->state, &mine, sizeof mine);
    /* The layout check, then the warm-up gsl_rng_set does too (6 draws). */
    for (i = 0; i < 6; i++) {
        if (gsl_rng_get(r) != taus2_next(&mine)) {
            free(r->state);
            free(r);
            return NULL;
        }
    }
    return r;
}

/* An independent copy with the same state (the same future draws). */
gsl_rng *friction_rng_clone(const gsl_rng *source)
{
    gsl_rng *r;

    if (source == NULL) return NULL;
    r = malloc(sizeof *r);
    if (r == NULL) return NULL;
    r->type = source->type;
    r->state = malloc(source->type->size);
    if (r->state == NULL) {
        free(r);
        return NULL;
    }
    memcpy(r->state, source->state, source->type->size);
    return r;
}

void friction_rng_free(gsl_rng *r)
{
    if (r == NULL) return;
    free(r->state);
    free(r);
}

/* n standard normal variates by the ziggurat method (Marsaglia & Tsang
 * 2000, GSL's gsl_ran_gaussian_ziggurat: one 32-bit draw per variate in
 * 98.8 % of cases; its 24-bit resolution, 6e-8, is far below what a
 * Langevin step resolves). */
void friction_rng_gaussians(gsl_rng *r, double *x, int n)
{
    int i;
    for (i = 0; i < n; i++) x[i] = gsl_ran_gaussian_ziggurat(r, 1.0);
}

/* A uniform variate in (0, 1): never 0, so -log(u) is finite. */
double friction_rng_uniform(gsl_rng *r)
{
    return gsl_rng_uniform_pos(r);
}

/* The next raw 32-bit output, for tests of the generator itself. */
unsigned long friction_rng_raw(gsl_rng *r)
{
    return gsl_rng_get(r);
}
