"""Exceptions raised by confined_rod (no imports of the simulator: post-processing uses them too)."""
from __future__ import annotations


def shorten(value, limit: int = 80) -> str:
    """repr of a value for an error message, cut to ``limit`` characters (a value
    may be a huge nested structure)."""
    import reprlib

    r = reprlib.Repr()
    r.maxstring, r.maxother, r.maxlist, r.maxdict, r.maxlevel = limit, limit, 6, 6, 3
    text = r.repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


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


__all__ = ["shorten", "SceneError", "ConfigError", "DivergenceError", "OutputPathError", "ResourceLimitError"]
