-- Momentum through insertion, node duplication and hand-off: a free block
-- (no gravity, no obstacles) moving at 1 m/s and expanding at 40 1/s tears
-- itself apart in fracture mode (explicit, no PBD), then is handed to the
-- pbd rigid backend.  Every internal force (Tet4, cohesive, PBD bars) comes in equal and opposite pairs and node copies keep their
-- velocity, so the total linear momentum stays M v to round-off.
return {
  name = "momentum",
  duration = 0.01,
  gravity = {0, 0, 0},
  material = { E = 1e6, nu = 0.25, rho = 1000, G_I = 1, sigma_max = 2e3 },
  bodies = { {
    mesh = { type = "box", size = {0.2, 0.2, 0.2}, cells = {3, 3, 3} },
    velocity = {1.0, 0.5, 0.0},
    expansion_rate = 40,
  } },
  solver = { mode = "fracture", constraints = "none", dt_rigid = 1e-4, cfl_fraction = 0.5 },
  output = { file = "out/momentum.h5", frame_interval = 1e-4 },
}
