"""Exceptions raised by confined_rod (no imports of the simulator: post-processing uses them too)."""
from __future__ import annotations


class SceneError(ValueError):
    """Invalid scene input. The message names the key and the offending value."""


class ConfigError(ValueError):
    """Invalid pipeline configuration; the message names the config path and the value."""


class OutputPathError(ValueError):
    """The place a result should be written to cannot take it (checked before any work)."""


class ResourceLimitError(RuntimeError):
    """A run would exceed a documented resource limit (memory of its snapshots);
    the message names the parameter to change."""


class DivergenceError(RuntimeError):
    """A run produced non-finite values or ran away. The message names the
    scene, the step and the simulated time."""


__all__ = ["SceneError", "ConfigError", "DivergenceError", "OutputPathError", "ResourceLimitError"]
