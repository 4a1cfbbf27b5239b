-- Source Fig 6.6: the mixed-mode beam, as scenes/verification/mixed_mode_beam.lua
-- (kept in step with it by hand: scenes cannot include one another).
-- A beam with an edge notch off mid-span on two supports, struck at
-- mid-span at 25 m/s.  E 9 MPa, nu 0.24, rho 2400, G_I 22 N/m, sigma_max
-- 8 kPa, alpha 2; PBD k = 1, 4 iterations, insertion checked every 10
-- steps, dt = 3e-5 s for 300 steps (the source: 1,000x its explicit step).
-- Geometry is ours (0.4 x 0.05 x 0.1 m, notch 0.025 m deep at x = +0.05 m).
-- Expected (source): stable at that step; the crack leaves the notch at
-- about 30 degrees.
-- Source scale (25,777 nodes / 113,984 tets): --set bodies[1].mesh.mesh_size=0.0045
-- (21,230 nodes / 106,077 tets here)
-- Coarser and faster: --set bodies[1].mesh.mesh_size=0.012
-- Wall time here (2 shared cores, tools/scene_times.sh): 19 s.
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
    dt_rigid = 3e-4, dt_fracture = 3e-5,
    pbd = { k_stiffness = 1.0, iterations = 4, k_damping = 0 },
  },
  output = { file = "out/mixed_mode_beam.h5", frame_interval = 3e-4 },
}
