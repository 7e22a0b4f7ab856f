"""FEM meshes: tetrahedra through the glass wall and shells on its mid-surface, from any
:class:`demfem.cartridge.Cartridge`; balls (for verification); placement of a mesh.

Every length is in m. Meshes are plain numpy arrays in frozen dataclasses, so they can be
saved, inspected and built by hand.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional, Sequence

import numpy as np

from demfem import _core
from demfem.cartridge import Cartridge
from demfem.errors import InvalidParameterError, check_count, check_positive, check_range

#: Meshes larger than this are refused unless ``max_elements`` is raised explicitly.
DEFAULT_MAX_ELEMENTS = 2_000_000


def _nodes(field_name: str, nodes: object) -> np.ndarray:
    try:
        a = np.asarray(nodes, dtype=float)
    except (TypeError, ValueError):
        raise InvalidParameterError(f"invalid {field_name}: must be (N, 3) coordinates in m, "
                                    "numbers") from None
    if a.ndim != 2 or a.shape[1] != 3:
        raise InvalidParameterError(f"invalid {field_name}: shape {a.shape}; must be (N, 3) "
                                    "coordinates in m")
    return a


def _indices(field_name: str, value: object, width: int, n_nodes: int) -> np.ndarray:
    """Node indices (E, width) of an integer dtype, each in [0, n_nodes); a float, boolean or
    other array is refused (a float index would be truncated to another node)."""
    a = np.asarray(value)
    if a.dtype == bool or not np.issubdtype(a.dtype, np.integer):
        raise InvalidParameterError(
            f"invalid {field_name}: dtype {a.dtype}; must be integer node indices (an array of "
            "an integer dtype, e.g. numpy.int64: non-integer indices are not truncated "
            "silently)")
    if a.ndim != 2 or a.shape[1] != width:
        raise InvalidParameterError(f"invalid {field_name}: shape {a.shape}; must be (E, "
                                    f"{width}) node indices")
    if a.size and (a.min() < 0 or a.max() >= n_nodes):
        k = int(np.flatnonzero(((a < 0) | (a >= n_nodes)).any(axis=1))[0])
        raise InvalidParameterError(f"invalid {field_name}: element {k} = {a[k].tolist()} "
                                    f"has node indices outside [0, {n_nodes})")
    return a


@dataclass(frozen=True)
class TetMesh:
    """Linear tetrahedra: ``nodes`` (N, 3) m, ``tets`` (E, 4) node indices (an integer
    dtype, each in [0, N)), positively oriented."""

    nodes: np.ndarray
    tets: np.ndarray

    def __post_init__(self) -> None:
        nodes = _nodes("nodes", self.nodes)
        object.__setattr__(self, "nodes", nodes)
        object.__setattr__(self, "tets", _indices("tets", self.tets, 4, len(nodes)))

    @property
    def n_nodes(self) -> int:
        return int(self.nodes.shape[0])

    @property
    def n_elements(self) -> int:
        return int(self.tets.shape[0])

    def placed(self, rotation: Optional[np.ndarray] = None,
               translation: Sequence[float] = (0.0, 0.0, 0.0)) -> "TetMesh":
        """The mesh rotated by the 3×3 proper rotation ``rotation`` about the origin, then
        moved by ``translation`` (m)."""
        r = np.eye(3) if rotation is None else np.asarray(rotation, dtype=float)
        if r.shape != (3, 3) or not np.allclose(r @ r.T, np.eye(3), atol=1e-9) \
                or not abs(np.linalg.det(r) - 1.0) < 1e-9:
            raise InvalidParameterError(
                f"invalid rotation = {r.tolist()!r}: must be a 3x3 proper rotation matrix")
        t = np.asarray(translation, dtype=float)
        if t.shape != (3,) or not np.all(np.isfinite(t)):
            raise InvalidParameterError(f"invalid translation = {translation!r}: must be 3 finite values (m)")
        return TetMesh(self.nodes @ r.T + t, self.tets)


@dataclass(frozen=True)
class ShellMesh:
    """Flat shell triangles on the mid-surface: ``nodes`` (N, 3) m, ``triangles`` (T, 3)
    node indices (an integer dtype, each in [0, N)), ``thickness`` (T,) m."""

    nodes: np.ndarray
    triangles: np.ndarray
    thickness: np.ndarray

    def __post_init__(self) -> None:
        nodes = _nodes("nodes", self.nodes)
        object.__setattr__(self, "nodes", nodes)
        object.__setattr__(self, "triangles",
                           _indices("triangles", self.triangles, 3, len(nodes)))

    @property
    def n_nodes(self) -> int:
        return int(self.nodes.shape[0])

    @property
    def n_elements(self) -> int:
        return int(self.triangles.shape[0])

    def placed(self, rotation: Optional[np.ndarray] = None,
               translation: Sequence[float] = (0.0, 0.0, 0.0)) -> "ShellMesh":
        """The mesh rotated by the 3×3 proper rotation ``rotation`` about the origin, then
        moved by ``translation`` (m)."""
        moved = TetMesh(self.nodes, np.zeros((0, 4), dtype=np.int64)).placed(rotation, translation)
        return ShellMesh(moved.nodes, self.triangles, self.thickness)


def rotation_about(axis: Sequence[float], angle_deg: float) -> np.ndarray:
    """Rotation matrix (3×3) by ``angle_deg`` degrees about ``axis`` (right-hand rule)."""
    a = np.asarray(axis, dtype=float)
    n = np.linalg.norm(a)
    if not (n > 0 and np.isfinite(n)):
        raise InvalidParameterError(f"invalid axis = {axis!r}: must be a finite non-zero vector")
    if not math.isfinite(angle_deg):
        raise InvalidParameterError(f"invalid angle_deg = {angle_deg!r}: must be finite")
    x, y, z = a / n
    t = math.radians(angle_deg)
    c, s, C = math.cos(t), math.sin(t), 1 - math.cos(t)
    return np.array([
        [c + x * x * C, x * y * C - z * s, x * z * C + y * s],
        [y * x * C + z * s, c + y * y * C, y * z * C - x * s],
        [z * x * C - y * s, z * y * C + x * s, c + z * z * C],
    ])


def _layers(layers: int) -> int:
    if isinstance(layers, bool) or not isinstance(layers, (int, np.integer)) or not 1 <= layers <= 16:
        raise InvalidParameterError(f"invalid layers = {layers!r}: must be an integer in [1, 16]")
    return int(layers)


#: Most divisions around a revolved mesh.
MAX_N_THETA = 4096


def _sizes(cartridge: Cartridge, layers: int, target_size: Optional[float],
           n_theta: Optional[int]) -> tuple[float, int]:
    t = cartridge.wall_thickness
    h = 2.0 * t / layers if target_size is None else check_positive("target_size", target_size)
    if n_theta is None:
        around = 2 * math.pi * 0.5 * cartridge.body_outer_diameter
        n_theta = max(12, int(math.ceil(around / h)))
        if n_theta > MAX_N_THETA:
            raise InvalidParameterError(
                f"invalid target_size = {target_size!r} m: the circumference {around:.4g} m "
                f"would need n_theta = {n_theta} divisions around, more than {MAX_N_THETA}; "
                f"target_size must be at least {around / MAX_N_THETA:.3g} m")
    if isinstance(n_theta, bool) or not isinstance(n_theta, (int, np.integer)) \
            or not 6 <= n_theta <= MAX_N_THETA:
        raise InvalidParameterError(f"invalid n_theta = {n_theta!r}: must be an integer in "
                                    f"[6, {MAX_N_THETA}]")
    return h, int(n_theta)


def estimated_tet_count(cartridge: Cartridge, layers: int = 2, target_size: Optional[float] = None,
                        n_theta: Optional[int] = None) -> int:
    """Elements the revolved tet mesher will make (about): 6 per cell of
    n_theta × layers × (length / target_size) cells."""
    layers = _layers(layers)
    h, n_theta = _sizes(cartridge, layers, target_size, n_theta)
    return int(6 * n_theta * layers * math.ceil(cartridge.length / h))


def cartridge_tet_mesh(cartridge: Cartridge, layers: int = 2, target_size: Optional[float] = None,
                       n_theta: Optional[int] = None,
                       max_elements: int = DEFAULT_MAX_ELEMENTS) -> TetMesh:
    """Revolved tetrahedral mesh of ``cartridge`` with ``layers`` elements through the wall.

    ``target_size`` (m) is the axial and circumferential element size (default: twice the
    radial size, 2 t / layers); ``n_theta`` the divisions around (default from the target
    size). The open end is at z = 0, the axis is z. Meshes whose estimated element count
    exceeds ``max_elements`` are refused before any memory is spent.
    """
    layers = _layers(layers)
    h, n_theta = _sizes(cartridge, layers, target_size, n_theta)
    est = estimated_tet_count(cartridge, layers, h, n_theta)
    if est > max_elements:
        raise InvalidParameterError(
            f"invalid mesh size: about {est} elements for layers = {layers}, target_size = {h:g} m, "
            f"n_theta = {n_theta}; must be at most max_elements = {max_elements} (raise it explicitly)")
    z, ri, ro = cartridge.stations()
    nodes, tets, _ = _core.fem_tet_mesh(z, ri, ro, n_theta, layers, h)
    return TetMesh(np.asarray(nodes), np.asarray(tets))


def estimated_shell_count(z: np.ndarray, n_theta: int, target_size: float) -> int:
    """Triangles the revolved shell mesher makes from the profile stations ``z`` (m): two
    per cell of n_theta around by the axial divisions of each station interval (at most
    ``target_size`` long, at least one)."""
    gaps = np.diff(np.asarray(z, float))
    axial = np.maximum(1.0, np.ceil(gaps / target_size))
    return int(2 * n_theta * float(np.sum(axial)))


def cartridge_shell_mesh(cartridge: Cartridge, target_size: Optional[float] = None,
                         n_theta: Optional[int] = None,
                         min_station_gap: float = 0.0,
                         max_elements: int = DEFAULT_MAX_ELEMENTS) -> ShellMesh:
    """Mid-surface triangle mesh of ``cartridge`` with the wall thickness per triangle.

    ``min_station_gap`` (m): profile stations closer than this to the previous kept one are
    dropped (never the ends), e.g. the 0.3 mm crimp step, whose ring of thin triangles
    would set the explicit step; the profile between the kept stations is linear. Meshes
    whose element count (:func:`estimated_shell_count`) exceeds ``max_elements`` are refused
    before any memory is spent."""
    h, n_theta = _sizes(cartridge, 1, target_size, n_theta)
    max_elements = check_count("max_elements", max_elements, 1)
    z, ri, ro = cartridge.stations()
    gap = check_range("min_station_gap", min_station_gap, 0.0, math.inf, lo_open=False)
    if gap > 0 and len(z) > 2:
        keep = [0]
        for i in range(1, len(z) - 1):
            if z[i] - z[keep[-1]] >= gap:
                keep.append(i)
        if z[-1] - z[keep[-1]] < gap and len(keep) > 1:
            keep.pop()
        keep.append(len(z) - 1)
        z, ri, ro = z[keep], ri[keep], ro[keep]
    est = estimated_shell_count(z, n_theta, h)
    if est > max_elements:
        raise InvalidParameterError(
            f"invalid target_size = {h:g} m: the shell mesh would have {est} triangles "
            f"(n_theta = {n_theta} around, {cartridge.length:g} m long), more than "
            f"max_elements = {max_elements}; raise target_size (or lower n_theta), or raise "
            "max_elements explicitly")
    nodes, tri, th = _core.fem_shell_mesh(z, ri, ro, n_theta, h)
    return ShellMesh(np.asarray(nodes), np.asarray(tri), np.asarray(th))


def ball_tet_mesh(radius: float, n: int = 6) -> TetMesh:
    """Tet mesh of a ball of ``radius`` (m) at the origin, 2n cells across (verification)."""
    nodes, tets = _core.fem_ball_mesh(check_positive("radius", radius), int(n))
    return TetMesh(np.asarray(nodes), np.asarray(tets))
