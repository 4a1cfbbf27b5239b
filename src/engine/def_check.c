/* Checks on world definitions (def_check.h). */
#include "def_check.h"

#include <math.h>
#include <stdio.h>

const cf_interval CF_POSITIVE = {0.0, INFINITY, 0, 0};
const cf_interval CF_NON_NEGATIVE = {0.0, INFINITY, 1, 0};

cf_status cf_check_interval(const char *key, double v, const cf_interval *r, cf_error *err)
{
    int ok = (r->lo_closed ? v >= r->lo : v > r->lo) && (r->hi_closed ? v <= r->hi : v < r->hi);
    if (ok)
        return CF_OK;
    char rule[96];
    if (isinf(r->hi))
        snprintf(rule, sizeof rule, "%s %g", r->lo_closed ? ">=" : ">", r->lo);
    else
        snprintf(rule, sizeof rule, "in %c%g, %g%c", r->lo_closed ? '[' : '(', r->lo, r->hi,
                 r->hi_closed ? ']' : ')');
    return cf_error_set(err, CF_ERR_SCENE_VALUE, "'%s' must be %s, got %.17g", key, rule, v);
}

cf_status cf_check_unit(const char *key, const double *v, int n, cf_error *err)
{
    double q = 0;
    for (int i = 0; i < n; i++)
        q += v[i] * v[i];
    if (fabs(q - 1.0) > 1e-9)
        return cf_error_set(err, CF_ERR_SCENE_VALUE,
                            "'%s' must be a unit %s (length 1), got length %.17g", key,
                            n == 4 ? "quaternion" : "vector", sqrt(q));
    return CF_OK;
}

const char *cf_obstacle_key(char *key, size_t size, int j, const char *name)
{
    snprintf(key, size, "obstacles[%d].%s", j + 1, name);
    return key;
}
