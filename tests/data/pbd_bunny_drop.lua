-- A long, busy run for the reliability tests (tests/reliability.sh,
-- sigkill.sh, failalloc.sh): the source's Fig 6.3 parameters as printed
-- (E = 0.6 Pa, nu = 0.23, rho = 2400 kg/m^3, G_I = 22 N/m,
-- sigma_max = 0.1 mPa, alpha = 2; fracture mode PBD with k = 0.9,
-- k_damping = 1, 3 iterations, dt 5 us) on the 14k-tet `bunny_small`,
-- dropped 1 m.  It goes through every stage (Bullet, the hand-off,
-- fracture mode with insertion, HDF5 output) for several seconds of wall
-- time, which is what the tests need; it does not break (the cohesive law
-- never lets go at these values: scenes/bunny_drop.lua and docs/scenes.md).
return {
  name = "pbd_bunny_drop",
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
  output = { file = "out/pbd_bunny_drop.h5", frame_interval = 0.005 },
}
