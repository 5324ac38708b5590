"""The discrete rod model: energies, forces, torques and wall friction.

* :mod:`.parameters` maps continuum constants (EI, beta_ph, k_ph) to the
  discrete ones (C, beta, gamma_r, k) -- see docs/model.md for the derivation.
* :mod:`.kernels` holds the numba kernels, one job each.
* :mod:`.reference` is a plain-numpy twin of the total energy, for tests.
"""
