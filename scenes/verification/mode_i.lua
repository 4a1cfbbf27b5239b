-- Mode-I separation of a bar through one pre-selected facet plane (z = 0):
-- cohesive elements are inserted there, and only there, when the facet
-- traction reaches sigma_max.
-- Explicit Tet4 + extrinsic PPR, no PBD.  The two end faces are pulled apart
-- at 0.05 m/s each; once every node pair has failed, the dissipated energy
-- is G_I x area = 22 N/m x 0.01 m^2 = 0.22 J.
return {
  name = "mode_i",
  duration = 0.12,
  gravity = {0, 0, 0},
  material = { E = 1e6, nu = 0.25, rho = 1000, G_I = 22, sigma_max = 1e4, alpha = 2 },
  bodies = { {
    mesh = { type = "box", size = {0.1, 0.1, 0.4}, cells = {2, 2, 8}, tets_per_cell = 6 },
  } },
  boundary = {
    { region = { type = "plane", point = {0, 0, -0.2}, normal = {0, 0, 1} }, velocity = {0, 0, -0.05} },
    { region = { type = "plane", point = {0, 0,  0.2}, normal = {0, 0, 1} }, velocity = {0, 0,  0.05} },
  },
  solver = {
    mode = "fracture", constraints = "none", criterion = "traction",
    crack_growth = "all",  -- the crack plane is prescribed: every facet on it that qualifies
    crack_plane = { point = {0, 0, 0}, normal = {0, 0, 1} },
    dt_rigid = 1e-3, cfl_fraction = 0.1,
  },
  output = { file = "out/mode_i.h5", frame_interval = 1e-3 },
}
