-- Source Fig 6.3, the chapter's headline scene: the Stanford bunny falls
-- under gravity as a rigid body, hits the ground, breaks in fracture mode,
-- and "each separate component of the bunny will be treated as a rigid
-- body" afterwards.  The source gives no size or drop height: here the
-- mesh's own units are metres (the bunny is 2 m tall) and its lowest point
-- falls 1 m (4.4 m/s at t = 0.45 s).
-- The chapter's values (E = 0.6 Pa, sigma_max = 0.1 mPa, G_I = 22 N/m) cannot
-- break it: the final opening alpha G_I / sigma_max is 440 km, so no
-- cohesive element ever fails (docs/scenes.md).  Kept from the chapter: the
-- ratio E / sigma_max = 6,000, nu 0.23, rho 2400 kg/m^3, alpha 2.
-- Chosen: a weak brittle stone, E 3 GPa and sigma_max 0.5 MPa (E / sigma as
-- the chapter's), G_I 10 N/m, so the cohesive length E G_I / sigma^2 is
-- 0.12 m, 6 % of the height; a Weibull strength field (modulus 6) and
-- crushing at 3.75 MPa (7.5 sigma_max, as the plaster).
-- Method: the explicit fracture mode of the plaster drop
-- (plaster_bunny_drop.lua): constraints "none" at 0.5 dt_cfl, penalty floor.
-- Mesh: the bunny at about 4,000 tets (`bunny_4k`, 3,867 tets on its
-- remeshed surface; dt_cfl 10.6 us, docs/physics.md §3.1).
-- The chapter's own values, on the chapter's PBD fracture mode:
--   --set material.E=0.6 --set material.sigma_max=1e-4 --set material.G_I=22
--   --set material.compressive_strength=0 --set solver.constraints="pbd"
--   --set solver.cfl_fraction=0 --set solver.dt_fracture=5e-6
--   --set solver.obstacle_contact="kinematic" --set solver.debris_size=0
-- (it lands whole; scenes/source/bunny_drop.lua runs it on bunny_small).
-- Expected (2026-11-29, seed 1): 188 fragments, 3 pieces of at least 5 %
-- (19.6, 14.6, 10.0 %), 11 of at least 1 %, no chip, 0.1 % of the mass as
-- debris; 26.6 kJ go into crushing the base and 0.33 kJ into the cracks;
-- the fastest piece 5.9 m/s against the bound 9.9 m/s; about 8 s on two
-- threads.  Seeds 2 and 3 give 4 pieces (11.9, 10.0, 6.9, 5.0 %) and
-- 3 (11.1, 9.5, 7.2 %).
return {
  name = "bunny_drop",
  duration = 0.6,               -- 0.15 s after the impact
  gravity = {0, 0, -9.81},
  material = {
    E = 3e9, nu = 0.23, rho = 2400,
    G_I = 10, sigma_max = 0.5e6, alpha = 2,
    friction = 0.5, restitution = 0.0,
    compressive_strength = 3.75e6,
    strength = {distribution = "weibull", modulus = 6, seed = 1},
  },
  bodies = {
    {
      mesh = "bunny_4k",                      -- prepared by `make run` (3,858 tets)
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
    dt_rigid = 2e-3,
    impact_threshold = 1.0,   -- m/s: the impact is 4.4 m/s; settling pieces stay rigid
    check_interval = 1, quiet_steps = 500,
    elasticity = "corotational", criterion = "source",
    constraints = "none", cfl_fraction = 0.5,
    obstacle_contact = "penalty",
    debris_size = 0.12,       -- l_ch: pieces narrower are debris (docs/physics.md §9.2)
    pbd = { k_stiffness = 0.9, iterations = 3, k_damping = 1.0 },  -- the chapter's, with "pbd"
  },
  output = { file = "out/bunny_drop.h5", frame_interval = 0.005 },
}
