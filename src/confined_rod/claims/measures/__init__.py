"""The named measures of the claims (paper/claims.yaml ``test: {method: measure, name: ...}``):
each reads the evidence (datasets and scene simulations) and returns a :class:`Measured`,
(value, holds, evidence, note), where holds is True, False, or None ("inconclusive": the answer
flips with an analysis choice, a fit window or a threshold, or the data cannot decide; the note
then says why). One module per subject; importing this package registers them all in MEASURES."""
from . import force_decay, scales, states, torque_pitch  # noqa: F401  (each registers its measures)
from ._base import MEASURES, Measured, measure

__all__ = ["MEASURES", "Measured", "measure"]
