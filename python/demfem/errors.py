"""The demfem exception tree.

One root, :class:`DemfemError`. Bad input raises :class:`InvalidParameterError`, which is also a
``ValueError``, with a message that names the field, the value and the allowed range. The same
classes are raised by the Rust core (the bindings raise the classes defined here) and by the
Python modules, so ``except demfem.errors.InvalidParameterError`` catches both.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np


class DemfemError(Exception):
    """Base class of every demfem error."""


class InvalidParameterError(DemfemError, ValueError):
    """A value outside its allowed range, NaN or infinite; the message names the field,
    the value and the allowed range."""


class UnstableTimeStepError(InvalidParameterError):
    """A requested time step above the stable limit of the active laws or elements."""


class ShapeError(DemfemError, ValueError):
    """Arrays whose shapes or lengths do not fit together."""


class EffectError(DemfemError, ValueError):
    """A scene needs an effect it did not name (or names one it cannot use)."""


class NumericalError(DemfemError, RuntimeError):
    """A simulation produced a non-finite value or lost stability."""


class DemfemIOError(DemfemError, OSError):
    """Reading or writing a file failed."""


class CheckpointError(DemfemIOError):
    """A checkpoint or record file that is damaged (truncated, altered: its checksum does
    not match) or unreadable; the message names the file."""


class SettingsMismatchError(DemfemError, ValueError):
    """A run asked to resume from a checkpoint or an output folder made with other settings;
    the message names each setting that differs."""


class OtherJobError(SettingsMismatchError):
    """An output folder that holds another command's job (e.g. a ``demfem run`` folder given
    to ``demfem assess``), or files of a job without its record; the message names the
    command that made it and the way out (another folder, or ``--fresh`` to replace it)."""


class FolderLockedError(DemfemIOError):
    """An output folder that another running demfem process is writing (it holds the
    folder's lock); the message names the folder and that process's PID."""


class DemfemWarning(UserWarning):
    """Something demfem repaired or assumed on the user's behalf (e.g. duplicate triangles
    of a mesh file dropped); the message names the file and what was done."""


class SimulationInterrupted(DemfemError, KeyboardInterrupt):
    """A run stopped cleanly at a step boundary (Ctrl-C); its state is consistent and can be
    checkpointed or continued."""


__all__ = [
    "DemfemError",
    "DemfemIOError",
    "EffectError",
    "InvalidParameterError",
    "NumericalError",
    "ShapeError",
    "SimulationInterrupted",
    "UnstableTimeStepError",
    "check_range",
    "check_positive",
    "check_count",
    "as_real",
    "CheckpointError",
    "SettingsMismatchError",
    "OtherJobError",
    "FolderLockedError",
    "DemfemWarning",
]


def as_real(field: str, value: Any) -> float:
    """``value`` as a float (may be inf or NaN); booleans and non-numbers raise
    :class:`InvalidParameterError` naming ``field``."""
    return _as_float(field, value)


def _as_float(field: str, value: Any) -> float:
    # True would be taken as 1.0: a boolean is never a physical quantity
    if isinstance(value, (bool, np.bool_)):
        raise InvalidParameterError(f"invalid {field} = {value!r}: must be a real number, "
                                    "not a boolean")
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise InvalidParameterError(f"invalid {field} = {value!r}: must be a real number") from None
    return x


def check_range(
    field: str,
    value: Any,
    lo: float = -math.inf,
    hi: float = math.inf,
    *,
    lo_open: bool = True,
    hi_open: bool = True,
) -> float:
    """Return ``value`` as a float if it is finite and inside the interval, else raise
    :class:`InvalidParameterError` naming ``field``, the value and the allowed range."""
    x = _as_float(field, value)
    lo_ok = x > lo if lo_open else x >= lo
    hi_ok = x < hi if hi_open else x <= hi
    if not (math.isfinite(x) and lo_ok and hi_ok):
        left = "(" if lo_open else "["
        right = ")" if hi_open else "]"
        raise InvalidParameterError(
            f"invalid {field} = {value!r}: must be finite and in {left}{lo:g}, {hi:g}{right}"
        )
    return x


def check_positive(field: str, value: Any) -> float:
    """``value`` as a float if finite and > 0, else :class:`InvalidParameterError`."""
    return check_range(field, value, 0.0, math.inf)


def check_count(field: str, value: Any, lo: int = 0) -> int:
    """``value`` as an int if it is a whole number >= ``lo`` (booleans and non-integral
    floats refused), else :class:`InvalidParameterError` naming ``field``."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise InvalidParameterError(f"invalid {field} = {value!r}: must be a whole number "
                                    f">= {lo}")
    if value < lo:
        raise InvalidParameterError(f"invalid {field} = {value!r}: must be a whole number "
                                    f">= {lo}")
    return int(value)
