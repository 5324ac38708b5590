"""Time integrators of the overdamped dynamics and the stopping rules they share."""
from . import explicit, implicit

SOLVERS = {"explicit": explicit.run, "implicit": implicit.run}
