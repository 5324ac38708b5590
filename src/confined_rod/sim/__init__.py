"""The simulator: a discrete rod of rigid links with soft joints, a penalty wall and Coulomb wall
friction, relaxed to equilibrium by overdamped dynamics.

- :mod:`.scenes`: ``Scene``, every parameter of a run, validated (``limits``) before any work;
- :mod:`.model`: the forces (numba kernels, one job each, with a numpy energy twin);
- :mod:`.solvers`: the paper's forward Euler and a backward Euler with Newton and a banded solve;
- :mod:`.simulation`: ``simulate(scene)`` -> a scene dataset (:mod:`.observables`);
- :mod:`.probe`, :mod:`.load_paths`, :mod:`.runs`: what the rules run (a stability-map point, a
  load sweep or thresholds by bisection, one scene or a batch of scenes).

It imports none of the other parts (analysis, claims, pipeline): pyproject.toml's import contracts.
"""
