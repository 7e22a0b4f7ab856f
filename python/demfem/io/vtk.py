"""Particle snapshots as VTK XML PolyData (``.vtp``) and time series (``.pvd``) for ParaView.

Each sphere is one point with one vertex cell, so ParaView shows it at once and its "Point
Gaussian" representation or a "Glyph" filter (scale by the ``radius`` array) draws spheres.
Files are ASCII XML (readable, diffable, and small enough for a table of ~10^3 spheres) and are
written atomically, so a ParaView session watching the series never reads a partial frame.
"""
from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Iterable, Mapping
from xml.sax.saxutils import quoteattr

import numpy as np

from demfem.errors import InvalidParameterError, ShapeError
from demfem.io.atomic import write_text_atomic

__all__ = ["write_vtp", "write_pvd", "write_vtk_series", "write_vtu_triangles"]


def _vtk_type(values: np.ndarray, name: str) -> tuple[str, np.ndarray]:
    if values.dtype == np.bool_:
        return "UInt8", values.astype(np.uint8)
    if np.issubdtype(values.dtype, np.integer):
        return ("Int32", values) if values.dtype.itemsize <= 4 else ("Int64", values)
    if np.issubdtype(values.dtype, np.floating):
        return "Float64", values.astype(np.float64)
    raise InvalidParameterError(
        f"invalid point_data[{name!r}] of dtype {values.dtype}: must be bool, integer or real")


def _ascii(values: np.ndarray) -> str:
    flat = values.reshape(-1)
    if np.issubdtype(flat.dtype, np.floating):
        # 17 significant digits round-trip a float64 exactly.
        return " ".join(format(float(v), ".17g") for v in flat)
    return " ".join(str(int(v)) for v in flat)


def _data_array(vtk_type: str, values: np.ndarray, name: str | None, components: int) -> str:
    name_attr = f" Name={quoteattr(name)}" if name is not None else ""
    return (f'<DataArray type="{vtk_type}"{name_attr} NumberOfComponents="{components}" '
            f'format="ascii">{_ascii(values)}</DataArray>')


def _arrays(data: Mapping[str, np.ndarray] | None, n: int, what: str) -> list[str]:
    """The XML arrays of ``data`` (name -> (n,) or (n, k) values), checked against ``n``."""
    out = []
    for name, values in (data or {}).items():
        if not isinstance(name, str) or not name:
            raise InvalidParameterError(f"invalid {what} name = {name!r}: must be a non-empty "
                                        "string")
        values = np.asarray(values)
        if values.ndim not in (1, 2) or values.shape[0] != n:
            raise ShapeError(f"shape mismatch for {what}[{name!r}]: expected ({n},) or "
                             f"({n}, k), got {values.shape}")
        vtk_type, values = _vtk_type(values, name)
        out.append(_data_array(vtk_type, values, name, 1 if values.ndim == 1 else values.shape[1]))
    return out


def write_vtp(path: str | Path, positions: np.ndarray,
              point_data: Mapping[str, np.ndarray] | None = None) -> Path:
    """Write one particle snapshot as VTK PolyData; returns the path.

    Args:
        path: output file, conventionally ``*.vtp``.
        positions: (N, 3) sphere centres, m. Rows must be finite: drop removed spheres (e.g.
            NaN rows) before writing, together with their point data.
        point_data: name -> (N,) or (N, k) array per sphere (e.g. ``radius`` in m, ``tag``,
            ``velocity`` (N, 3) in m/s, ``force`` (N, 3) in N). bool, integer and real dtypes.
    """
    pos = np.asarray(positions, float)
    if pos.ndim != 2 or pos.shape[1] != 3:
        raise ShapeError(f"shape mismatch for positions: expected (N, 3), got {pos.shape}")
    if not np.all(np.isfinite(pos)):
        raise InvalidParameterError(
            "invalid positions: must be finite (drop removed spheres before writing)")
    n = len(pos)
    arrays = _arrays(point_data, n, "point_data")
    index = np.arange(n, dtype=np.int64)
    text = "\n".join([
        '<?xml version="1.0"?>',
        '<VTKFile type="PolyData" version="1.0" byte_order="LittleEndian" '
        'header_type="UInt64">',
        "<PolyData>",
        f'<Piece NumberOfPoints="{n}" NumberOfVerts="{n}" NumberOfLines="0" '
        'NumberOfStrips="0" NumberOfPolys="0">',
        "<PointData>", *arrays, "</PointData>",
        "<Points>", _data_array("Float64", pos, None, 3), "</Points>",
        "<Verts>",
        _data_array("Int64", index, "connectivity", 1),
        _data_array("Int64", index + 1, "offsets", 1),
        "</Verts>",
        "</Piece>", "</PolyData>", "</VTKFile>", "",
    ])
    return write_text_atomic(path, text)


