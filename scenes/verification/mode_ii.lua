-- Mode-II separation of a block through one pre-selected facet plane
-- (z = 0; insertion there when the shear traction reaches tau_max): the top
-- face slides at +0.05 m/s and the bottom at -0.05 m/s
-- along x.  Explicit Tet4 + extrinsic PPR, no PBD.  Once every node pair has
-- failed, the dissipated energy is G_II x area = 44 N/m x 0.04 m^2 = 1.76 J
-- (G_II = 2 G_I, so the figure shows the mode-II energy is the one used).
return {
  name = "mode_ii",
  duration = 0.2,
  gravity = {0, 0, 0},
  material = { E = 1e6, nu = 0.25, rho = 1000, G_I = 22, G_II = 44,
               sigma_max = 1e4, tau_max = 1e4, alpha = 2, beta = 2 },
  bodies = { {
    mesh = { type = "box", size = {0.2, 0.2, 0.04}, cells = {4, 4, 2}, tets_per_cell = 6 },
  } },
  boundary = {
    { region = { type = "plane", point = {0, 0, -0.02}, normal = {0, 0, 1} }, velocity = {-0.05, 0, 0} },
    { region = { type = "plane", point = {0, 0,  0.02}, normal = {0, 0, 1} }, velocity = { 0.05, 0, 0} },
  },
  solver = {
    mode = "fracture", constraints = "none", criterion = "traction",
    crack_growth = "all",  -- the crack plane is prescribed: every facet on it that qualifies
    crack_plane = { point = {0, 0, 0}, normal = {0, 0, 1} },
    dt_rigid = 1e-3, cfl_fraction = 0.1,
  },
  output = { file = "out/mode_ii.h5", frame_interval = 1e-3 },
}
