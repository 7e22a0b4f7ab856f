"""The assessment's tables a user opens: ``events.parquet`` (one row per event) and
``passages.parquet`` (one row per passage of a cartridge over the table), each column named
with its SI unit and carrying it in the Parquet schema (field metadata ``unit``); the same as
CSV on request (``csv=True``). :func:`load_assessment` reads a finished assessment folder
back into pandas DataFrames and the summary.

Written atomically (:mod:`demfem.io.atomic`); zstd-compressed, real columns byte-stream
split (lossless, about 12 % smaller for doubles) and increasing integer columns (the row
numbers) delta-encoded.

Precision of ``events.parquet``: double (float64) for every number the probabilities are
computed from and the probabilities themselves — ``time_s``, ``force_N``, ``duration_s``,
``sigma_inner_Pa``, ``sigma_outer_Pa``, ``area_inner_m2``, ``area_outer_m2``, ``p_inner``,
``p_outer``, ``p_event`` — so that P can be recomputed from the table to 1e-9; single
(float32, 7 significant digits) for the descriptive columns :data:`SINGLE_PRECISION_COLUMNS`
(contact point, speeds, angle, friction force, contact radius, the law's force). The CSV
files hold the same values.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from demfem.errors import DemfemIOError

__all__ = ["write_table", "events_columns", "passages_columns", "load_assessment",
           "Assessment", "SINGLE_PRECISION_COLUMNS"]

#: The columns of ``events.parquet`` held in single precision (float32): descriptive, no
#: probability is computed from them (module docstring).
SINGLE_PRECISION_COLUMNS = ("x_m", "y_m", "z_m", "normal_speed_m_per_s",
                            "tangential_speed_m_per_s", "impact_angle_deg",
                            "peak_tangential_force_N", "contact_radius_m", "law_force_N")


def _unit(name: str) -> str:
    for suffix, unit in (("_m_per_s", "m/s"), ("_m2", "m^2"), ("_Pa", "Pa"), ("_N", "N"),
                         ("_deg", "deg"), ("_s", "s"), ("_m", "m")):
        if name.endswith(suffix):
            return unit
    return "1"


def write_table(path: Path, columns: dict[str, Any], csv: bool = False) -> list[Path]:
    """Write ``columns`` ({name: (n,) array}) as Parquet at ``path`` (the unit of each column,
    from its name's suffix, in the schema's field metadata; each column in its array's
    dtype) and, with ``csv``, as CSV beside it; returns the files written. Real columns are
    byte-stream split, integer columns that never decrease delta-encoded, the others
    dictionary-encoded; all zstd-compressed (lossless)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    from demfem.io.atomic import atomic_path, write_text_atomic

    fields, arrays = [], []
    encoding: dict[str, str] = {}
    for name, values in columns.items():
        a = np.asarray(values)
        arr = pa.array(a) if a.dtype.kind != "U" else pa.array(a.tolist()).dictionary_encode()
        fields.append(pa.field(name, arr.type, metadata={"unit": _unit(name)}))
        arrays.append(arr)
        if a.dtype.kind == "f":
            encoding[name] = "BYTE_STREAM_SPLIT"
        elif a.dtype.kind == "i" and a.size > 1 and bool(np.all(np.diff(a) >= 0)):
            encoding[name] = "DELTA_BINARY_PACKED"
    table = pa.Table.from_arrays(arrays, schema=pa.schema(
        fields, metadata={"producer": "demfem assess", "units": "SI, per column"}))
    path = Path(path)
    with atomic_path(path, suffix=".parquet") as tmp:
        pq.write_table(table, str(tmp), compression="zstd",
                       use_dictionary=[n for n in columns if n not in encoding],
                       column_encoding=encoding or None)
    out = [path]
    if csv:
        lines = [",".join(columns)]
        cols = [np.asarray(v) for v in columns.values()]
        for k in range(len(cols[0]) if cols else 0):
            lines.append(",".join(_fmt(c[k]) for c in cols))
        out.append(write_text_atomic(path.with_suffix(".csv"), "\n".join(lines) + "\n"))
    return out


