"""Post-processing: reads the scene datasets and never imports the simulator (pyproject.toml's
import contracts; numba is never loaded).

- :mod:`.measure`, :mod:`.fits`, :mod:`.regions`, :mod:`.torque`: what is measured on one rod;
- :mod:`.ensembles`: seed ensembles (statistics, paired changes, final states);
- :mod:`.run_checks`: is a stored run the one the config asks for, and is it at equilibrium;
- :mod:`.figure_quantities`: the figure datasets' quantities (name, symbol, unit) and the
  parameters a figure states;
- :mod:`.figures`: one module per figure kind (dataset builder and plot), :mod:`.postprocess`
  (a figure's scene files -> its dataset) and :mod:`.plotting` (the shared style).
"""
