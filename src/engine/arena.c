/* The step's arena (arena.h). */
#include "arena.h"

#include <assert.h>
#include <stdalign.h>
#include <stdlib.h>

/* A spill block's header; the room follows it. */
struct cf_arena_spill {
    alignas(max_align_t) cf_arena_spill *next;
};

static size_t aligned(size_t bytes)
{
    const size_t A = alignof(max_align_t);
    return (bytes + A - 1) / A * A;
}

void *cf_arena_take(cf_arena *a, size_t bytes)
{
    size_t n = aligned(bytes > 0 ? bytes : 1);
    if (a->base && n <= a->cap - a->top) {
        void *p = a->base + a->top;
        a->top += n;
        return p;
    }
    /* Full: a block of its own until the step ends (the marks taken before
     * stay valid, as the block does not move). */
    cf_arena_spill *s = malloc(sizeof *s + n);
    if (!s)
        return NULL;
    s->next = a->spill, a->spill = s;
    a->spilled += n;
    return s + 1;
}

static void free_spills(cf_arena *a)
{
    while (a->spill) {
        cf_arena_spill *next = a->spill->next;
        free(a->spill);
        a->spill = next;
    }
    a->spilled = 0;
}

int cf_arena_end_step(cf_arena *a)
{
    assert(a->top == 0 && "a stage kept scratch of the step's arena past its end");
    a->top = 0;
    if (!a->spill)
        return 0;
    size_t cap = a->cap + a->spilled;
    free_spills(a);
    unsigned char *b = malloc(cap);
    if (!b)
        return -1;
    free(a->base);
    a->base = b, a->cap = cap;
    return 0;
}

void cf_arena_free(cf_arena *a)
{
    free_spills(a);
    free(a->base);
    a->base = NULL, a->cap = a->top = 0;
}