def _fmt(x: Any) -> str:
    if isinstance(x, (bool, np.bool_)):
        return "1" if x else "0"
    if isinstance(x, (int, np.integer)):
        return str(int(x))
    if isinstance(x, (str, np.str_)):
        return str(x)
    v = float(x)
    return "" if math.isnan(v) else f"{v:.9g}"


def events_columns(events: np.ndarray, extra: dict[str, np.ndarray],
                   wall_names: list[str]) -> dict[str, Any]:
    """The columns of ``events.parquet``: the event table
    (:data:`demfem.assess.events.EVENT_DTYPE`) with its partner and wall named, then
    ``extra`` (per-event arrays, named with their units); the columns named in
    :data:`SINGLE_PRECISION_COLUMNS` in single precision."""
    from demfem.assess.impact import PARTNERS

    partner = np.array([PARTNERS[int(p)] for p in events["partner"]], dtype="U8")
    wall = np.asarray(events["wall"], np.int64)
    names = np.array([wall_names[w] if 0 <= w < len(wall_names) else "" for w in wall],
                     dtype="U32")
    columns = {"event": np.arange(len(events), dtype=np.int64), "i": events["i"],
               "j": events["j"], "partner": partner, "wall": names, "time_s": events["time"],
               "x_m": events["x"], "y_m": events["y"], "z_m": events["z"],
               "normal_speed_m_per_s": events["normal_speed"],
               "tangential_speed_m_per_s": events["tangential_speed"],
               "impact_angle_deg": np.degrees(events["impact_angle"]), **extra}
    return {k: np.asarray(v, np.float32) if k in SINGLE_PRECISION_COLUMNS else v
            for k, v in columns.items()}


def passages_columns(passages: np.ndarray, tags: np.ndarray,
                     risk: dict[str, Any]) -> dict[str, Any]:
    """The columns of ``passages.parquet``: one row per passage
    (:func:`demfem.assess.passages.passages`) with its time on the table in the window,
    events and probability of breakage over it (``p_window``) and its hazard."""
    return {"passage": np.arange(len(passages), dtype=np.int64),
            "cartridge": passages["particle"],
            "tag": np.asarray(tags, np.int64)[passages["particle"]],
            "start_s": passages["start"], "end_s": passages["end"],
            "exited": passages["exited"], "exposure_in_window_s": risk["exposure_s"],
            "n_events_window": risk["n_events"], "p_window": risk["p_window"],
            "hazard": risk["hazard"]}


@dataclass
class Assessment:
    """A finished assessment read back: ``events`` and ``passages`` (pandas DataFrames, SI
    units in the column names), ``summary`` and ``risk`` (``risk.json``'s summary and whole
    document), ``folder``."""

    folder: Path
    risk: dict[str, Any]
    events: Any
    passages: Any

    @property
    def summary(self) -> dict[str, Any]:
        """``risk.json``'s summary."""
        return self.risk["summary"]


def load_assessment(folder: str | Path) -> Assessment:
    """Read the assessment in ``folder`` (a finished ``demfem assess`` output) into pandas
    DataFrames and its summary.

    Raises:
        DemfemIOError: the folder holds no finished assessment (naming the missing file).
    """
    import pandas as pd

    folder = Path(folder)
    files = {k: folder / k for k in ("risk.json", "events.parquet", "passages.parquet")}
    for name, f in files.items():
        if not f.is_file():
            raise DemfemIOError(f"no finished assessment in {folder}: {name} is missing (run "
                                f"demfem assess --out {folder})")
    try:
        risk = json.loads(files["risk.json"].read_text(encoding="utf-8"))
        return Assessment(folder=folder, risk=risk,
                          events=pd.read_parquet(files["events.parquet"]),
                          passages=pd.read_parquet(files["passages.parquet"]))
    except (OSError, ValueError) as exc:
        raise DemfemIOError(f"damaged assessment file in {folder}: {exc}") from None
