#!/bin/sh
# Rigid mode alone: the bunny drop (scenes/source/bunny_drop.lua, bunny_small)
# with fracture switched off (impact_threshold 1e9 m/s: the bunny never
# leaves rigid mode), dt_rigid for Bullet against the source's damped PBD
# rigid mode (k_damping 1), measured against Bullet at dt_rigid = 1e-4 s.
#
# Usage, from the repository root after `make`: sh studies/rigid_dt.sh [JOBS]
# Results: docs/studies/rigid_dt/study.{md,csv,png}
set -e
cohfrac=${COHFRAC:-build/cohfrac}
$cohfrac study scenes/source/bunny_drop.lua -j "${1:-2}" -o docs/studies/rigid_dt \
  --set 'solver.impact_threshold=1e9' \
  --vary 'solver.dt_rigid=5e-4,1e-3,2e-3,5e-3' \
  --vary 'solver.rigid_backend="bullet","pbd"' \
  --reference 'solver.dt_rigid=1e-4' \
  --reference 'solver.rigid_backend="bullet"'
