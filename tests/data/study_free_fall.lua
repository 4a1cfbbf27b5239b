-- A box in free fall in fracture mode (no obstacles, no insertion): the
-- in-house solver's symplectic Euler puts the centre of mass at
-- x0 + g t^2/2 + g t dt/2, so two runs with steps dt1 and dt2 are
-- |g| t |dt1 - dt2| / 2 apart at time t (test_study.c).
return {
  name = "study_free_fall",
  duration = 0.1,
  gravity = {0, 0, -9.81},
  material = { E = 1e3, nu = 0.25, rho = 1000 },
  bodies = { { mesh = { type = "box", size = {0.1, 0.1, 0.1} } } },
  solver = { mode = "fracture", criterion = "none", dt_rigid = 1e-3, dt_fracture = 1e-4 },
  output = { file = "", frame_interval = 0.01 },
}
