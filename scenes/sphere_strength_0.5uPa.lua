-- Source Fig 6.11(b): the same sphere as Fig 6.11(a)
-- (sphere_strength_5mPa.lua) with a lower cohesive strength; the text: it
-- "breaks even more".  The chapter prints 0.5 uPa (the caption 500 mPa):
-- E / sigma_max = 2e8, a solid whose strength is eight orders of
-- magnitude below rho g R; with any mesh the chapter's values cut every
-- tet loose at the first contact (docs/scenes.md).
-- Chosen: Fig 6.11(a)'s solid (E 30 GPa, nu 0.1, rho 2400 kg/m^3, crushing
-- at 11.25 MPa, Weibull modulus 6) at half its strength, sigma_max
-- 0.75 MPa, with the cohesive length kept at 0.2 m (G_I 3.75 N/m): the
-- pair differs in strength, as the chapter's does, and not in how finely
-- the mesh resolves the cohesive zone.
-- Method: as Fig 6.11(a).
-- The chapter's own values:
--   --set material.E=100 --set material.sigma_max=5e-7 --set material.G_I=22
--   --set material.compressive_strength=0 --set solver.constraints="pbd"
--   --set solver.cfl_fraction=0 --set solver.obstacle_contact="kinematic"
-- Expected (2026-11-29, seed 1): 148 fragments, 6 pieces of at least 5 %
-- (8.8, 6.6, 6.2, 5.3, 5.2, 5.1 %), 17 of at least 1 % (12 at Fig
-- 6.11(a)'s strength), no chip, 38 % of the mass as debris; the fastest
-- piece 4.8 m/s against the bound 8.3 m/s.  Seeds 2 and 3 give 10 and 15
-- pieces of at least 1 %, against 17 and 16 at 6.11(a)'s strength, though
-- more crack area (docs/scenes.md).  Wall time: about 5 s.
return {
  name = "sphere_strength_0.5uPa",
  duration = 0.6,               -- 0.15 s after the impact
  material = {
    E = 3e10, nu = 0.1, rho = 2400, G_I = 3.75, sigma_max = 0.75e6, alpha = 2,
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
  output = { file = "out/sphere_strength_0.5uPa.h5", frame_interval = 0.01 },
}
