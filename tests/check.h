/* Double-precision assertion for CMocka (its assert_float_equal casts to float). */
#ifndef COHFRAC_TEST_CHECK_H
#define COHFRAC_TEST_CHECK_H

#include <math.h>

#define assert_near(a, b, tol)                                                              \
    do {                                                                                    \
        double a_ = (a), b_ = (b), t_ = (tol);                                              \
        if (!(fabs(a_ - b_) <= t_))                                                         \
            fail_msg("%s = %.17g, expected %s = %.17g within %.3g", #a, a_, #b, b_, t_);    \
    } while (0)

#endif
