-- Source Fig 6.3 with the parameters as the chapter prints them: the
-- Stanford bunny (`bunny_small`, 15,040 tets; 2 m tall, the mesh's own
-- units) dropped 1 m; E = 0.6 Pa, nu = 0.23, rho = 2400 kg/m^3,
-- G_I = 22 N/m, sigma_max = 0.1 mPa, alpha = 2; dt 1e-3 s rigid / 5 us
-- fracture; fracture mode PBD with k = 0.9, k_damping = 1, 3 iterations;
-- cohesive elements inserted by the source's rule.
-- It lands whole: the final opening alpha G_I / sigma_max is 440 km, so no
-- cohesive element ever fails, and the hand-off keeps what still holds
-- (docs/scenes.md).  scenes/bunny_drop.lua is the figure with parameters
-- that break it.  This one is for the source's method itself: the PBD
-- studies (studies/bunny_drop.sh, rigid_dt.sh), the two rigid backends
-- (`cohfrac compare`), the source-scale timing
-- (--set 'bodies[1].mesh="bunny"', README) and the reliability tests,
-- which need a run through every stage for several seconds.
return {
  name = "source_bunny_drop",
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
  output = { file = "out/source_bunny_drop.h5", frame_interval = 0.005 },
}
