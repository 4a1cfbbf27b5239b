-- An elastic block hits a plane corner first, in fracture mode only with
-- explicit elasticity (no constraints, no insertion): 0.1 m plaster-like
-- cube (E 5 GPa, rho 1200 kg/m^3), tilted, at 4.4 m/s down and 1 m/s
-- sideways, friction 0.5.  Nothing but the contact takes energy out, so the
-- ledger (kinetic + strain + contact's removal) must equal the input to
-- round-off and the leapfrog's own error (tests/verify_elastic_impact.c).
-- `friction = 0` and a flat landing are the other cases the test runs.
return {
  name = "elastic_impact",
  duration = 0.0012,
  gravity = {0, 0, 0},   -- the impact alone (the test's resting case sets a body force)
  material = { E = 5e9, nu = 0.2, rho = 1200, friction = 0.5, restitution = 0.0 },
  bodies = { {
    mesh = { type = "box", size = {0.1, 0.1, 0.1}, cells = {6, 6, 6} },
    position = {0, 0, 0.0755},              -- lowest corner 1 mm above the plane
    orientation = {0.96, 0.2, 0.1, 0},
    velocity = {1, 0, -4.4},
  } },
  obstacles = { { type = "plane", point = {0, 0, 0}, normal = {0, 0, 1} } },
  solver = { mode = "fracture", constraints = "none", criterion = "none",
             cfl_fraction = 0.5, dt_rigid = 1e-5 },
  output = { file = "out/elastic_impact.h5", frame_interval = 1e-4 },
}
