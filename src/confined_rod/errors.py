"""Exceptions raised by confined_rod."""
from __future__ import annotations

from .scenes import SceneError


class DivergenceError(RuntimeError):
    """A run produced non-finite values or ran away. The message names the
    scene, the step and the simulated time."""


__all__ = ["SceneError", "DivergenceError"]
