/* Wall-clock time for the run profile, the studies and the mesher's log. */
#ifndef COHFRAC_CLOCK_H
#define COHFRAC_CLOCK_H

/* Seconds on the monotonic clock (CLOCK_MONOTONIC): differences only. */
double cf_wall_time(void);

#endif