def write_vtu_triangles(path: str | Path, points: np.ndarray, triangles: np.ndarray,
                        point_data: Mapping[str, np.ndarray] | None = None,
                        cell_data: Mapping[str, np.ndarray] | None = None) -> Path:
    """Write a triangle mesh (a shell's mid-surface) as a VTK UnstructuredGrid (``.vtu``,
    ASCII, atomically); returns the path.

    Args:
        path: output file, conventionally ``*.vtu``.
        points: (N, 3) node coordinates, m, finite.
        triangles: (T, 3) node indices (0-based).
        point_data: name -> (N,) or (N, k) per node (e.g. ``displacement`` (N, 3) in m).
        cell_data: name -> (T,) or (T, k) per triangle (e.g. ``sigma1_top`` in Pa).
    """
    pts = np.asarray(points, float)
    tri = np.asarray(triangles)
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise ShapeError(f"shape mismatch for points: expected (N, 3), got {pts.shape}")
    if tri.ndim != 2 or tri.shape[1] != 3 or not np.issubdtype(tri.dtype, np.integer):
        raise ShapeError(f"shape mismatch for triangles: expected (T, 3) integers, got "
                         f"{tri.shape} {tri.dtype}")
    if not np.all(np.isfinite(pts)):
        raise InvalidParameterError("invalid points: must be finite")
    n, t = len(pts), len(tri)
    if t and (tri.min() < 0 or tri.max() >= n):
        raise InvalidParameterError(f"invalid triangles: node indices must be in [0, {n})")
    text = "\n".join([
        '<?xml version="1.0"?>',
        '<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" '
        'header_type="UInt64">',
        "<UnstructuredGrid>",
        f'<Piece NumberOfPoints="{n}" NumberOfCells="{t}">',
        "<PointData>", *_arrays(point_data, n, "point_data"), "</PointData>",
        "<CellData>", *_arrays(cell_data, t, "cell_data"), "</CellData>",
        "<Points>", _data_array("Float64", pts, None, 3), "</Points>",
        "<Cells>",
        _data_array("Int64", tri.astype(np.int64), "connectivity", 1),
        _data_array("Int64", 3 * np.arange(1, t + 1, dtype=np.int64), "offsets", 1),
        _data_array("UInt8", np.full(t, 5, np.uint8), "types", 1),  # VTK_TRIANGLE
        "</Cells>",
        "</Piece>", "</UnstructuredGrid>", "</VTKFile>", "",
    ])
    return write_text_atomic(path, text)


def write_pvd(path: str | Path, frames: Iterable[tuple[float, str | Path]]) -> Path:
    """Write a ParaView collection (``*.pvd``) that lists snapshot files with their times.

    Args:
        path: output file, conventionally ``*.pvd``.
        frames: (time in s, file) pairs; a file is best given relative to the ``.pvd`` file's
            directory so that the series can be moved as a whole.
    """
    entries = []
    for k, (time, file) in enumerate(frames):
        t = float(time)
        if not math.isfinite(t):
            raise InvalidParameterError(f"invalid frames[{k}] time = {time!r}: must be finite")
        entries.append(f'<DataSet timestep="{t!r}" group="" part="0" '
                       f"file={quoteattr(str(file))}/>")
    text = "\n".join([
        '<?xml version="1.0"?>',
        '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">',
        "<Collection>", *entries, "</Collection>", "</VTKFile>", "",
    ])
    return write_text_atomic(path, text)


def write_vtk_series(folder: str | Path, run: Any, interval: float,
                     name: str = "table") -> Path:
    """Write a sampled run as ParaView frames: ``<name>_<k>.vtp`` every ``interval`` s
    (present spheres only, with their ``index``, ``radius`` (m), ``tag``, ``velocity``
    (m/s), ``force`` (N) and ``coordination``) and ``<name>.pvd`` listing them; returns the
    ``.pvd`` path.

    ``run`` is a :class:`demfem.dem.table_run.TableRun` (or any object with its ``times``,
    ``positions``, ``velocities``, ``forces``, ``coordination``, ``present``, ``radii`` and
    ``tags`` arrays). Frames of an earlier series of the same ``name`` in ``folder`` are
    removed first, so the folder never mixes two runs.
    """
    folder = Path(folder)
    interval = float(interval)
    if not (math.isfinite(interval) and interval > 0):
        raise InvalidParameterError(f"invalid interval = {interval!r}: must be a finite "
                                    "number of seconds > 0")
    times = np.asarray(run.times, float)
    step = float(times[1] - times[0]) if len(times) > 1 else interval
    stride = max(1, int(round(interval / step)))
    if folder.is_dir():
        for old in folder.glob(f"{name}_*.vtp"):
            old.unlink()
    entries = []
    for k in range(0, len(times), stride):
        ok = run.present[k]
        file = f"{name}_{k:05d}.vtp"
        write_vtp(folder / file, run.positions[k][ok], {
            "index": np.flatnonzero(ok), "radius": run.radii[ok], "tag": run.tags[ok],
            "velocity": run.velocities[k][ok], "force": run.forces[k][ok],
            "coordination": run.coordination[k][ok].astype(np.int64)})
        entries.append((float(times[k]), file))
    return write_pvd(folder / f"{name}.pvd", entries)
