-- A free spinning asymmetric box (no gravity, nothing to touch), 0.3 x 0.2
-- x 0.1 m, spinning at 5 rad/s about its major axis with a small wobble
-- (0.5 rad/s about the others), for 2 s in rigid mode.  A rigid body keeps
-- its angular momentum and energy exactly; tests/verify_spin.c measures
-- what each rigid backend keeps (set solver.rigid_backend) and that none
-- of it is booked as contact.
return {
  name = "free_spin",
  duration = 2.0,
  gravity = {0, 0, 0},
  material = { E = 1e6, nu = 0.3, rho = 1000 },
  bodies = { {
    mesh = { type = "box", size = {0.3, 0.2, 0.1}, cells = {3, 2, 1} },
    angular_velocity = {0.5, 0.5, 5.0},
  } },
  solver = { rigid_backend = "bullet", dt_rigid = 1e-3, criterion = "none" },
  output = { file = "out/free_spin.h5", frame_interval = 0.1 },
}
