-- Source Fig 6.9: a falling plate with k_damping = 0 "completely deforms"
-- when it hits the ground at t = 0.55 s; Fig 6.10 (plate_damping_kd1.lua)
-- is the same drop with k_damping = 1, where it stays rigid.
-- The source's rigid mode (rigid_backend "pbd"): the plate stays in the
-- explicit solver at the rigid step with internal forces off, held only by
-- the PBD bars (k_stiffness 0.9, 3 iterations) and by global damping
-- k_damping; no fracture (criterion "none", so an impact never switches it
-- to fracture mode).  The source prints no material, size or time step
-- here: rho 2400 kg/m^3 (E does not act in this mode), a 1 x 1 x 0.05 m
-- plate tilted 15 degrees about x (an edge lands first), dt 1 ms; the drop
-- height makes the first contact at t = 0.55 s as in the source.
-- The pair differs in one value: --set solver.pbd.k_damping=1 gives kd1.
-- Expected: kd0 deforms at the impact; kd1 lands as a rigid plate.  Measured
-- here: mean non-rigid kinetic energy 9.1 J (kd0) against 0.51 J (kd1); both
-- end lying flat (material restitution 0: no bounce).
-- Finer mesh: --set bodies[1].mesh.mesh_size=0.025 (18,109 tets; default 4,918)
-- Wall time here (2 shared cores, tools/scene_times.sh): < 1 s.
return {
  name = "plate_damping_kd0",
  duration = 1.0,
  material = { E = 1e5, nu = 0.3, rho = 2400 },
  bodies = { {
    mesh = { type = "plate", size = {1, 1, 0.05}, mesh_size = 0.04 },
    orientation = {0.9914448613738104, 0.1305261922200516, 0, 0},   -- 15 deg about x
    -- lowest edge 0.5 sin15 + 0.025 cos15 = 0.1535 m below the centre;
    -- it falls 9.81 x 0.55^2 / 2 = 1.4837 m before the contact
    position = {0, 0, 1.4837 + 0.1535},
  } },
  obstacles = { { type = "plane", point = {0, 0, 0}, normal = {0, 0, 1} } },
  solver = {
    rigid_backend = "pbd", criterion = "none",
    dt_rigid = 1e-3,
    pbd = { k_stiffness = 0.9, iterations = 3, k_damping = 0.0 },
  },
  output = { file = "out/plate_damping_kd0.h5", frame_interval = 0.01 },
}
