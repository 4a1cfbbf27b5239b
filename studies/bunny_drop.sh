#!/bin/sh
# Bunny drop (scenes/source/bunny_drop.lua, bunny_small): error against run time of
# the source's fracture-mode settings, dt_fracture x PBD iterations x
# k_stiffness (the source's: 5e-6 s, 3, 0.9).
#
# 1. Against the explicit reference (the default: constraints "none",
#    dt = 0.5 dt_cfl), with the scene as written.  At the source's
#    E = 0.6 Pa the explicit solver inverts tets at the impact: the report
#    says so and gives no verdict.
# 2. The grid against the converged PBD limit (dt_fracture 1e-6 s, k 1,
#    20 iterations): what the source's settings cost in accuracy against
#    the same method run fine.
#
# Usage, from the repository root after `make`: sh studies/bunny_drop.sh [JOBS]
# Results: docs/studies/bunny_drop{,_explicit}/study.{md,csv,png}
set -e
jobs=${1:-2}
cohfrac=${COHFRAC:-build/cohfrac}
$cohfrac study scenes/source/bunny_drop.lua -j "$jobs" -o docs/studies/bunny_drop_explicit
$cohfrac study scenes/source/bunny_drop.lua -j "$jobs" -o docs/studies/bunny_drop \
  --vary 'solver.dt_fracture=5e-6,2e-5,1e-4' \
  --vary 'solver.pbd.iterations=1,3,10' \
  --vary 'solver.pbd.k_stiffness=0.5,0.9,1' \
  --reference 'solver.dt_fracture=1e-6' \
  --reference 'solver.pbd.iterations=20' \
  --reference 'solver.pbd.k_stiffness=1'
