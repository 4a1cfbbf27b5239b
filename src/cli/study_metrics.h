/* cohfrac study: the metrics of a case against the reference, apart from
 * the orchestration that runs the cases (study.c).  cf_study_measure is
 * declared in study.h. */
#ifndef COHFRAC_STUDY_METRICS_H
#define COHFRAC_STUDY_METRICS_H

#include "study.h"
#include "trajectory.h"

/* How far the reference's fragments travel, m: the scale D of traj_rel. */
double cf_study_travel(const cf_trajectory *r);

/* Case c's metrics against the reference r (study.h), D from
 * cf_study_travel. */
void cf_study_case_measure(cf_study_case *c, const cf_trajectory *v, const cf_trajectory *r,
                           double D);

/* Mark the Pareto front over (wall, traj_rel) of the finished variants
 * c[1..n) (c[i].pareto), and return the cheapest one whose traj_rel is at
 * most tol, or -1. */
int cf_study_pareto(cf_study_case *c, int n, double tol);

#endif
