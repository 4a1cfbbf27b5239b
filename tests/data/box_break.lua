-- A soft, brittle 0.2 m cube dropped 1 m onto the ground (tests of the
-- output's geometry): it cracks at the 4.4 m/s impact (about 0.06 m^2 of
-- cohesive facets) but stays one body: no piece is cut free of shared
-- nodes and unfailed cohesive elements (the hand-off keeps such pieces
-- together).  examples/drop.c lowers the strength and G_I so that it
-- comes apart.
return {
  name = "box_break",
  duration = 0.6,
  material = { E = 1e5, sigma_max = 3e3 },
  bodies = { { mesh = { type = "box", size = {0.2, 0.2, 0.2}, cells = {4, 4, 4} },
               position = {0, 0, 1} } },
  obstacles = { { type = "plane", point = {0, 0, 0}, normal = {0, 0, 1} } },
  solver = { constraints = "xpbd" },
  output = { file = "out/box_break.h5", frame_interval = 0.01 },
}
