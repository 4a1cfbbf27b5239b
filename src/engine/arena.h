/* The step's arena: scratch that lives inside one stage of one step.  A
 * stage takes what it needs (cf_arena_take) and gives it back before it
 * returns (cf_arena_release to the mark it took first), so the arena is
 * empty between steps, which cf_arena_end_step asserts.  The block grows
 * to the most a step has needed, so once the largest step has run, steps
 * call no allocator (tests/test_step_profile.c counts them). */
#ifndef COHFRAC_ARENA_H
#define COHFRAC_ARENA_H

#include <stddef.h>

typedef struct cf_arena_spill cf_arena_spill;

typedef struct cf_arena {
    unsigned char *base; /* the block */
    size_t cap, top;     /* bytes: its size, the part in use */
    cf_arena_spill *spill; /* blocks taken this step when the block was full */
    size_t spilled;      /* bytes in them */
} cf_arena;

/* Where the arena stands now: give it to cf_arena_release. */
static inline size_t cf_arena_mark(const cf_arena *a) { return a->top; }

/* Room for `bytes`, aligned for any type, until the release to a mark
 * taken before.  NULL when out of memory. */
void *cf_arena_take(cf_arena *a, size_t bytes);

/* Gives back everything taken since `mark`. */
static inline void cf_arena_release(cf_arena *a, size_t mark) { a->top = mark; }

/* The step is over: asserts that every stage gave back what it took,
 * frees the spill blocks and grows the block by what they held, so the
 * next step like this one fits.  Returns 0, or -1 out of memory (the
 * arena stays usable: it spills again). */
int cf_arena_end_step(cf_arena *a);

void cf_arena_free(cf_arena *a);

#endif
