/* The step's profile: wall time per stage (cohfrac/world.h, cf_stage).
 * The stages take turns on one clock: cf_profile_lap charges the time
 * since the last lap to the stage that has just run and starts the next,
 * so no time is counted twice, nested calls included, and the stages add
 * up to the step (the time from cf_profile_start to the last lap). */
#ifndef COHFRAC_PROFILE_H
#define COHFRAC_PROFILE_H

#include "clock.h"
#include "cohfrac/world.h"

typedef struct cf_profile {
    double stage[CF_STAGE_COUNT]; /* s of wall time */
    double mark;                  /* s: when the running stage began */
} cf_profile;

/* The step begins: the clock runs for its first stage. */
static inline void cf_profile_start(cf_profile *p) { p->mark = cf_wall_time(); }

/* Stage s has just run: its time is charged, and the next one begins.
 * Returns the time charged, s. */
static inline double cf_profile_lap(cf_profile *p, cf_stage s)
{
    double now = cf_wall_time(), lap = now - p->mark;
    p->stage[s] += lap;
    p->mark = now;
    return lap;
}

#endif
