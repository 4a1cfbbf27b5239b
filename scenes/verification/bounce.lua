-- Free fall and bounce of a rigid box on a plane (Bullet rigid mode, no
-- fracture).  With restitution e the apex after the first bounce is e^2
-- times the drop height (measured from the height at contact): 0.25 for
-- e = 0.5.  Before the contact the centre of mass follows z0 - g t^2 / 2.
return {
  name = "bounce",
  duration = 1.2,
  material = { E = 1e6, nu = 0.3, rho = 1000, friction = 0.0, restitution = 0.5 },
  bodies = { {
    mesh = { type = "box", size = {0.2, 0.2, 0.2}, cells = {2, 2, 2} },
    position = {0, 0, 1.0},
  } },
  obstacles = { { type = "plane", point = {0, 0, 0}, normal = {0, 0, 1} } },
  solver = { criterion = "none", dt_rigid = 1e-3, rigid_substeps = 5 },
  output = { file = "out/bounce.h5", frame_interval = 1e-3 },
}
