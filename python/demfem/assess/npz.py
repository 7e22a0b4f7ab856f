"""Small file helpers of the assess stages: arrays to and from ``.npz`` (written atomically),
and nested settings flattened to dotted keys for tables."""
from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["save_npz", "load_npz", "flatten"]


def save_npz(path: Path, **arrays: Any) -> Path:
    """Write ``arrays`` to ``path`` (.npz, compressed) atomically; returns the path."""
    from demfem.io.atomic import atomic_path

    with atomic_path(path, suffix=".npz") as tmp:
        with open(tmp, "wb") as fh:
            np.savez_compressed(fh, **arrays)
    return path


def load_npz(path: Path) -> dict[str, np.ndarray]:
    """Every array of the ``.npz`` at ``path`` (no pickles)."""
    with np.load(path, allow_pickle=False) as data:
        return {k: data[k] for k in data.files}


def flatten(d: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    """``{"a": {"b": 1}}`` → ``{"a.b": 1}``."""
    out: dict[str, Any] = {}
    for k, v in d.items():
        if isinstance(v, dict):
            out.update(flatten(v, f"{prefix}{k}."))
        else:
            out[f"{prefix}{k}"] = v
    return out
