/* cohfrac — a run's fragments for other tools.
 *
 * cf_export_gltf reads an output file (docs/output.md) and writes glTF 2.0
 * binary (.glb) through tinygltf: one node per fragment with its rest
 * surface in its body frame (vertices X - com_rest) as its mesh, coloured
 * by fragment, its crack faces a second primitive with the material
 * "crack", its record in the node's extras (fragment, mass kg, parent,
 * birth_time s, n_tets, debris, mode at its last frame: 0 rigid,
 * 1 fracture), and one animation with a translation, rotation and scale
 * channel per fragment, keyed at every output frame: the pose while it is
 * alive, scale 0 before its birth and after it splits (step keys), so a
 * fragment shows from its birth time.  Key times are the run's times
 * times `slow_motion` (1: real time; 100: a 2 ms break plays for 0.2 s).  glTF is +y up: cohfrac's (x, y, z)
 * becomes (x, z, -y) (Blender's importer turns it back to +z up).
 * Errors: CF_ERR_FILE_OPEN (the .h5 is missing or not HDF5),
 * CF_ERR_MESH_PARSE (it holds no geometry: written by an older cohfrac),
 * CF_ERR_OUTPUT (the .glb cannot be written), CF_ERR_USAGE (slow_motion
 * not > 0), CF_ERR_NOMEM. */
#ifndef COHFRAC_EXPORT_H
#define COHFRAC_EXPORT_H

#include "cohfrac/error.h"

cf_status cf_export_gltf(const char *h5_path, const char *glb_path, double slow_motion,
                         cf_error *err);

#endif
