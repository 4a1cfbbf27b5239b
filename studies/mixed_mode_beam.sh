#!/bin/sh
# Mixed-mode beam (scenes/verification/mixed_mode_beam.lua): error against
# run time of fracture mode from dt_cfl upwards, PBD (the scene's k 1,
# 4 iterations) against XPBD (compliance from E), measured against the
# explicit reference (constraints "none", dt = 0.5 dt_cfl).
#
# dt/dt_cfl goes 1, 2, 5, 10, 20.  The source ran this beam at ~1,000x
# its explicit step; here dt_cfl = 1.44e-5 s (smallest tet of the gmsh
# mesh), so 1,000 dt_cfl = 0.0144 s is longer than the whole 9 ms run, and
# above ~20 dt_cfl the frame interval (dt_rigid, 3e-4 s) would be shorter
# than one step.
#
# Usage, from the repository root after `make`: sh studies/mixed_mode_beam.sh [JOBS]
# Results: docs/studies/mixed_mode_beam/study.{md,csv,png}
set -e
cohfrac=${COHFRAC:-build/cohfrac}
$cohfrac study scenes/verification/mixed_mode_beam.lua -j "${1:-2}" \
  -o docs/studies/mixed_mode_beam \
  --set 'output.file=""' \
  --vary 'solver.cfl_fraction=1,2,5,10,20' \
  --vary 'solver.constraints="pbd","xpbd"'
