"""confined_rod: an elastic rod pushed into a frictional cylindrical pore.

Reproduces D. Svensek and R. Podgornik, "Confined nanorods: jamming due to
helical buckling", with a discrete rod of rigid links, soft joints, a penalty
wall and Coulomb wall friction relaxed by overdamped dynamics.

    from confined_rod import Scene, simulate
    ds = simulate(Scene(L=40, load=0.25, k_fr=0.8))
"""
__version__ = "0.1.0"

from .errors import DivergenceError, SceneError  # noqa: E402
from .scenes import Scene  # noqa: E402
from .simulation import simulate  # noqa: E402

__all__ = ["Scene", "simulate", "SceneError", "DivergenceError", "__version__"]
