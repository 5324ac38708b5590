"""Time integrators of the overdamped dynamics and the stopping rules."""
from . import explicit

SOLVERS = {"explicit": explicit.run}
