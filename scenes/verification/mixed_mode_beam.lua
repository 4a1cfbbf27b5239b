-- The source's mixed-mode beam (Fig 6.6): a beam with an edge notch off
-- mid-span, on two supports, struck at mid-span at 25 m/s.  PBD with
-- k_stiffness = 1 and 4 iterations, insertion checked every 10 steps,
-- dt = 3e-5 s for 300 steps: about 1,000x the explicit step the source
-- needed.  The source reports a stable run and a crack leaving the notch at
-- about 30 degrees.  E 9 MPa, nu 0.24, rho 2400, G_I 22 N/m, sigma_max 8 kPa.
-- The geometry (0.4 x 0.05 x 0.1 m, notch 0.025 m deep at x = +0.05 m) is
-- ours: the source does not print it.
-- Departure: dt_fracture = 1e-5 s (0.69 dt_cfl of this mesh, 900 steps).
-- The source's 3e-5 s (2.1 dt_cfl), --set solver.dt_fracture=3e-5, runs
-- to the end without diverging (tests/verify_beam.c checks that) but is
-- not believable: the explicit Tet4 kick is unstable on the smallest tets,
-- the projection removes the energy it invents (ledger residual 68 % of
-- the input) and single tets leave at 68 m/s against the bound 55 m/s of
-- tests/checks/check_physics.py.  At 1e-5 s: residual 0.11 % (docs/physics.md
-- §14.8); a 6-tet piece from under the indenter leaves at 72 m/s, over that
-- bound (tests/plausibility_known.txt says why).
return {
  name = "mixed_mode_beam",
  duration = 0.009,
  gravity = {0, 0, 0},
  material = { E = 9e6, nu = 0.24, rho = 2400, G_I = 22, sigma_max = 8e3, alpha = 2 },
  bodies = { {
    mesh = { type = "notched_beam", size = {0.4, 0.05, 0.1},
             notch = {0.025, 0.004, 0.05}, mesh_size = 0.008 },
  } },
  boundary = {
    { region = { type = "box", min = {-0.2, -1, -0.051}, max = {-0.18, 1, -0.049} }, fixed = true },
    { region = { type = "box", min = { 0.18, -1, -0.051}, max = { 0.2, 1, -0.049} }, fixed = true, axes = "z" },
    { region = { type = "box", min = {-0.01, -1, 0.049}, max = { 0.01, 1, 0.051} }, velocity = {0, 0, -25} },
  },
  solver = {
    mode = "fracture", criterion = "source", check_interval = 10,
    dt_rigid = 3e-4, dt_fracture = 1e-5,
    pbd = { k_stiffness = 1.0, iterations = 4, k_damping = 0 },
  },
  output = { file = "out/mixed_mode_beam.h5", frame_interval = 3e-4 },
}
