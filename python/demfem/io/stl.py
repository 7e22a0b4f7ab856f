"""Triangle meshes from CAD files: STL (binary and ASCII) read with numpy alone, other formats
through ``meshio`` or ``trimesh`` when one of them is installed; vertex welding, units, and
the checks a mesh wall needs (degenerate triangles, closed surfaces), every error naming the
file.

A mesh is two numpy arrays: ``vertices`` (N, 3) float64 in metres and ``triangles`` (M, 3)
int64 vertex indices.

Example::

    from demfem.io.stl import read_mesh, write_stl
    vertices, triangles = read_mesh("rails.stl", scale=1e-3)   # a file in millimetres
"""
from __future__ import annotations

import struct
import warnings
from pathlib import Path

import numpy as np

from demfem.errors import DemfemIOError, DemfemWarning, InvalidParameterError, check_positive

__all__ = ["read_stl", "read_mesh", "write_stl", "weld_vertices", "check_mesh",
           "open_edge_count", "drop_duplicate_triangles", "MAX_COORDINATE"]

_BINARY_HEADER = 80
_BINARY_RECORD = 50

#: Largest coordinate of a mesh, m (after ``scale``): a table lies within 100 km of its
#: origin (the DEM refuses a wider scene); more is a wrong unit or a broken export.
MAX_COORDINATE = 1e5


def _io_error(path: Path, detail: str) -> DemfemIOError:
    return DemfemIOError(f"i/o error on {path}: {detail}")


