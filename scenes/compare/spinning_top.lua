-- Torque-free symmetric top (cohfrac compare): a 0.1 x 0.1 x 0.3 m box
-- (two equal principal moments about x and y, I_1 = M (0.1^2 + 0.3^2)/12
-- for a continuum; the engine uses the lumped nodal moments) spinning at
-- 20 rad/s about its long axis with a 3 rad/s tilt.  Its symmetry axis
-- precesses about the constant angular momentum L at Omega_p = |L| / I_1
-- (about 5 rad/s here); gravity gives no torque about the centre of mass,
-- so the centre of mass free-falls meanwhile.  No obstacles: no fracture.
-- tets_per_cell = 5: the checkerboard cells keep the lumped moments about x
-- and y equal (the 6-tet Kuhn cells split them by 4 %, no longer a top).
-- Measured with dt_rigid = 1e-3 s (Omega_p = 6.225 rad/s from the lumped
-- moments): Bullet 6.202 rad/s (0.37 % low), pbd 5.565 rad/s (10.6 % low:
-- the damped-PBD rigid step loses ~18 % of L over the run); both errors are
-- first order in dt_rigid.  tests/verify_compare.c holds Bullet to 1 % and
-- pbd to 15 %.
return {
  name = "spinning_top",
  duration = 1.5,
  gravity = {0, 0, -9.81},
  material = { E = 1e6, nu = 0.3, rho = 1000 },
  bodies = { {
    mesh = { type = "box", size = {0.1, 0.1, 0.3}, cells = {2, 2, 6}, tets_per_cell = 5 },
    position = {0, 0, 1.0},
    angular_velocity = {0, 3, 20},
  } },
  solver = { criterion = "none", dt_rigid = 1e-3, rigid_substeps = 5 },
  output = { file = "", frame_interval = 5e-3 },
}
