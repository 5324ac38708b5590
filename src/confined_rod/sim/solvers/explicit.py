"""Paper-faithful explicit (forward Euler) integrator of the overdamped dynamics.

The time step is dt_factor times the Gershgorin estimate of the stability limit
(model.parameters).  The kernels do the steps in chunks of about 0.1 s of work;
the stopping rules of solvers.base run between chunks.
"""
from __future__ import annotations

import numpy as np

from ..model import kernels as K
from ..model.forces import Workspace
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

    def advance(self, st: RunState, t_stop: float) -> int:
        nsteps = int(min(self.chunk, max(1, np.ceil((t_stop - st.time) / self.dt - 1e-9))))
        if self.max_steps:  # stop exactly at the step budget
            nsteps = max(1, min(nsteps, self.max_steps - st.steps))
        ws = self.ws
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
