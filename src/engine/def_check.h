/* Checks on world definitions, worded as the scene loader words them
 * ("'material.E' must be > 0, got -1"): what cf_world_def_check and each
 * obstacle kind's check share. */
#ifndef COHFRAC_DEF_CHECK_H
#define COHFRAC_DEF_CHECK_H

#include "cohfrac/error.h"

#include <stddef.h>

/* An allowed interval of a setting. */
typedef struct cf_interval {
    double lo, hi;
    int lo_closed, hi_closed;
} cf_interval;

extern const cf_interval CF_POSITIVE;     /* (0, inf) */
extern const cf_interval CF_NON_NEGATIVE; /* [0, inf) */

/* CF_OK when v lies in r, else CF_ERR_SCENE_VALUE naming `key`, the
 * interval and v. */
cf_status cf_check_interval(const char *key, double v, const cf_interval *r, cf_error *err);

/* CF_OK when the n-vector v has length 1 within 1e-9, else
 * CF_ERR_SCENE_VALUE naming `key` (a "quaternion" for n = 4). */
cf_status cf_check_unit(const char *key, const double *v, int n, cf_error *err);

/* "obstacles[j+1].name" in key[size]: the key path of obstacle j's setting. */
const char *cf_obstacle_key(char *key, size_t size, int j, const char *name);

/* Return from the calling function (its cf_error *err) when value lies
 * outside range. */
#define CHECK(key, value, range)                                                             \
    do {                                                                                     \
        cf_status st_ = cf_check_interval(key, (double)(value), &(range), err);              \
        if (st_ != CF_OK)                                                                    \
            return st_;                                                                      \
    } while (0)

#endif
