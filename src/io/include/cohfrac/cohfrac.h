/* cohfrac — everything a program needs, in one include:
 *   cohfrac/types.h    world definitions and their defaults (cf_default_*)
 *   cohfrac/tetmesh.h  the Tet4 mesh type
 *   cohfrac/world.h    the engine: create, step, events, queries
 *   cohfrac/mesh.h     mesh preparation: loaders, primitives, hollowing
 *   cohfrac/surface.h  triangle surfaces, tetgen, the meshes a definition names
 *   cohfrac/scene.h    Lua scene files into a world definition
 *   cohfrac/sim.h      the run loop: HDF5 output, progress, summary
 *   cohfrac/h5_output.h  the HDF5 writer
 *   cohfrac/export.h   glTF export of a run
 *   cohfrac/version.h  COHFRAC_VERSION_* and cf_version()
 * See docs/architecture.md and examples/drop.c. */
#ifndef COHFRAC_COHFRAC_H
#define COHFRAC_COHFRAC_H

#include "cohfrac/error.h"
#include "cohfrac/export.h"
#include "cohfrac/h5_output.h"
#include "cohfrac/mesh.h"
#include "cohfrac/scene.h"
#include "cohfrac/settings.h"
#include "cohfrac/sim.h"
#include "cohfrac/surface.h"
#include "cohfrac/tetmesh.h"
#include "cohfrac/types.h"
#include "cohfrac/version.h"
#include "cohfrac/world.h"

#endif
