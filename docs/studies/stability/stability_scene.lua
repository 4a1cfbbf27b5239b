-- Written by `cohfrac stability`: the base case (see cohfrac/stability.h).
return {
  name = 'stability', duration = 1, gravity = {0, 0, 0},
  material = {E = 1e6, nu = 0.25, rho = 2400, G_I = 1, sigma_max = 1,
              friction = 0.5, restitution = 0},
  bodies = {{mesh = {type = 'box', size = {0.1, 0.1, 0.1}, cells = {3, 3, 3},
                     tets_per_cell = 6},
             position = {0, 0, 0.05}, velocity = {0, 0, -10}}},
  obstacles = {{type = 'plane', point = {0, 0, 0}, normal = {0, 0, 1}}},
  solver = {mode = 'fracture', criterion = 'none', cfl_fraction = 1, threads = 1,
            guard = {max_energy_growth = 0.1, max_inverted_fraction = 0.01}},
  output = {file = ''},
}
