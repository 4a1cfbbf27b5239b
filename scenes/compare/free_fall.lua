-- Free fall from rest (cohfrac compare): the centre of mass follows
-- x0 + g t^2 / 2 exactly; no obstacles, no rotation, no fracture.
return {
  name = "free_fall",
  duration = 1.0,
  gravity = {0, 0, -9.81},
  material = { E = 1e6, nu = 0.3, rho = 1000 },
  bodies = { {
    mesh = { type = "box", size = {0.2, 0.2, 0.2}, cells = {2, 2, 2} },
    position = {0, 0, 5.0},
  } },
  solver = { criterion = "none", dt_rigid = 1e-3, rigid_substeps = 5 },
  output = { file = "", frame_interval = 1e-2 },
}
