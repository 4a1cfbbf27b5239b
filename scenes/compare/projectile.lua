-- Projectile (cohfrac compare): a box thrown at 10 m/s, 45 degrees up in
-- the x-z plane, with a slow spin about z; the centre of mass follows
-- x0 + v0 t + g t^2 / 2 whatever the spin.  No obstacles, no fracture.
return {
  name = "projectile",
  duration = 1.4,
  gravity = {0, 0, -9.81},
  material = { E = 1e6, nu = 0.3, rho = 1000 },
  bodies = { {
    mesh = { type = "box", size = {0.2, 0.1, 0.1}, cells = {2, 1, 1} },
    position = {0, 0, 1.0},
    velocity = {7.0710678118654755, 0, 7.0710678118654755},
    angular_velocity = {0, 0, 2},
  } },
  solver = { criterion = "none", dt_rigid = 1e-3, rigid_substeps = 5 },
  output = { file = "", frame_interval = 1e-2 },
}
