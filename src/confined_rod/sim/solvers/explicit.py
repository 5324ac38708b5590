"""Paper-faithful explicit (forward Euler) integrator of the overdamped dynamics.

The time step is dt_factor times the Gershgorin estimate of the stability limit
(model.parameters).  The kernels do the steps in chunks of about 0.1 s of work;
the stopping rules of solvers.base run between chunks.
"""
from __future__ import annotations

import numpy as np

from ..model import kernels as K
from ..model.forces import Workspace, end_points
from ..scenes import Scene
from .base import RunState, run_protocol
from .base import relax as _relax


class ExplicitStepper:
    def __init__(self, scene: Scene):
        self.par = scene.params()
        self.dt = scene.dt()
        self.ws = Workspace.for_links(scene.N)
        self.chunk = int(max(20, min(200_000, 2_000_000 // scene.N)))
        self.step_hint = f"reduce dt_factor (now {scene.dt_factor})"
        self.max_steps = scene.max_steps
        # friction at the link ends: stick springs k_t per end, as in the implicit solver
        self.ends = scene.friction_at == "ends" and scene.k_fr > 0.0
        self.kt = scene.k_t
        n2 = 2 * scene.N
        self.Ne, self.fmax, self.pf = np.zeros(n2), np.zeros(n2), np.zeros((n2, 3, 3))

    def advance(self, st: RunState, t_stop: float) -> int:
        nsteps = int(min(self.chunk, max(1, np.ceil((t_stop - st.time) / self.dt - 1e-9))))
        if self.max_steps:  # stop exactly at the step budget
            nsteps = max(1, min(nsteps, self.max_steps - st.steps))
        ws = self.ws
        if self.ends:
            if st.anchor is None:
                st.anchor = end_points(st.r, st.t, self.par[K.HALF])
            done, code = K.explicit_steps_ends(st.r, st.t, self.par, self.dt, nsteps, self.kt, st.anchor, self.Ne,
                                               self.fmax, self.pf, ws.Fm, ws.Fp, ws.F, ws.M, ws.Nw, ws.Ff, ws.stuck)
        else:
            done, code = K.explicit_steps(st.r, st.t, self.par, self.dt, nsteps, ws.Fm, ws.Fp, ws.F, ws.M,
                                          ws.Nw, ws.Ff, ws.stuck)
        st.steps += done
        st.time += done * self.dt
        return code


def relax(scene: Scene, st: RunState, *, t_end: float | None = None, progress: bool = True,
          label: str = "") -> RunState:
    """Integrate until equilibrium, escape, or the time cap (t_end or scene.t_max)."""
    return _relax(scene, st, ExplicitStepper(scene), t_end=t_end, progress=progress, label=label)


def run(scene: Scene, *, progress: bool = True) -> RunState:
    """Run the scene's protocol from its initial state."""
    return run_protocol(scene, ExplicitStepper, progress=progress)
