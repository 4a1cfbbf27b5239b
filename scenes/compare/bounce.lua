-- Free fall and bounce of a rigid box on a plane (cohfrac compare; the
-- scene of scenes/verification/bounce.lua): restitution 0.5, no friction,
-- no fracture (criterion "none").  Reference: a point at the centre of mass,
-- at the box's half height above the plane at contact, dropped from 1 m and
-- bouncing with e = 0.5 (apex at e^2 of the drop height), compared up to
-- the second contact.
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
  output = { file = "", frame_interval = 2e-3 },
}
