"""confined_rod: an elastic rod pushed into a frictional cylindrical pore.

Reproduces D. Svensek and R. Podgornik, "Confined nanorods: jamming due to
helical buckling", with a discrete rod of rigid links, soft joints, a penalty
wall and Coulomb wall friction relaxed by overdamped dynamics.

    from confined_rod import Scene, simulate
    ds = simulate(Scene(L=40, load=0.25, k_fr=0.8))

``Scene`` and ``simulate`` are imported on first use, so that post-processing
(``confined_rod.analysis.figures``, ``confined_rod.analysis.measure``) never loads the simulator.
"""
from ._version import __version__  # noqa: E402
from .errors import ConfigError, DivergenceError, SceneError  # noqa: E402

__all__ = ["Scene", "simulate", "SceneError", "ConfigError", "DivergenceError", "__version__"]


def __getattr__(name):
    if name == "Scene":
        from .sim.scenes import Scene

        return Scene
    if name == "simulate":
        from .sim.simulation import simulate

        return simulate
    raise AttributeError(f"module 'confined_rod' has no attribute {name!r}")
