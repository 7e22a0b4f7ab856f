"""The graded tet mesh of the resolved contact FEM (:mod:`demfem.stress.resolved_fem`).

The bodies — :class:`HalfSpaceBlock` (a quarter of a block much larger than the contact) and
:class:`TubeSegment` (a quarter of the cartridge's glass tube) —, the target element sizes
graded toward the contact and its rim (:class:`Grading`, a gmsh MathEval size field; its
element count estimated beforehand by :func:`estimate_elements`) and the mesh itself
(:func:`build_mesh`, gmsh with OpenCASCADE geometry: linear tets for demfem, 10-node tets in
CalculiX/Abaqus node order for CalculiX), with the loaded and inner surfaces' triangles and
the measured edge lengths.

Units: SI (m). gmsh (PyPI ``gmsh``) is imported only by :func:`build_mesh`.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any, Optional

import numpy as np

from demfem.errors import (
    DemfemError,
    InvalidParameterError,
    NumericalError,
    check_positive,
    check_range,
)
from demfem.stress.fem_patch import HertzPatch

__all__ = [
    "HalfSpaceBlock",
    "TubeSegment",
    "Body",
    "Grading",
    "estimate_elements",
    "ResolvedMesh",
    "ABAQUS_EDGES",
    "signed_volume",
    "build_mesh",
    "surface_coordinates",
    "size_expression",
    "mesh_stats",
    "generate_graded",
]


@dataclass(frozen=True)
class HalfSpaceBlock:
    """Quarter of a block x ∈ [0, width], z ∈ [0, width], y ∈ [−depth, 0] (m), loaded on
    y = 0 around the origin and clamped at y = −depth."""

    width: float
    depth: float

    def __post_init__(self) -> None:
        check_positive("width", self.width)
        check_positive("depth", self.depth)

    @property
    def contact_point(self) -> np.ndarray:
        return np.zeros(3)

    @property
    def size(self) -> float:
        return max(self.width, self.depth)


@dataclass(frozen=True)
class TubeSegment:
    """Quarter (x ≥ 0, 0 ≤ z ≤ half_length) of a straight tube of ``outer_radius`` and wall
    ``thickness`` (m), axis z, loaded on its outer surface at (0, outer_radius, 0)."""

    outer_radius: float
    thickness: float
    half_length: float

    def __post_init__(self) -> None:
        check_positive("outer_radius", self.outer_radius)
        check_range("thickness", self.thickness, 0.0, self.outer_radius)
        check_positive("half_length", self.half_length)

    @classmethod
    def from_cartridge(cls, cartridge: Any = None, half_length: float = 15e-3) -> "TubeSegment":
        """The body of a :class:`demfem.cartridge.Cartridge` (the default one when None)."""
        if cartridge is None:
            from demfem.cartridge import Cartridge

            cartridge = Cartridge()
        return cls(0.5 * cartridge.body_outer_diameter, cartridge.wall_thickness, half_length)

    @property
    def inner_radius(self) -> float:
        return self.outer_radius - self.thickness

    @property
    def contact_point(self) -> np.ndarray:
        return np.array([0.0, self.outer_radius, 0.0])

    @property
    def size(self) -> float:
        return max(2.0 * self.outer_radius, self.half_length)


Body = Any  # HalfSpaceBlock | TubeSegment


@dataclass(frozen=True)
class Grading:
    """Target element sizes (m) of the graded mesh (gmsh's size field; realised edges come
    out ≈ 0.8–1.2× the target, the measured ones are in :attr:`ResolvedMesh.stats`).

    ``contact_size`` over the contact (within 1.3 semi-axes of its centre), ``edge_size`` along
    the rim of the contact (where the radial stress peaks), ``wall_size`` within ``wall_zone``
    of the contact (the shell's bending; 0 = none), ``far_size`` elsewhere; between them the
    size grows by ``growth`` per unit distance (dh/dd), away from the rim by ``edge_growth``
    (default: ``growth``; a fixed value is not scaled by :meth:`scaled`: the rim band is a
    thin ring whose cost grows as 1/(edge_size · edge_growth²)).
    """

    contact_size: float
    edge_size: float
    far_size: float
    growth: float = 0.3
    wall_size: float = 0.0
    wall_zone: float = 0.0
    edge_growth: Optional[float] = None

    def __post_init__(self) -> None:
        check_positive("grading.contact_size", self.contact_size)
        check_positive("grading.edge_size", self.edge_size)
        check_positive("grading.far_size", self.far_size)
        check_range("grading.growth", self.growth, 0.01, 1.0, lo_open=False, hi_open=False)
        check_range("grading.wall_size", self.wall_size, 0.0, math.inf, lo_open=False)
        check_range("grading.wall_zone", self.wall_zone, 0.0, math.inf, lo_open=False)
        if self.edge_growth is not None:
            check_range("grading.edge_growth", self.edge_growth, 0.01, 1.0, lo_open=False,
                        hi_open=False)
        for name in ("contact_size", "edge_size", "wall_size"):
            v = getattr(self, name)
            if v > self.far_size:
                raise InvalidParameterError(
                    f"invalid grading.{name} = {v!r}: must be <= grading.far_size = "
                    f"{self.far_size!r} m (a mesh graded toward the contact)")

    def scaled(self, factor: float) -> "Grading":
        """Every size and the growth rate times ``factor``: the whole mesh refined uniformly
        (a mesh level of a convergence study; scaling the sizes but not the growth would leave
        the mesh around the refined zone, whose stiffness pollutes the contact's field,
        unrefined)."""
        f = check_positive("factor", factor)
        return Grading(self.contact_size * f, self.edge_size * f, self.far_size * f,
                       min(self.growth * f, 1.0), self.wall_size * f, self.wall_zone,
                       self.edge_growth)

    @property
    def rim_growth(self) -> float:
        """The growth rate away from the rim (``edge_growth`` or ``growth``)."""
        return self.growth if self.edge_growth is None else self.edge_growth

    @classmethod
    def for_patch(cls, patch: HertzPatch, body: Body, *, per_radius: float = 6.0,
                  edge_ratio: float = 0.1, wall_layers: float = 8.0,
                  wall_zone: Optional[float] = None, far_layers: float = 2.0,
                  growth: Optional[float] = None,
                  edge_growth: Optional[float] = None) -> "Grading":
        """The default grading: ``contact_size`` = a / ``per_radius`` (a: the smaller
        semi-axis), ``edge_size`` = ``edge_ratio`` × that; on a block ``far_size`` = depth / 4
        and ``growth`` 0.3 everywhere; on a tube ``wall_size`` = t / ``wall_layers`` within
        ``wall_zone`` (default 1.25 √(R t), R the mid-surface radius: ≈ 2.3 bending lengths,
        over which the bending field under the load falls to a tenth),
        ``far_size`` = t / ``far_layers``, ``growth`` 0.12 (the wall under the load needs fine
        elements through its whole thickness: the outer surface's bending compression next to
        the contact changed by 15 % from t/8 to t/12 there) and a fixed ``edge_growth`` 0.3
        away from the rim."""
        check_range("per_radius", per_radius, 1.0, math.inf, lo_open=False)
        check_range("edge_ratio", edge_ratio, 0.0, 1.0, hi_open=False)
        a = patch.contact_radius
        hc = a / per_radius
        if isinstance(body, TubeSegment):
            t = body.thickness
            far = t / check_positive("far_layers", far_layers)
            wall = t / check_positive("wall_layers", wall_layers)
            zone = (1.25 * math.sqrt((body.outer_radius - 0.5 * t) * t) if wall_zone is None
                    else check_positive("wall_zone", wall_zone))
            g = 0.12 if growth is None else growth
            eg = 0.3 if edge_growth is None else edge_growth
            return cls(min(hc, far), min(hc * edge_ratio, far), far, g,
                       min(wall, far), zone, eg)
        far = body.depth / 4.0
        return cls(min(hc, far), min(hc * edge_ratio, far), far,
                   0.3 if growth is None else growth, edge_growth=edge_growth)


def size_expression(body: Body, patch: HertzPatch, g: Grading,
                    opposite: bool) -> str:
    """The size field of grading ``g`` (target edge length, m, at (x, y, z) in m) as a gmsh
    MathEval expression (also evaluated with numpy): graded toward the contact centred at
    ``body.contact_point`` (its z = 0), its rim and, on a tube, the wall around it."""
    y0 = float(body.contact_point[1])
    yy = "Abs(y)" if opposite else "y"
    a_s, a_z = patch.semi_axis_s, patch.semi_axis_z
    rc = 1.3
    if patch.kind == "ellipse":
        zone = f"Sqrt(x^2+({yy}-{y0!r})^2+z^2)"
        rz = rc * max(a_s, a_z)
        rho = f"Sqrt((x/{a_s!r})^2+(z/{a_z!r})^2)"
        rim_s = f"(({rho}-1)*{min(a_s, a_z)!r})"
    else:
        zone = f"Sqrt(x^2+({yy}-{y0!r})^2+Max(0,Abs(z)-{a_z!r})^2)"
        rz = rc * a_s
        # distance to the rim of the strip |s| <= b, |z| <= L/2 in the surface
        rim_s = (f"Sqrt(Max(Abs(x)-{a_s!r},0)^2+Max(Abs(z)-{a_z!r},0)^2)"
                 f"+Max(Min({a_s!r}-Abs(x),{a_z!r}-Abs(z)),0)")
    if isinstance(body, TubeSegment):
        depth = f"({body.outer_radius!r}-Sqrt(x^2+y^2))"
    else:
        depth = "(-y)"
    rim = f"Sqrt({rim_s}^2+{depth}^2)"
    parts = [
        f"{g.contact_size!r}+{g.growth!r}*Max(0,{zone}-{rz!r})",
        f"{g.edge_size!r}+{g.rim_growth!r}*{rim}",
        f"{g.far_size!r}",
    ]
    if g.wall_size > 0.0 and g.wall_zone > 0.0:
        parts.append(f"{g.wall_size!r}+{g.growth!r}*Max(0,{zone}-{g.wall_zone!r})")
    expr = parts[0]
    for p in parts[1:]:
        expr = f"Min({expr},{p})"
    return expr


def _eval_expression(expr: str, x: np.ndarray, y: np.ndarray, z: np.ndarray) -> np.ndarray:
    ns = {"Min": np.minimum, "Max": np.maximum, "Sqrt": np.sqrt, "Abs": np.abs,
          "x": x, "y": y, "z": z}
    return np.asarray(eval(expr.replace("^", "**"), {"__builtins__": {}}, ns), dtype=float)


def _inside(body: Body, p: np.ndarray) -> np.ndarray:
    x, y, z = p[..., 0], p[..., 1], p[..., 2]
    if isinstance(body, TubeSegment):
        r = np.hypot(x, y)
        return ((r >= body.inner_radius) & (r <= body.outer_radius) & (x >= 0) & (z >= 0)
                & (z <= body.half_length))
    return (x >= 0) & (x <= body.width) & (z >= 0) & (z <= body.width) & (y <= 0) \
        & (y >= -body.depth)


def _bbox(body: Body) -> tuple[np.ndarray, np.ndarray]:
    if isinstance(body, TubeSegment):
        R = body.outer_radius
        return np.array([0.0, -R, 0.0]), np.array([R, R, body.half_length])
    return np.array([0.0, -body.depth, 0.0]), np.array([body.width, 0.0, body.width])


#: tets per h³ of gmsh's Delaunay mesher at target size h (measured: ≈ 5–6).
_TETS_PER_H3 = 6.0


def estimate_elements(body: Body, patch: HertzPatch, grading: Grading,
                      opposite: bool = False, limit: float = math.inf) -> float:
    """Tets a mesh of this grading will have, ≈ 6 ∫ dV / h³, integrated on an octree refined
    until each cell is below the local size (stops early once above ``limit``)."""
    expr = size_expression(body, patch, grading, opposite)
    lo, hi = _bbox(body)
    span = hi - lo
    n0 = np.maximum(1, np.ceil(span / (span.max() / 4))).astype(int)
    axes = [lo[k] + (np.arange(n0[k]) + 0.5) * span[k] / n0[k] for k in range(3)]
    centers = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 3)
    half = 0.5 * span / n0
    total = 0.0
    sub = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)], float)
    probe = np.concatenate([sub, np.zeros((1, 3))])
    for _ in range(40):
        if len(centers) == 0:
            break
        pts = centers[:, None, :] + 0.999 * probe[None] * half[None, None, :]
        inside = _inside(body, pts)
        frac = inside.mean(1)
        keep = inside.any(1)
        centers, frac = centers[keep], frac[keep]
        h = _eval_expression(expr, *pts[keep].reshape(-1, 3).T).reshape(-1, 9).min(1)
        done = (2.0 * half.max() <= h)
        vol = 8.0 * half.prod()
        total += float(np.sum(frac[done] * vol * _TETS_PER_H3 / h[done] ** 3))
        if total > limit:
            return total
        centers = (centers[~done][:, None, :] + 0.5 * sub[None] * half).reshape(-1, 3)
        half = 0.5 * half
        if len(centers) > 4_000_000:
            return math.inf
    return total


@dataclass
class ResolvedMesh:
    """A graded tet mesh of one body (0-based node ids).

    ``tets`` (E, 4) or (E, 10) in CalculiX/Abaqus node order; ``outer_faces`` and
    ``inner_faces`` (F, 3) or (F, 6): the triangles of the loaded surface (the block's top)
    and of the tube's inner surface (empty for a block); ``stats``: counts, the measured edge
    lengths under the contact and at its rim (m), the worst element quality (gmsh minSICN) and
    the meshing time (s).
    """

    body: Body
    patch: HertzPatch
    grading: Grading
    order: int
    nodes: np.ndarray
    tets: np.ndarray
    outer_faces: np.ndarray
    inner_faces: np.ndarray
    opposite: bool
    stats: dict[str, float] = field(default_factory=dict)


#: corner pairs of the 6 midside nodes of a 10-node tet, in CalculiX/Abaqus order.
ABAQUS_EDGES = [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)]


def _reorder_tet10(X: np.ndarray, T: np.ndarray) -> np.ndarray:
    """gmsh's 10-node tets in Abaqus/CalculiX order (midside nodes 5–10 on edges 1-2, 2-3,
    3-1, 1-4, 2-4, 3-4), found geometrically from the first element and checked on all."""
    mids = T[:, 4:]
    perm = []
    for i, j in ABAQUS_EDGES:
        m = 0.5 * (X[T[0, i]] + X[T[0, j]])
        perm.append(int(np.argmin(np.linalg.norm(X[mids[0]] - m, axis=1))))
    if sorted(perm) != list(range(6)):
        raise NumericalError("cannot match gmsh's 10-node tet edges to CalculiX's order")
    out = np.concatenate([T[:, :4], mids[:, perm]], axis=1)
    for k, (i, j) in enumerate(ABAQUS_EDGES):
        m = 0.5 * (X[out[:, i]] + X[out[:, j]])
        L = np.linalg.norm(X[out[:, i]] - X[out[:, j]], axis=1)
        if np.any(np.linalg.norm(X[out[:, 4 + k]] - m, axis=1) > 0.25 * L):
            raise NumericalError("gmsh's 10-node tets do not share one node order")
    return out


def signed_volume(X: np.ndarray, T: np.ndarray) -> np.ndarray:
    """Signed volumes (E,) of the tets T (E, ≥4; corners first) of nodes X (N, 3), m³
    (positive when the corners are in right-handed order)."""
    a, b, c, d = (X[T[:, k]] for k in range(4))
    return np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a) / 6.0



def generate_graded(expr: str, grading: Grading, order: int = 1, algorithm_3d: int = 1,
                    threads: int = 1) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Mesh the open gmsh model (its geometry synchronised) with the MathEval size field
    ``expr`` (:func:`size_expression`) as the only size source, bounded by ``grading``'s
    smallest and far sizes: tets of ``order`` 1 or 2, gmsh's 3-D ``algorithm_3d`` on
    ``threads``. Returns the nodes X (m), the tets T (rows of node indices), each tet's
    minSICN quality and the map from gmsh node tags to indices. Refused
    (InvalidParameterError naming the grading): a grading gmsh cannot mesh, or no tets."""
    import gmsh

    g = grading
    fld = gmsh.model.mesh.field.add("MathEval")
    gmsh.model.mesh.field.setString(fld, "F", expr)
    gmsh.model.mesh.field.setAsBackgroundMesh(fld)
    for k in ("Mesh.MeshSizeExtendFromBoundary", "Mesh.MeshSizeFromPoints",
              "Mesh.MeshSizeFromCurvature"):
        gmsh.option.setNumber(k, 0)
    gmsh.option.setNumber("Mesh.MeshSizeMin", 0.5 * min(g.contact_size, g.edge_size))
    gmsh.option.setNumber("Mesh.MeshSizeMax", g.far_size)
    gmsh.option.setNumber("Mesh.Algorithm", 6)
    gmsh.option.setNumber("Mesh.Algorithm3D", algorithm_3d)
    gmsh.option.setNumber("General.NumThreads", int(threads))
    gmsh.option.setNumber("Mesh.ElementOrder", order)
    gmsh.option.setNumber("Mesh.SecondOrderLinear", 0)
    try:
        gmsh.model.mesh.generate(3)
    except Exception as e:  # gmsh raises plain Exception
        raise InvalidParameterError(
            f"invalid grading.contact_size = {g.contact_size!r} m: gmsh could not mesh "
            f"this grading ({e})") from None
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    tags = tags.astype(np.int64)
    index = np.full(int(tags.max()) + 1, -1, dtype=np.int64)
    index[tags] = np.arange(len(tags))
    X = xyz.reshape(-1, 3).copy()
    etags, enodes = gmsh.model.mesh.getElementsByType(4 if order == 1 else 11)
    T = index[enodes.astype(np.int64)].reshape(-1, 4 if order == 1 else 10)
    if len(T) == 0:
        raise InvalidParameterError(
            f"invalid grading.contact_size = {g.contact_size!r} m: gmsh made no tets")
    q = np.asarray(gmsh.model.mesh.getElementQualities(etags, "minSICN"), float)
    return X, T, q, index

def build_mesh(body: Body, patch: HertzPatch, grading: Optional[Grading] = None, *,
               order: int = 1, opposite: bool = False, conforming_rim: Optional[bool] = None,
               max_elements: float = 2.0e6, threads: int = 1, min_quality: float = 0.01,
               algorithm_3d: int = 1) -> ResolvedMesh:
    """A tet mesh of ``body`` graded toward ``patch`` (gmsh, OpenCASCADE geometry).

    ``order`` 1 (demfem's Tet4) or 2 (C3D10 for CalculiX); ``opposite``: refine around an
    identical contact at the tube's bottom too; ``conforming_rim`` puts surface nodes on the
    rim of an elliptical contact by splitting the volume with a short cylinder through the
    patch (off by default: the recovery evaluates the stresses on the rim itself,
    :func:`rim_points`, and gmsh's mesher fails on the finest such splits). Refused
    (InvalidParameterError naming the grading field): a grading whose estimated element count exceeds ``max_elements``; a
    contact size below 1e-5 of the body (below gmsh's geometric tolerance); a mesh gmsh cannot
    make or whose worst element (minSICN) is below ``min_quality``. ``algorithm_3d``: gmsh's
    3-D mesher (1 Delaunay, the default; 10 HXT); ``threads``: gmsh's threads (1, the default,
    makes the same mesh every time).
    """
    try:
        import gmsh
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise DemfemError("the resolved FEM needs gmsh: pip install gmsh") from e
    if order not in (1, 2):
        raise InvalidParameterError(f"invalid order = {order!r}: must be 1 or 2")
    g = grading if grading is not None else Grading.for_patch(patch, body)
    if conforming_rim is None:
        conforming_rim = False
    if conforming_rim and patch.kind != "ellipse":
        raise InvalidParameterError("invalid conforming_rim = True: only for an elliptical "
                                    "contact (a line contact's rim runs along the body)")
    if not isinstance(body, (HalfSpaceBlock, TubeSegment)):
        raise InvalidParameterError(f"invalid body = {body!r}: must be a HalfSpaceBlock or "
                                    "a TubeSegment")
    if opposite and not isinstance(body, TubeSegment):
        raise InvalidParameterError("invalid opposite = True: only a TubeSegment has an "
                                    "opposite side")
    for name in ("contact_size", "edge_size"):
        v = getattr(g, name)
        if v < 1e-5 * body.size:
            raise InvalidParameterError(
                f"invalid grading.{name} = {v!r}: must be >= {1e-5 * body.size:.3g} m "
                "(1e-5 of the body; gmsh's geometric tolerance)")
    if isinstance(body, TubeSegment):
        if patch.kind == "ellipse" and max(patch.semi_axis_s, patch.semi_axis_z) >= \
                0.5 * body.outer_radius:
            raise InvalidParameterError(
                f"invalid patch: semi-axes {patch.semi_axis_s:.3g}, {patch.semi_axis_z:.3g} m "
                f"must be < R/2 = {0.5 * body.outer_radius:.3g} m on the tube")
        if patch.kind == "line" and patch.semi_axis_z >= body.half_length:
            raise InvalidParameterError(
                f"invalid patch: half the contact length {patch.semi_axis_z:.3g} m must be < "
                f"the tube's half_length = {body.half_length:.3g} m")
    n_est = estimate_elements(body, patch, g, opposite, limit=max_elements)
    if n_est > max_elements:
        raise InvalidParameterError(
            f"invalid grading.contact_size = {g.contact_size!r} m (with edge_size "
            f"{g.edge_size!r}, wall_size {g.wall_size!r}, growth {g.growth!r}): about "
            f"{n_est:.3g} elements, above max_elements = {max_elements:.3g}; coarsen the "
            "grading or raise max_elements")
    expr = size_expression(body, patch, g, opposite)
    t0 = time.perf_counter()
    initialized_here = not gmsh.isInitialized()
    if initialized_here:
        gmsh.initialize(interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("resolved_contact")
        occ = gmsh.model.occ
        if isinstance(body, TubeSegment):
            R, Ri, L = body.outer_radius, body.inner_radius, body.half_length
            outer = occ.addCylinder(0, 0, 0, 0, 0, L, R)
            inner = occ.addCylinder(0, 0, 0, 0, 0, L, Ri)
            tube, _ = occ.cut([(3, outer)], [(3, inner)])
            box = occ.addBox(0, -2 * R, -L, 2 * R, 4 * R, 3 * L)
            occ.intersect(tube, [(3, box)])
        else:
            occ.addBox(0, -body.depth, 0, body.width, body.depth, body.width)
        if conforming_rim:
            # a short cylinder along y through the contact (an ellipse after scaling): its
            # trace on the loaded surface is the rim of the contact, so that surface nodes
            # lie on the rim, where the radial stress has its cusp
            y0 = float(body.contact_point[1])
            a_ref = patch.semi_axis_s
            cyl = occ.addCylinder(0, y0 - 0.5 * patch.contact_radius, 0, 0,
                                  1.5 * patch.contact_radius, 0, a_ref)
            if patch.semi_axis_z != patch.semi_axis_s:
                occ.dilate([(3, cyl)], 0, y0, 0, 1.0, 1.0, patch.semi_axis_z / a_ref)
            vols = occ.getEntities(3)
            body_vols = [v for v in vols if v[1] != cyl]
            pieces, _ = occ.intersect([(3, cyl)], [(d, t) for d, t in body_vols],
                                      removeObject=True, removeTool=False)
            occ.fragment([(d, t) for d, t in occ.getEntities(3) if (d, t) not in pieces],
                         pieces)
        occ.synchronize()
        X, T, q, index = generate_graded(expr, g, order, algorithm_3d, threads)
        npe = T.shape[1]
        ftype = 2 if order == 1 else 9
        outer_f, inner_f = [], []
        for dim, stag in gmsh.model.getEntities(2):
            _, fn = gmsh.model.mesh.getElementsByType(ftype, stag)
            F = index[fn.astype(np.int64)].reshape(-1, 3 if order == 1 else 6)
            if len(F) == 0:
                continue
            P = X[F[:, :3].ravel()]
            if isinstance(body, TubeSegment):
                r = np.hypot(P[:, 0], P[:, 1])
                tol = 1e-6 * body.outer_radius
                if np.all(np.abs(r - body.outer_radius) < tol):
                    outer_f.append(F)
                elif np.all(np.abs(r - body.inner_radius) < tol):
                    inner_f.append(F)
            elif np.all(np.abs(P[:, 1]) < 1e-9 * body.size):
                outer_f.append(F)
    finally:
        gmsh.model.remove()
        if initialized_here:
            gmsh.finalize()
    t_mesh = time.perf_counter() - t0
    qmin = float(q.min())
    if qmin < min_quality:
        raise InvalidParameterError(
            f"invalid grading.growth = {g.growth!r}: the mesh's worst element has minSICN "
            f"{qmin:.3g} < {min_quality} (too abrupt a grading for the mesher)")
    # positive orientation (demfem and CalculiX both want it)
    neg = signed_volume(X, T) < 0
    if np.any(neg):
        T = T.copy()
        if npe == 4:
            T[neg] = T[neg][:, [0, 2, 1, 3]]
        else:
            # swap corners 1,2 and the midside nodes that follow them
            T[neg] = T[neg][:, [0, 2, 1, 3, 6, 5, 4, 7, 9, 8]]
    if npe == 10:
        T = _reorder_tet10(X, T)
    # drop nodes no element uses (gmsh keeps geometry points)
    used = np.zeros(len(X), bool)
    used[T.ravel()] = True
    if not used.all():
        new = np.cumsum(used) - 1
        X = X[used]
        T = new[T]
        outer_f = [new[f] for f in outer_f]
        inner_f = [new[f] for f in inner_f]
    fo = np.concatenate(outer_f) if outer_f else np.zeros((0, 3 * order), np.int64)
    fi = np.concatenate(inner_f) if inner_f else np.zeros((0, 3 * order), np.int64)
    mesh = ResolvedMesh(body, patch, g, order, X, T.astype(np.int64), fo.astype(np.int64),
                        fi.astype(np.int64), opposite)
    mesh.stats = mesh_stats(mesh, qmin, t_mesh, n_est)
    return mesh


def surface_coordinates(body: Body, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(s, z) of points on the loaded surface, m: their projection on the plane tangent at the
    contact (s = x, z), Hertz's coordinates (on the tube s differs from the arc length by
    (x/R)²/6, < 1e-3 over a contact)."""
    return X[:, 0], X[:, 2]


def mesh_stats(mesh: ResolvedMesh, qmin: float, t_mesh: float, n_est: float
               ) -> dict[str, float]:
    """Counts and measured edge lengths (m) of a mesh: under the contact and at its rim on
    ``mesh.outer_faces``, on the tube's inner surface under the load; ``qmin`` (the worst
    minSICN), the meshing time ``t_mesh`` (s) and the estimated tet count ``n_est`` as given."""
    X, F = mesh.nodes, mesh.outer_faces[:, :3]
    p = mesh.patch
    edges = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    mid = 0.5 * (X[edges[:, 0]] + X[edges[:, 1]])
    L = np.linalg.norm(X[edges[:, 0]] - X[edges[:, 1]], axis=1)
    s, z = surface_coordinates(mesh.body, mid)
    if p.kind == "ellipse":
        rho = np.hypot(s / p.semi_axis_s, z / p.semi_axis_z)
    else:
        rho = np.where(np.abs(z) <= p.semi_axis_z, np.abs(s) / p.semi_axis_s, np.inf)
    inside = rho < 1.0
    rim = np.abs(rho - 1.0) < 0.15
    a = p.contact_radius
    out = {
        "nodes": float(len(X)), "tets": float(len(mesh.tets)), "estimated_tets": float(n_est),
        "min_quality": qmin, "mesh_time_s": t_mesh, "contact_radius_m": a,
        "edge_mean_in_contact_m": float(L[inside].mean()) if inside.any() else math.nan,
        "edge_max_in_contact_m": float(L[inside].max()) if inside.any() else math.nan,
        "edge_mean_at_rim_m": float(L[rim].mean()) if rim.any() else math.nan,
    }
    out["contact_radius_per_edge"] = a / out["edge_mean_in_contact_m"] \
        if inside.any() else 0.0
    if isinstance(mesh.body, TubeSegment) and len(mesh.inner_faces):
        Fi = mesh.inner_faces[:, :3]
        ei = np.concatenate([Fi[:, [0, 1]], Fi[:, [1, 2]], Fi[:, [2, 0]]])
        mi = 0.5 * (X[ei[:, 0]] + X[ei[:, 1]])
        Li = np.linalg.norm(X[ei[:, 0]] - X[ei[:, 1]], axis=1)
        near = np.hypot(mi[:, 0], mi[:, 2]) < mesh.body.thickness
        out["inner_edge_mean_under_load_m"] = float(Li[near].mean()) if near.any() \
            else math.nan
    return out
