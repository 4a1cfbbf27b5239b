-- Elastic wave in a slender bar (explicit Tet4, no PBD, dt = 0.9 dt_cfl).
-- The end x = -0.5 m is pushed at v0 = 0.1 m/s from t = 0: a compressive
-- front travels at the bar speed c0 = sqrt(E/rho) = 100 m/s carrying the
-- stress rho c0 v0 = 1e4 Pa; it reaches x = 0.25 m at t = 0.75 L/c0 = 7.5 ms.
return {
  name = "wave_bar",
  duration = 0.012,
  gravity = {0, 0, 0},
  material = { E = 1e7, nu = 0.25, rho = 1000 },
  bodies = { {
    mesh = { type = "box", size = {1.0, 0.05, 0.05}, cells = {80, 4, 4}, tets_per_cell = 6 },
  } },
  boundary = { {
    region = { type = "plane", point = {-0.5, 0, 0}, normal = {1, 0, 0} },
    velocity = {0.1, 0, 0}, axes = "x",
  } },
  solver = {
    mode = "fracture", constraints = "none", criterion = "none",
    dt_rigid = 1e-4, cfl_fraction = 0.9,
  },
  output = { file = "out/wave_bar.h5", frame_interval = 1e-4 },
}
