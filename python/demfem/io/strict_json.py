"""Strict JSON: what demfem writes is read by any JSON parser.

Python's :mod:`json` writes ``NaN``, ``Infinity`` and ``-Infinity`` by default, which are not
JSON (RFC 8259) and which many readers (JavaScript's ``JSON.parse``, jq, Go, Rust's serde)
refuse. :func:`dumps` turns every non-finite float into ``null`` and numpy scalars and arrays
into plain numbers and lists, then serialises with ``allow_nan=False`` so that nothing
non-standard can slip through.
"""
from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any, Callable, Optional

import numpy as np

__all__ = ["dumps", "finite_or_none", "write_json_atomic"]


def finite_or_none(obj: Any, default: Optional[Callable[[Any], Any]] = None) -> Any:
    """A copy of ``obj`` (dicts, lists, tuples, numbers, numpy scalars and arrays, paths)
    with every NaN or infinite float replaced by ``None`` and numpy values made plain; other
    objects go through ``default`` (e.g. ``str``), or raise TypeError without one."""
    if isinstance(obj, dict):
        return {str(k): finite_or_none(v, default) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [finite_or_none(v, default) for v in obj]
    if isinstance(obj, np.ndarray):
        return finite_or_none(obj.tolist(), default)
    if isinstance(obj, np.generic):
        return finite_or_none(obj.item(), default)
    if isinstance(obj, bool) or obj is None or isinstance(obj, (int, str)):
        return obj
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, Path):
        return str(obj)
    if default is not None:
        return finite_or_none(default(obj))
    raise TypeError(f"not JSON serialisable: {type(obj).__name__}")


def dumps(obj: Any, default: Optional[Callable[[Any], Any]] = None, **kwargs: Any) -> str:
    """``json.dumps`` of :func:`finite_or_none` ``(obj, default)`` with ``allow_nan=False``:
    strict JSON, non-finite numbers as ``null``."""
    return json.dumps(finite_or_none(obj, default), allow_nan=False, **kwargs)


def write_json_atomic(path: str | Path, obj: Any, indent: Optional[int] = 1,
                      default: Optional[Callable[[Any], Any]] = None) -> Path:
    """Write ``obj`` as strict JSON (see :func:`dumps`) to ``path`` atomically, with a final
    newline; returns the path."""
    from demfem.io.atomic import write_text_atomic

    return write_text_atomic(path, dumps(obj, default, indent=indent) + "\n")
