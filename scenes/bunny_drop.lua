-- The source's headline scene (Fig 6.3): the Stanford bunny falls under
-- gravity as a rigid body, hits the ground, breaks in fracture mode and its
-- fragments fly on as rigid bodies.  Parameters as printed in the source:
-- E = 0.6 Pa, nu = 0.23, rho = 2400 kg/m^3, G_I = 22 N/m, sigma_max = 0.1 mPa,
-- alpha = 2; dt 1e-3 s rigid / 5 us fracture; PBD k = 0.9, k_damping = 1,
-- 3 iterations; cohesive elements inserted by the source's rule (nodal
-- maximum principal stress >= 0.9 sigma_max at the facet's three nodes).
-- The source gives no size or drop height: here the mesh's own units are
-- metres (the bunny is 2 m tall) and it falls 1 m (its lowest point starts
-- at z = 1 m; from 0.5 m the small bunny does not crack).
-- Default mesh: the coarse `bunny_small` (14,390 tets; `make run`), about
-- 10 s here.  Source scale (the source's bunny has 208,353 tets; ours
-- 202,404): --set 'bodies[1].mesh="bunny"', about 8 minutes on 2 threads
-- (see the README and docs/performance.md).
-- Expected: the bunny rebounds at the impact (fracture mode is PBD with
-- k = 0.9 and 3 iterations, an almost rigid elastic body: the compression
-- wave comes back) and loses small pieces where it meets the ground:
-- bunny_small ~260 pieces of one to a few tets, the body keeping 99.4% of its mass,
-- the fastest piece ~3-4 m/s (the fall gives 4.4 m/s).  It chips; it does
-- not break into large pieces (the source's Fig 6.3 shows several): with
-- the source's parameters, Weibull strength scatter, the traction rule,
-- lower strength, softer PBD (k 0.3-0.5) or a 5 m fall, the largest piece
-- still holds 90-99% of the mass on this mesh.
return {
  name = "bunny_drop",
  duration = 0.6,
  gravity = {0, 0, -9.81},
  material = {
    E = 0.6, nu = 0.23, rho = 2400,
    G_I = 22, sigma_max = 1e-4, alpha = 2,
    friction = 0.5, restitution = 0.0,
  },
  bodies = {
    {
      mesh = "bunny_small",                   -- prepared by `make run` (~15k tets)
      scale = 1.0,                            -- the OBJ is ~2 units tall
      orientation = {0.7071067811865476, 0.7071067811865476, 0, 0},  -- y-up -> z-up
      position = {0, 0, 1.0 + 0.991233},      -- bottom 1 m above the ground
      velocity = {0, 0, 0},
      visual = "/usr/share/glmark2/models/bunny.obj",  -- the 70k-triangle surface, drawn
    },
  },
  obstacles = {
    { type = "plane", point = {0, 0, 0}, normal = {0, 0, 1} },
  },
  solver = {
    rigid_backend = "bullet",
    dt_rigid = 1e-3, rigid_substeps = 5,
    dt_fracture = 5e-6, check_interval = 1, quiet_steps = 400,
    elasticity = "corotational", criterion = "source",
    impact_threshold = 1.0,   -- m/s: the first impact is 3.1 m/s; settling fragments stay rigid
    pbd = { k_stiffness = 0.9, iterations = 3, k_damping = 1.0 },
  },
  output = { file = "out/bunny_drop.h5", frame_interval = 0.005 },
}