def read_stl(path: str | Path, *, scale: float = 1.0,
             weld_tolerance: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (N, 3), m, and triangles (M, 3) of the STL file at ``path`` (binary or
    ASCII, told apart by the binary file's size), coordinates multiplied by ``scale`` (the
    file's unit in metres: 1e-3 for millimetres). Coincident corners are merged
    (:func:`weld_vertices`, ``weld_tolerance`` in m, default 1e-9 of the mesh's size).

    A missing or unreadable file raises :class:`DemfemIOError`, a malformed one
    :class:`InvalidParameterError`, both naming the file."""
    path = Path(path)
    scale = check_positive(f"scale of {path}", scale)
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise _io_error(path, exc.strerror or str(exc)) from None
    corners = _stl_corners(data, path)
    if corners.shape[0] == 0:
        raise InvalidParameterError(f"invalid mesh file {path}: it holds no triangles")
    corners = corners.astype(np.float64) * scale
    _check_coordinates(corners, path, scale)
    vertices, triangles = weld_vertices(corners.reshape(-1, 3), weld_tolerance)
    return vertices, drop_duplicate_triangles(triangles.reshape(-1, 3), str(path))


def _check_coordinates(corners: np.ndarray, path: Path, scale: float) -> None:
    """Refuse non-finite corners and coordinates beyond :data:`MAX_COORDINATE` (after
    ``scale``), naming the file, the triangle and the scale."""
    corners = corners.reshape(-1, 3, 3)
    finite = np.all(np.isfinite(corners), axis=(1, 2))
    if not np.all(finite):
        t = int(np.flatnonzero(~finite)[0])
        raise InvalidParameterError(
            f"invalid mesh file {path}: triangle {t} has non-finite coordinates")
    far = np.max(np.abs(corners), axis=(1, 2))
    if far.size and float(far.max()) > MAX_COORDINATE:
        t = int(np.argmax(far))
        raise InvalidParameterError(
            f"invalid mesh file {path}: coordinates up to {float(far[t]):.3g} m (triangle "
            f"{t}, with scale = {scale:g}); a table's walls must lie within "
            f"{MAX_COORDINATE:g} m of the origin: is the unit right? (scale converts the "
            "file's unit to metres: 1e-3 for millimetres)")


def drop_duplicate_triangles(triangles: np.ndarray, source: str) -> np.ndarray:
    """``triangles`` without repeats: a triangle on the same three (welded) vertices as an
    earlier one, in either orientation, is dropped with a :class:`~demfem.errors.
    DemfemWarning` naming ``source`` and the count. A face exported twice (two coincident
    bodies, a face of each) would otherwise be a wall of twice the contact stiffness."""
    t = np.asarray(triangles)
    if len(t) < 2:
        return t
    _, first = np.unique(np.sort(t, axis=1), axis=0, return_index=True)
    if len(first) == len(t):
        return t
    keep = np.zeros(len(t), bool)
    keep[first] = True
    dropped = np.flatnonzero(~keep)
    warnings.warn(
        f"mesh {source}: {len(dropped)} of its {len(t)} triangles repeat an earlier one (the "
        f"first: triangle {int(dropped[0])}); the repeats were dropped, so each face acts once "
        "(a face twice would press twice as hard); remove them from the CAD export to silence "
        "this warning", DemfemWarning, stacklevel=3)
    return t[keep]


def _stl_corners(data: bytes, path: Path) -> np.ndarray:
    """The (M, 3, 3) corners of an STL file's triangles, binary or ASCII."""
    if len(data) >= _BINARY_HEADER + 4:
        (count,) = struct.unpack_from("<I", data, _BINARY_HEADER)
        if len(data) == _BINARY_HEADER + 4 + _BINARY_RECORD * count:
            record = np.dtype([("normal", "<f4", 3), ("corners", "<f4", (3, 3)),
                               ("attribute", "<u2")])
            rows = np.frombuffer(data, dtype=record, count=count, offset=_BINARY_HEADER + 4)
            return np.array(rows["corners"], dtype=np.float64)
    try:
        text = data.decode("ascii")
    except UnicodeDecodeError:
        raise InvalidParameterError(
            f"invalid mesh file {path}: neither a binary STL (size {len(data)} bytes does not "
            "match its triangle count) nor ASCII STL text") from None
    if not text.lstrip().lower().startswith("solid"):
        raise InvalidParameterError(
            f"invalid mesh file {path}: an ASCII STL starts with 'solid'")
    values = []
    lines = text.splitlines()
    for number, line in enumerate(lines, start=1):
        words = line.split()
        if words and words[0].lower() == "vertex":
            if len(words) != 4:
                raise InvalidParameterError(
                    f"invalid mesh file {path}, line {number}: 'vertex x y z' expected, got "
                    f"{line.strip()!r}")
            try:
                values.append([float(w) for w in words[1:]])
            except ValueError:
                raise InvalidParameterError(
                    f"invalid mesh file {path}, line {number}: non-numeric vertex "
                    f"{line.strip()!r}") from None
    if len(values) % 3:
        raise InvalidParameterError(
            f"invalid mesh file {path}: {len(values)} vertex lines, not three per facet")
    return np.asarray(values, dtype=np.float64).reshape(-1, 3, 3)


def read_mesh(path: str | Path, *, scale: float = 1.0,
              weld_tolerance: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (N, 3), m, and triangles (M, 3) of a mesh file: ``.stl`` by
    :func:`read_stl`; any other format ``meshio`` (or else ``trimesh``) reads, when installed
    (their triangle cells; other cells are ignored). ``scale``: the file's unit in metres."""
    path = Path(path)
    if path.suffix.lower() == ".stl":
        return read_stl(path, scale=scale, weld_tolerance=weld_tolerance)
    scale = check_positive(f"scale of {path}", scale)
    if not path.is_file():
        raise _io_error(path, "no such file")
    points = cells = None
    try:
        import meshio  # type: ignore[import-not-found]

        try:
            m = meshio.read(path)
        except Exception as exc:  # meshio raises many kinds
            raise InvalidParameterError(f"invalid mesh file {path}: {exc}") from None
        points = np.asarray(m.points, float)
        tri = [np.asarray(c.data) for c in m.cells if c.type == "triangle"]
        cells = np.concatenate(tri) if tri else np.zeros((0, 3), np.int64)
    except ImportError:
        try:
            import trimesh  # type: ignore[import-not-found]

            try:
                m = trimesh.load(path, force="mesh", process=False)
            except Exception as exc:
                raise InvalidParameterError(f"invalid mesh file {path}: {exc}") from None
            points, cells = np.asarray(m.vertices, float), np.asarray(m.faces)
        except ImportError:
            raise InvalidParameterError(
                f"invalid mesh file {path}: format {path.suffix!r} needs meshio or trimesh "
                "(pip install meshio); STL is read without them") from None
    if cells is None or len(cells) == 0:
        raise InvalidParameterError(f"invalid mesh file {path}: it holds no triangles")
    if points.shape[1] == 2:
        points = np.column_stack([points, np.zeros(len(points))])
    cells = np.asarray(cells)
    if not np.issubdtype(cells.dtype, np.integer) or cells.ndim != 2 or cells.shape[1] != 3 \
            or cells.min() < 0 or cells.max() >= len(points):
        raise InvalidParameterError(f"invalid mesh file {path}: its triangles are not (M, 3) "
                                    f"integer indices into its {len(points)} points")
    corners = points[cells.astype(np.int64)] * scale
    _check_coordinates(corners, path, scale)
    vertices, triangles = weld_vertices(corners.reshape(-1, 3), weld_tolerance)
    return vertices, drop_duplicate_triangles(triangles.reshape(-1, 3), str(path))


def weld_vertices(points: np.ndarray,
                  tolerance: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Merge points closer than ``tolerance`` (m; default 1e-9 of the bounding box's
    diagonal): the distinct vertices (N, 3), in order of first appearance, and the index of
    each input point's vertex. STL stores every triangle's corners apart, so a mesh's
    adjacency (which the contact rule at edges and vertices needs) exists only once the
    shared corners are merged."""
    from scipy.spatial import cKDTree

    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if not np.all(np.isfinite(points)) or (
            len(points) and float(np.max(np.abs(points))) > 1e150):
        raise InvalidParameterError(
            "invalid points to weld: coordinates must be finite and at most 1e150 m (got up "
            f"to {float(np.max(np.abs(points))):.3g}); is the unit right?")
    if tolerance is None:
        size = float(np.linalg.norm(points.max(axis=0) - points.min(axis=0))) if len(points) else 0.0
        tolerance = 1e-9 * size
    if not (np.isfinite(tolerance) and tolerance >= 0.0):
        raise InvalidParameterError(
            f"invalid weld_tolerance = {tolerance}: must be finite and >= 0 (m)")
    # exact duplicates first (the common case), then near ones through a k-d tree
    unique, first, inverse = np.unique(points, axis=0, return_index=True, return_inverse=True)
    inverse = inverse.reshape(-1)
    label = np.arange(len(unique))
    if tolerance > 0.0 and len(unique) > 1:
        pairs = cKDTree(unique).query_pairs(tolerance, output_type="ndarray")
        if len(pairs):
            # union-find over the close pairs: each cluster takes its smallest label
            parent = np.arange(len(unique))

            def root(k: int) -> int:
                while parent[k] != k:
                    parent[k] = parent[parent[k]]
                    k = parent[k]
                return k

            for a, b in pairs:
                ra, rb = root(int(a)), root(int(b))
                if ra != rb:
                    parent[max(ra, rb)] = min(ra, rb)
            label = np.array([root(k) for k in range(len(unique))])
    # number the clusters in order of their first appearance in the input
    cluster_first = np.full(len(unique), np.iinfo(np.int64).max)
    np.minimum.at(cluster_first, label, first)
    roots = np.flatnonzero(cluster_first < np.iinfo(np.int64).max)
    order = roots[np.argsort(cluster_first[roots])]
    number = np.empty(len(unique), np.int64)
    number[order] = np.arange(len(order))
    vertices = points[cluster_first[order]]
    return vertices, number[label][inverse]


def check_mesh(vertices: np.ndarray, triangles: np.ndarray, *, source: str,
               closed: bool = False) -> None:
    """Refuse a mesh a wall cannot use, naming ``source`` (the file) and the triangle:
    indices out of range, degenerate or zero-area triangles (area at most 1e-12 of the
    squared bounding-box diagonal, the core's limit), and, with ``closed``, an open surface
    (an edge not shared by exactly two triangles)."""
    v = np.asarray(vertices, float)
    t = np.asarray(triangles)
    if v.ndim != 2 or v.shape[1] != 3 or not np.all(np.isfinite(v)) or (
            len(v) and float(np.max(np.abs(v))) > MAX_COORDINATE):
        raise InvalidParameterError(
            f"invalid mesh {source}: vertices must be (N, 3) finite coordinates within "
            f"{MAX_COORDINATE:g} m of the origin (is the unit right?)")
    if t.dtype == bool or not np.issubdtype(t.dtype, np.integer):
        raise InvalidParameterError(f"invalid mesh {source}: triangles must be integer vertex "
                                    f"indices, got dtype {t.dtype}")
    if t.ndim != 2 or t.shape[1] != 3 or len(t) == 0:
        raise InvalidParameterError(f"invalid mesh {source}: triangles must be (M, 3), M >= 1, "
                                    f"got shape {t.shape}")
    if t.min() < 0 or t.max() >= len(v):
        k = int(np.flatnonzero((t < 0).any(axis=1) | (t >= len(v)).any(axis=1))[0])
        raise InvalidParameterError(f"invalid mesh {source}: triangle {k} = {t[k].tolist()} "
                                    f"has vertex indices outside 0..{len(v) - 1}")
    size2 = float(np.sum((v.max(axis=0) - v.min(axis=0)) ** 2))
    a, b, c = v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    limit = 1e-12 * size2
    bad = np.flatnonzero(~(area > limit))
    if len(bad):
        k = int(bad[0])
        raise InvalidParameterError(
            f"invalid mesh {source}: triangle {k} (vertices {t[k].tolist()}) is degenerate, "
            f"area {area[k]:.3g} m^2; must be > {limit:.3g} m^2 ({len(bad)} such triangle(s); "
            "repair the CAD export or weld with a smaller tolerance)")
    if closed:
        n_open = open_edge_count(t)
        if n_open:
            raise InvalidParameterError(
                f"invalid mesh {source}: closed = true but {n_open} edge(s) are not shared by "
                "exactly two triangles (an open or non-manifold surface)")


def open_edge_count(triangles: np.ndarray) -> int:
    """Edges not shared by exactly two triangles (0 for a closed manifold surface)."""
    t = np.asarray(triangles, np.int64)
    edges = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    return int(np.count_nonzero(counts != 2))


def write_stl(path: str | Path, vertices: np.ndarray, triangles: np.ndarray, *,
              binary: bool = True, name: str = "demfem") -> Path:
    """Write a mesh as STL (binary by default, else ASCII), coordinates as given (m),
    atomically; returns the path."""
    from demfem.io.atomic import atomic_path

    v = np.asarray(vertices, float)
    t = np.asarray(triangles, np.int64)
    corners = v[t]
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    length = np.linalg.norm(normal, axis=1, keepdims=True)
    normal = np.divide(normal, length, out=np.zeros_like(normal), where=length > 0)
    with atomic_path(path, suffix=".stl") as tmp:
        if binary:
            record = np.dtype([("normal", "<f4", 3), ("corners", "<f4", (3, 3)),
                               ("attribute", "<u2")])
            rows = np.zeros(len(t), dtype=record)
            rows["normal"] = normal
            rows["corners"] = corners
            with open(tmp, "wb") as handle:
                handle.write(name.encode("ascii", "replace")[:80].ljust(80, b" "))
                handle.write(struct.pack("<I", len(t)))
                handle.write(rows.tobytes())
        else:
            lines = [f"solid {name}"]
            for n, c in zip(normal, corners):
                lines.append(f"  facet normal {n[0]:.9e} {n[1]:.9e} {n[2]:.9e}")
                lines.append("    outer loop")
                lines.extend(f"      vertex {p[0]:.17g} {p[1]:.17g} {p[2]:.17g}" for p in c)
                lines.append("    endloop")
                lines.append("  endfacet")
            lines.append(f"endsolid {name}")
            Path(tmp).write_text("\n".join(lines) + "\n", encoding="ascii")
    return Path(path)
