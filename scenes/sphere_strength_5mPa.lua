-- Source Fig 6.11(a): the cohesive strength sets how much a falling sphere
-- breaks; the text: "The sphere collides and breaks with smax = 5 mPa".
-- The chapter's values (E = 100 Pa, sigma_max = 5 mPa, G_I = 22 N/m) cannot
-- break it: the final opening alpha G_I / sigma_max is 8.8 km, so no
-- cohesive element ever fails, and the shear wave runs at centimetres per
-- second (docs/scenes.md).  Kept from the chapter: the ratio
-- E / sigma_max = 20,000, nu 0.1, rho 2400 kg/m^3, alpha 2, the sphere
-- (radius 0.5 m, our geometry) and its 1 m fall (4.4 m/s at t = 0.45 s).
-- Chosen: a stiff brittle solid, E 30 GPa and sigma_max 1.5 MPa (E / sigma
-- as the chapter's), G_I 15 N/m, so the cohesive length E G_I / sigma^2 is
-- 0.2 m, a fifth of the diameter (the plaster spheres of
-- docs/physics.md §15 have 50 mm against 12.5 mm); a Weibull strength
-- field (modulus 6) and crushing at 7.5 sigma_max, as the plaster.
-- Method: the explicit fracture mode of the plaster drop
-- (plaster_bunny_drop.lua): constraints "none" at 0.5 dt_cfl, penalty floor.
-- The chapter's own values:
--   --set material.E=100 --set material.sigma_max=5e-3 --set material.G_I=22
--   --set material.compressive_strength=0 --set solver.constraints="pbd"
--   --set solver.cfl_fraction=0 --set solver.obstacle_contact="kinematic"
-- Expected (2026-11-29, seed 1): 131 fragments, 2 pieces of at least 5 %
-- (34.6, 13.9 %), 12 of at least 1 %, no chip, 34 % of the mass as
-- debris; 9.0 kJ of the 12.1 kJ input go into crushing; the fastest piece
-- 4.0 m/s against the bound 8.3 m/s.  Seeds 2 and 3 give 2 and 3 pieces
-- of at least 5 %.  Wall time: about 5 s.
-- Finer mesh: --set bodies[1].mesh.mesh_size=0.07 (7,458 tets; default 2,704)
return {
  name = "sphere_strength_5mPa",
  duration = 0.6,               -- 0.15 s after the impact
  material = {
    E = 3e10, nu = 0.1, rho = 2400, G_I = 15, sigma_max = 1.5e6, alpha = 2,
    friction = 0.5, restitution = 0.0, compressive_strength = 11.25e6,
    strength = {distribution = "weibull", modulus = 6, seed = 1},
  },
  bodies = { {
    mesh = { type = "sphere", radius = 0.5, mesh_size = 0.1 },
    position = {0, 0, 1.5},
  } },
  obstacles = { { type = "plane", point = {0, 0, 0}, normal = {0, 0, 1} } },
  solver = {
    dt_rigid = 2e-3,
    impact_threshold = 1.0,   -- m/s: the impact is 4.4 m/s; settling pieces stay rigid
    check_interval = 1, quiet_steps = 500,
    elasticity = "corotational", criterion = "source",
    constraints = "none", cfl_fraction = 0.5,
    obstacle_contact = "penalty",
    debris_size = 0.2,        -- l_ch: pieces narrower are debris (docs/physics.md §9.2)
    pbd = { k_stiffness = 0.9, iterations = 3, k_damping = 1.0 },  -- the chapter's, with "pbd"
  },
  output = { file = "out/sphere_strength_5mPa.h5", frame_interval = 0.01 },
}
