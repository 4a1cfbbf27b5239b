-- Free vibration of an elastic block: explicit Tet4, no PBD, no gravity.
-- A uniform expansion velocity field starts the breathing mode; the total
-- energy (kinetic + strain) must stay constant: drift < 0.1% over 10,000
-- steps at dt = 0.5 dt_cfl.
return {
  name = "vibration",
  duration = 0.2,
  gravity = {0, 0, 0},
  material = { E = 1e6, nu = 0.3, rho = 1000 },
  bodies = { {
    mesh = { type = "box", size = {0.2, 0.2, 0.2}, cells = {4, 4, 4}, tets_per_cell = 6 },
    expansion_rate = 0.5,            -- 1/s: v = 0.5 (x - x_com)
  } },
  solver = {
    mode = "fracture", constraints = "none", criterion = "none",
    dt_rigid = 1e-3, cfl_fraction = 0.5,
  },
  output = { file = "out/vibration.h5", frame_interval = 1e-3 },
}
