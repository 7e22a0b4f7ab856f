"""A resolved FEM of one contact at a place on the real cartridge: near the open rim, below the
shoulder, or mid-body (the reference).

The quarter-tube FEM of :mod:`demfem.stress.resolved_fem` is a straight tube loaded at its
middle; contacts between upright neighbours land mostly at the open end of the body (the rim)
and at the body–shoulder junction (docs/cartridge-places.md), where no closed form holds. This
module meshes the cartridge's glass itself and loads it there.

* **Body** — the whole glass of a :class:`demfem.cartridge.Cartridge` (its profile
  :meth:`~demfem.cartridge.Cartridge.stations`: body, conical shoulder, neck, flange; the
  open end a flat annulus at z = 0), a **half model** x ≥ 0: the plane x = 0 through the axis
  and the contact centre is the only symmetry plane (the pressure and an axial traction are
  both symmetric about it). The mesh's frame is the cartridge's shifted along its axis so that
  the contact centre is (0, R, 0) (R the body's outer radius): the recovery functions of
  :mod:`demfem.stress.fem_recovery` take their surface coordinates from there. The mesh's
  ``body`` is the :class:`~demfem.stress.fem_mesh.TubeSegment` of the cylindrical body (the
  geometry of the surfaces the contact and the fits live on: their normals are radial).
* **Places** (:func:`contact_height`): ``"rim"`` — the contact centre s from the open end
  face, default s = max(t/2, 1.5 a) (the end is fire-polished, rounded with radius ≈ t/2, so
  the cylinder a contact can land on ends ≈ t/2 from the end face; the model keeps the end
  flat and puts the whole Hertz circle on the cylinder); ``"shoulder"`` — s below the
  body–shoulder junction (z = body_length − s), same default; ``"body"`` — mid-body
  (z = body_length / 2), the reference.
* **Mesh** — gmsh (OpenCASCADE: the wall's profile revolved by 180°), the size field of
  :func:`~demfem.stress.fem_mesh.size_expression` for a :class:`~demfem.stress.fem_mesh.
  Grading` (:meth:`Grading.for_patch` of the tube by default: the same grading at every
  place, so that place-to-body ratios share the mesh's bias), linear tets.
* **Load** — the Hertz pressure of a crossed-cylinder point contact
  (:func:`~demfem.stress.fem_patch.crossed_cylinders_patch`, a circle of radius a) as
  consistent nodal forces (:func:`~demfem.stress.fem_load.contact_loads`, its quarter
  resultant doubled for the half), and a sliding traction q = μ p along the axis (solved at
  μ = 1, scaled; both directions from one solve: σ = σ_N ± μ σ_T).
* **Support** — free, inertia relief (:func:`~demfem.stress.fem_load.inertia_relief`): the
  plane x = 0 leaves three rigid modes (translation along y and z, rotation about x), which
  the d'Alembert body force balances; their reactions at the far dofs are checked to vanish.
* **Quasi-static** — as in :mod:`~demfem.stress.resolved_fem` (contact 30–100 µs, the wall's
  local bending period under the load ≈ 5 µs).
* **Stresses** — the in-plane surface stresses of the outer and inner *cylinders* recovered
  by :func:`~demfem.stress.fem_recovery.surface_fit_stresses` (on the rim of the contact too,
  smoothed along it by :func:`~demfem.stress.fem_recovery.smooth_rim`); on the other surfaces
  (the end face, the shoulder, neck and flange, inside and out) the volume-averaged nodal
  stresses' in-plane part (normals from the mesh's triangles). Per surface (outer: the
  outer cylinder, the outer half of the flat end faces and the outside of shoulder, neck and
  flange; inner: the inside and the end faces' inner half — the fire-polished end is a
  rounding from one surface to the other) the peak σ1, where it is, and the Weibull effective area
  A_eff = ∫ ⟨σ1/σ1,max⟩^m dA over the whole surface (twice the half's), m².

Units: SI (m, N, Pa, m²). gmsh is imported only by :func:`build_place_mesh`.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace
from typing import Any, Optional, Sequence

import numpy as np

from demfem.errors import DemfemError, InvalidParameterError, NumericalError, check_positive
from demfem.stress.fem_load import contact_loads, inertia_relief, surface_pressure
from demfem.stress.fem_mesh import (
    Grading,
    ResolvedMesh,
    TubeSegment,
    estimate_elements,
    generate_graded,
    mesh_stats,
    signed_volume,
    size_expression,
)
from demfem.stress.fem_patch import HertzPatch, check_material, crossed_cylinders_patch
from demfem.stress.fem_quadrature import subdivided_triangle_rule, tri_shape
from demfem.stress.fem_recovery import (
    in_plane_sigma1,
    nodal_average,
    rim_points,
    smooth_rim,
    surface_fit_stresses,
)

__all__ = [
    "PLACES",
    "contact_height",
    "PlaceMesh",
    "PlacePeak",
    "PlaceResult",
    "build_place_mesh",
    "solve_place",
    "place_case",
    "default_distance",
    "FAR_DISTANCE_WALLS",
]

#: Places of a contact on the cartridge (:func:`contact_height`).
PLACES = ("body", "rim", "shoulder")


def _cartridge(cartridge: Any) -> Any:
    from demfem.cartridge import Cartridge

    c = Cartridge() if cartridge is None else cartridge
    if not isinstance(c, Cartridge):
        raise InvalidParameterError(f"invalid cartridge = {cartridge!r}: must be a "
                                    "demfem.cartridge.Cartridge")
    return c


def default_distance(cartridge: Any, contact_radius: float) -> float:
    """s = max(t/2, 1.5 a), m: the rim and shoulder contacts' distance from the end face,
    resp. below the body–shoulder junction (t the wall, a the contact radius, m)."""
    c = _cartridge(cartridge)
    return max(0.5 * c.wall_thickness, 1.5 * check_positive("contact_radius", contact_radius))


def contact_height(cartridge: Any, place: str, contact_radius: float,
                   distance: Optional[float] = None) -> float:
    """Height z (m, from the open end face, :meth:`Cartridge.stations`'s frame) of the
    contact centre at ``place``: "rim" z = s, "shoulder" z = body_length − s (s =
    ``distance``, default :func:`default_distance`), "body" z = body_length / 2 (``distance``
    refused). The whole contact circle (radius ``contact_radius``, m) must lie on the body's
    cylinder."""
    c = _cartridge(cartridge)
    a = check_positive("contact_radius", contact_radius)
    if place not in PLACES:
        raise InvalidParameterError(f"invalid place = {place!r}: must be one of "
                                    f"{', '.join(map(repr, PLACES))}")
    L = c.body_length
    if place == "body":
        if distance is not None:
            raise InvalidParameterError(f"invalid distance = {distance!r}: only for place "
                                        "'rim' or 'shoulder' (the body's contact is mid-body)")
        return 0.5 * L
    s = default_distance(c, a) if distance is None else check_positive("distance", distance)
    if s < a * (1.0 + 1e-9) or s > L - a:
        raise InvalidParameterError(
            f"invalid distance = {s!r} m: the contact circle (a = {a:.4g} m) must lie on the "
            f"body's cylinder: a <= distance <= body_length - a = {L - a:.4g} m")
    return s if place == "rim" else L - s


@dataclass
class PlaceMesh:
    """The half model's mesh at one place (:func:`build_place_mesh`).

    ``mesh``: the :class:`~demfem.stress.fem_mesh.ResolvedMesh` (nodes in the contact's
    frame: the cartridge's z minus ``z_contact``; ``outer_faces``/``inner_faces`` the outer
    and inner *cylinder* of the body, ``body`` its :class:`TubeSegment`); ``other_outer`` and
    ``other_inner`` (F, 3): the triangles of the other surfaces outside (the outer half of
    the flat end faces, the outside of shoulder, neck and flange) and inside (the inner half
    of the end faces, the inside of shoulder, neck and flange); ``z_contact`` (m) the contact centre's
    height on the cartridge, ``distance`` (m) its distance from the end face (rim), below the
    junction (shoulder) or NaN (body)."""

    mesh: ResolvedMesh
    place: str
    z_contact: float
    distance: float
    cartridge: Any
    other_outer: np.ndarray
    other_inner: np.ndarray
    stats: dict[str, float] = field(default_factory=dict)


def _profile(cartridge: Any) -> list[tuple[float, float]]:
    """The wall's cross-section (r, z), m, counter-clockwise: up the inside, down the
    outside."""
    z, ri, ro = cartridge.stations()
    pts = [(float(r), float(zz)) for r, zz in zip(ri, z)]
    pts += [(float(r), float(zz)) for r, zz in zip(ro[::-1], z[::-1])]
    out: list[tuple[float, float]] = []
    for p in pts:
        if not out or (abs(p[0] - out[-1][0]) + abs(p[1] - out[-1][1])) > 1e-12:
            out.append(p)
    return out


def build_place_mesh(patch: HertzPatch, place: str, *, cartridge: Any = None,
                     distance: Optional[float] = None, grading: Optional[Grading] = None,
                     max_elements: float = 1.5e6, min_quality: float = 0.01) -> PlaceMesh:
    """The half model of ``cartridge``'s glass (x ≥ 0) meshed with linear tets, graded toward
    the circular contact ``patch`` at ``place`` (:func:`contact_height`). ``grading``: default
    :meth:`Grading.for_patch` on the body's tube. Refused (InvalidParameterError naming the
    field): an elliptical or line patch (crossed cylinders at 90° only), a grading whose
    estimated size is above ``max_elements`` tets, a mesh gmsh cannot make or whose worst
    element (minSICN) is below ``min_quality``."""
    try:
        import gmsh
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise DemfemError("the place FEM needs gmsh: pip install gmsh") from e
    c = _cartridge(cartridge)
    if patch.kind != "ellipse" or abs(patch.semi_axis_s - patch.semi_axis_z) > \
            1e-9 * patch.semi_axis_s:
        raise InvalidParameterError("invalid patch: the place FEM takes a circular contact "
                                    "(crossed cylinders at 90°, crossed_cylinders_patch)")
    a = patch.contact_radius
    zc = contact_height(c, place, a, distance)
    R, t = 0.5 * c.body_outer_diameter, c.wall_thickness
    tube = TubeSegment(R, t, c.length)
    g = grading if grading is not None else Grading.for_patch(patch, tube)
    # the graded zone of the half ≈ twice the quarter tube's; the rest of the cartridge at
    # the far size
    n_est = 2.0 * estimate_elements(TubeSegment(R, t, min(zc, c.body_length - zc, 15e-3)),
                                    patch, g, limit=max_elements)
    n_est += 6.0 * 0.5 * math.pi * (R * R - (R - t) ** 2) * c.length / g.far_size ** 3
    if n_est > max_elements:
        raise InvalidParameterError(
            f"invalid grading.contact_size = {g.contact_size!r} m: about {n_est:.3g} tets, "
            f"above max_elements = {max_elements:.3g}; coarsen the grading")
    expr = size_expression(tube, patch, g, False)
    t0 = time.perf_counter()
    here = not gmsh.isInitialized()
    if here:
        gmsh.initialize(interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("place_contact")
        occ = gmsh.model.occ
        prof = _profile(c)
        pts = [occ.addPoint(r, 0.0, z) for r, z in prof]
        lines = [occ.addLine(pts[k], pts[(k + 1) % len(pts)]) for k in range(len(pts))]
        surf = occ.addPlaneSurface([occ.addCurveLoop(lines)])
        occ.revolve([(2, surf)], 0, 0, 0, 0, 0, 1, math.pi)
        vols = occ.getEntities(3)
        occ.rotate(vols, 0, 0, 0, 0, 0, 1, -0.5 * math.pi)
        occ.translate(vols, 0, 0, -zc)
        occ.synchronize()
        X, T, q, index = generate_graded(expr, g, order=1, algorithm_3d=1, threads=1)
        qmin = float(np.min(q))
        groups: dict[str, list[np.ndarray]] = {"outer": [], "inner": [], "other_outer": [],
                                               "other_inner": []}
        tol = 1e-6 * R
        for _, stag in gmsh.model.getEntities(2):
            _, fn = gmsh.model.mesh.getElementsByType(2, stag)
            F = index[fn.astype(np.int64)].reshape(-1, 3)
            if len(F) == 0:
                continue
            P = X[F.ravel()]
            if np.all(np.abs(P[:, 0]) < tol):
                continue  # the symmetry plane
            r = np.hypot(P[:, 0], P[:, 1])
            zz = P[:, 2] + zc
            body = np.all(zz <= c.body_length + tol)
            ri, ro = c.radii_at(np.clip(zz, 0.0, c.length))
            if body and np.all(np.abs(r - R) < tol):
                groups["outer"].append(F)
            elif body and np.all(np.abs(r - (R - t)) < tol):
                groups["inner"].append(F)
            elif np.all(r <= ri + tol):
                groups["other_inner"].append(F)
            elif np.ptp(zz) < tol:
                # a flat end (the open end face; the flange's top): its inner half goes with
                # the inner surface, its outer half with the outer (the fire-polished end is
                # a rounding from one surface to the other)
                rc = np.hypot(*X[F].mean(1)[:, :2].T)
                zc_ = float(np.mean(zz))
                r_in, r_out = c.radii_at(np.array([min(max(zc_, 0.0), c.length)]))
                inner_half = rc < 0.5 * (float(r_in[0]) + float(r_out[0]))
                groups["other_inner"].append(F[inner_half])
                groups["other_outer"].append(F[~inner_half])
            else:
                groups["other_outer"].append(F)
    finally:
        gmsh.model.remove()
        if here:
            gmsh.finalize()
    t_mesh = time.perf_counter() - t0
    if qmin < min_quality:
        raise InvalidParameterError(
            f"invalid grading.growth = {g.growth!r}: the mesh's worst element has minSICN "
            f"{qmin:.3g} < {min_quality}")
    neg = signed_volume(X, T) < 0
    if np.any(neg):
        T = T.copy()
        T[neg] = T[neg][:, [0, 2, 1, 3]]
    used = np.zeros(len(X), bool)
    used[T.ravel()] = True
    new = np.cumsum(used) - 1
    X, T = X[used], new[T]
    faces = {k: (new[np.concatenate(v)] if v else np.zeros((0, 3), np.int64)).astype(np.int64)
             for k, v in groups.items()}
    if len(faces["outer"]) == 0 or len(faces["inner"]) == 0:
        raise NumericalError("place mesh: no triangles on the body's outer or inner cylinder")
    mesh = ResolvedMesh(tube, patch, g, 1, X, T.astype(np.int64), faces["outer"],
                        faces["inner"], False)
    mesh.stats = mesh_stats(mesh, qmin, t_mesh, n_est)
    s = zc if place == "rim" else (c.body_length - zc if place == "shoulder" else math.nan)
    return PlaceMesh(mesh, place, zc, s, c, faces["other_outer"], faces["other_inner"],
                     dict(mesh.stats))


# --------------------------------------------------------------------------------------------
# peaks and effective areas on the half model
# --------------------------------------------------------------------------------------------


@dataclass
class PlacePeak:
    """The largest σ1 on one surface (Pa), where: ``position`` (m, the contact's frame: the
    contact centre at (0, R, 0), z along the cartridge's axis toward the shoulder),
    ``distance`` (m, from the contact centre), ``face`` (which surface: "outer cylinder",
    "contact rim", "inner cylinder", or "end face", "shoulder", "neck" …, outside or inside)
    and the effective area (m²) of the whole surface for ``weibull_modulus``; ``far_sigma1``
    (Pa) and ``far_area`` (m², for its own peak): the same over the surface farther than
    :data:`FAR_DISTANCE_WALLS` wall thicknesses from the contact centre (the wall's bending
    field away from the contact: the model's ``outer_ring_Pa``)."""

    sigma1_max: float
    position: np.ndarray
    distance: float
    face: str
    effective_area: float
    weibull_modulus: float
    far_sigma1: float = math.nan
    far_area: float = math.nan

    def as_dict(self) -> dict[str, Any]:
        return {"sigma1_max_Pa": self.sigma1_max,
                "position_m": [float(v) for v in self.position],
                "distance_m": self.distance, "face": self.face,
                "dz_m": float(self.position[2]),
                "effective_area_m2": self.effective_area,
                "weibull_modulus": self.weibull_modulus,
                "far_sigma1_Pa": self.far_sigma1, "far_effective_area_m2": self.far_area}


def _vertex_normals(X: np.ndarray, F: np.ndarray) -> np.ndarray:
    """Unit normals (N, 3; either sign, zero off F) at the nodes of triangles F: the main
    axis of the area-weighted Σ n nᵀ of the triangles around each node (independent of the
    triangles' orientation; at an edge between two surfaces, their average direction)."""
    n = np.cross(X[F[:, 1]] - X[F[:, 0]], X[F[:, 2]] - X[F[:, 0]])
    area = np.linalg.norm(n, axis=1)
    nn = n / np.where(area > 0, area, 1.0)[:, None]
    M = np.zeros((len(X), 3, 3))
    for i in range(3):
        for j in range(3):
            M[:, i, j] = np.bincount(F.ravel(), np.repeat(area * nn[:, i] * nn[:, j], 3),
                                     minlength=len(X))
    nodes = np.unique(F)
    out = np.zeros((len(X), 3))
    _, v = np.linalg.eigh(M[nodes])
    out[nodes] = v[:, :, -1]
    return out


#: "Away from the contact": farther than this many wall thicknesses from its centre.
FAR_DISTANCE_WALLS = 2.0


def _triangle_area_sum(X: np.ndarray, F: np.ndarray, s1: np.ndarray, smax: float,
                       m: float) -> float:
    """∫ ⟨σ1/σmax⟩^m dA over triangles F (σ1 per node, linear over each), m²."""
    if len(F) == 0 or smax <= 0.0:
        return 0.0
    xi_eta, w = subdivided_triangle_rule(1)
    N, _ = tri_shape(xi_eta[:, 0], xi_eta[:, 1], 1)
    A = 0.5 * np.linalg.norm(np.cross(X[F[:, 1]] - X[F[:, 0]], X[F[:, 2]] - X[F[:, 0]]),
                             axis=1)
    sq = np.einsum("qk,ek->eq", N, s1[F])
    return float(np.sum(2.0 * A[:, None] * w[None, :] * (np.maximum(sq, 0.0) / smax) ** m))


def _face_name(pm: PlaceMesh, pos: np.ndarray, outer: bool, group: str) -> str:
    if group in ("outer cylinder", "contact rim", "inner cylinder"):
        return group
    c = pm.cartridge
    z = float(pos[2]) + pm.z_contact
    side = "outside" if outer else "inside"
    tol = 1e-6 * c.length
    if z < tol:
        return f"open end face ({side} half)"
    if z <= c.body_length + tol:
        return f"body {side}"
    if z <= c.body_length + c.shoulder_length + tol:
        return f"shoulder {side}"
    if z <= c.body_length + c.shoulder_length + c.neck_length + tol:
        return f"neck {side}"
    return f"flange {side}" if z < c.length - tol else "flange end face"


def _half_peak(pm: PlaceMesh, outer: bool, s_fit: np.ndarray, s_avg: np.ndarray,
               rim_pts: np.ndarray, rim_s: Optional[np.ndarray], m: float) -> PlacePeak:
    """Peak σ1 and effective area (the half ×2) of the outer or inner surface: the cylinder
    from the surface fit ``s_fit`` (N, 6), the contact's rim from its points' fits ``rim_s``
    (smoothed along it), the other surfaces from the nodal averages ``s_avg``."""
    mesh = pm.mesh
    X = mesh.nodes
    cyl = mesh.outer_faces if outer else mesh.inner_faces
    other = pm.other_outer if outer else pm.other_inner
    s1_cyl = np.zeros(len(X))
    nc = np.unique(cyl)
    rad = np.stack([X[nc, 0], X[nc, 1], np.zeros(len(nc))], -1)
    s1_cyl[nc] = in_plane_sigma1(s_fit[nc], rad)
    s1_oth = np.zeros(len(X))
    no = np.unique(other) if len(other) else np.zeros(0, np.int64)
    if len(no):
        s1_oth[no] = in_plane_sigma1(s_avg[no], _vertex_normals(X, other)[no])
    cand = nc
    p = mesh.patch
    if outer and rim_s is not None and len(rim_pts):
        rho = np.hypot(X[nc, 0] / p.semi_axis_s, X[nc, 2] / p.semi_axis_z)
        rho = np.where(X[nc, 1] > 0, rho, np.inf)
        cand = nc[np.abs(rho - 1.0) > 0.1]
    best: tuple[float, np.ndarray, str] = (-math.inf, np.zeros(3), "")
    cyl_name = "outer cylinder" if outer else "inner cylinder"
    if len(cand):
        j = int(np.argmax(s1_cyl[cand]))
        best = (float(s1_cyl[cand[j]]), X[cand[j]].copy(), cyl_name)
    if len(no):
        j = int(np.argmax(s1_oth[no]))
        if s1_oth[no[j]] > best[0]:
            best = (float(s1_oth[no[j]]), X[no[j]].copy(), "other")
    if outer and rim_s is not None and len(rim_pts):
        v = in_plane_sigma1(rim_s, np.stack([rim_pts[:, 0], rim_pts[:, 1],
                                             np.zeros(len(rim_pts))], -1))
        phi = np.arctan2(rim_pts[:, 2] / p.semi_axis_z, rim_pts[:, 0] / p.semi_axis_s)
        phi_r, sm = smooth_rim(np.concatenate([phi, math.pi - phi]), np.concatenate([v, v]))
        if sm > best[0]:
            x, z = p.semi_axis_s * math.cos(phi_r), p.semi_axis_z * math.sin(phi_r)
            best = (sm, np.array([abs(x), math.sqrt(mesh.body.outer_radius ** 2 - x * x), z]),
                    "contact rim")
    smax, pos, grp = best
    area = 2.0 * (_triangle_area_sum(X, cyl, s1_cyl, smax, m)
                  + _triangle_area_sum(X, other, s1_oth, smax, m))
    dist = float(np.linalg.norm(pos - mesh.body.contact_point))
    # the field away from the contact
    d_far = FAR_DISTANCE_WALLS * mesh.body.thickness
    s1 = np.maximum(s1_cyl, s1_oth)
    far_nodes = np.linalg.norm(X - mesh.body.contact_point, axis=1) > d_far
    tris = [f[far_nodes[f].all(1)] for f in (cyl, other)]
    nf = np.unique(np.concatenate([t.ravel() for t in tris]))
    far = float(s1[nf].max()) if len(nf) else math.nan
    far_area = 2.0 * (_triangle_area_sum(X, tris[0], s1_cyl, far, m)
                      + _triangle_area_sum(X, tris[1], s1_oth, far, m)) if far > 0 else 0.0
    return PlacePeak(smax, pos, dist, _face_name(pm, pos, outer, grp), area, m, far, far_area)


# --------------------------------------------------------------------------------------------
# solve
# --------------------------------------------------------------------------------------------


@dataclass
class PlaceResult:
    """The place FEM of one case: per friction coefficient μ and traction direction (+1:
    toward the shoulder, −1: toward the open end; 0 for μ = 0) the outer and inner
    :class:`PlacePeak`; the mesh's stats, the wall times (s) and the support's check;
    ``fields``: per load part ("normal", "tangential" at μ = 1) the displacements (N, 3; m),
    the surface-fit stresses of the outer and inner cylinder and the nodal averages (N, 6;
    Pa; Voigt xx, yy, zz, yz, xz, xy) under keys "displacement", "outer", "inner",
    "average"; ``mesh`` the :class:`PlaceMesh`."""

    place: str
    distance: float
    z_contact: float
    force: float
    contact_radius: float
    peaks: dict[tuple[float, int], tuple[PlacePeak, PlacePeak]]
    stats: dict[str, float]
    times: dict[str, float]
    support: dict[str, float]
    fields: dict[str, dict[str, np.ndarray]] = field(default_factory=dict, repr=False)
    mesh: Optional[PlaceMesh] = field(default=None, repr=False)

    def peak(self, mu: float = 0.0, direction: int = 0) -> tuple[PlacePeak, PlacePeak]:
        """(outer, inner) at friction ``mu`` and traction ``direction`` (±1; 0 when μ = 0)."""
        key = (float(mu), 0 if mu == 0 else int(direction))
        if key not in self.peaks:
            raise InvalidParameterError(f"invalid mu, direction = {key!r}: solved "
                                        f"{sorted(self.peaks)!r}")
        return self.peaks[key]

    def as_dict(self) -> dict[str, Any]:
        return {"place": self.place, "distance_m": self.distance,
                "z_contact_m": self.z_contact, "force_N": self.force,
                "contact_radius_m": self.contact_radius,
                "cases": [{"mu": k[0], "direction": k[1], "outer": o.as_dict(),
                           "inner": i.as_dict()} for k, (o, i) in self.peaks.items()],
                "mesh": self.stats, "times_s": self.times, "support": self.support}


def solve_place(pm: PlaceMesh, E: float, nu: float, frictions: Sequence[float] = (0.0,), *,
                m_outer: float = 6.0, m_inner: float = 10.0) -> PlaceResult:
    """Static solves (Tet4, :func:`demfem._core.fem_solve_static`) of the half model under
    the normal pressure and, when some μ > 0, the axial traction at μ = 1 (scaled; both
    directions); free, inertia relief. Per μ (and direction) the peak σ1 and effective area
    of the outer and inner surface (:class:`PlacePeak`)."""
    from demfem._core import fem_element_stresses, fem_solve_static

    E, nu = check_material(E, nu)
    mus = [float(m) for m in frictions]
    if not mus or any(not (0.0 <= m <= 1.0) for m in mus):
        raise InvalidParameterError(f"invalid frictions = {frictions!r}: give coefficients in "
                                    "[0, 1]")
    mesh = pm.mesh
    X = mesh.nodes
    F = mesh.patch.normal_force
    parts = ["normal", "tangential"] if max(mus) > 0 else ["normal"]
    unit = replace(mesh, patch=mesh.patch.with_friction(1.0))
    x0 = np.flatnonzero(np.abs(X[:, 0]) < 1e-9 * mesh.body.size)
    planes = np.stack([x0, np.zeros(len(x0), np.int64)], -1)
    times: dict[str, float] = {}
    support: dict[str, float] = {}
    disp: dict[str, np.ndarray] = {}
    avg: dict[str, np.ndarray] = {}
    for part in parts:
        t0 = time.perf_counter()
        f = contact_loads(unit, part)  # type: ignore[arg-type]
        if part == "normal":
            f = 2.0 * f  # contact_loads gives the quarter's F/4; the half carries F/2
        fixed, values, f2, info = inertia_relief(mesh, planes, f)
        times[f"loads_{part}"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        u, reac = fem_solve_static(X, mesh.tets, E, nu, f2, fixed.astype(np.int64), values)
        times[f"solve_{part}"] = time.perf_counter() - t0
        k = int(info.get("relief_dofs", 0))
        if k:
            r = float(np.abs(np.asarray(reac)[fixed[-k:, 0], fixed[-k:, 1]]).max())
            info["relief_reaction_N"] = r
            if r > 1e-6 * F:
                raise NumericalError(f"inertia relief left a reaction of {r:.3g} N (force "
                                     f"{F:g} N) at the far dofs")
        support.update({f"{part}_{kk}": v for kk, v in info.items()})
        disp[part] = np.asarray(u)
        t0 = time.perf_counter()
        se = np.asarray(fem_element_stresses(X, mesh.tets, E, nu, u))
        avg[part] = nodal_average(X, mesh.tets, se)
        times[f"stress_{part}"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    snn = -surface_pressure(mesh, X)
    q = rim_points(mesh)
    rim = np.concatenate([q, q[q[:, 2] > 0] * np.array([1.0, 1.0, -1.0])])
    fo: dict[str, np.ndarray] = {}
    fr: dict[str, np.ndarray] = {}
    fi: dict[str, np.ndarray] = {}
    a = mesh.patch.contact_radius
    t = mesh.body.thickness
    for part, up in disp.items():
        fo[part], fr[part] = surface_fit_stresses(
            mesh, up, mesh.outer_faces, E, nu, snn if part == "normal" else None,
            window=0.1 * a, rim="outside" if part == "normal" else "inside",
            extra_points=rim, one_sided=True)
        fi[part], _ = surface_fit_stresses(mesh, up, mesh.inner_faces, E, nu, None,
                                           window=0.1 * t, one_sided=False)
    times["surface_fit"] = time.perf_counter() - t0
    peaks: dict[tuple[float, int], tuple[PlacePeak, PlacePeak]] = {}
    for mu in mus:
        for sgn in ((0,) if mu == 0 else (1, -1)):
            def tot(d: dict[str, np.ndarray]) -> np.ndarray:
                return d["normal"] + (sgn * mu * d["tangential"] if mu > 0 else 0.0)
            po = _half_peak(pm, True, tot(fo), tot(avg), rim, tot(fr), m_outer)
            pi = _half_peak(pm, False, tot(fi), tot(avg), rim, None, m_inner)
            peaks[(mu, sgn)] = (po, pi)
    times["mesh"] = mesh.stats.get("mesh_time_s", math.nan)
    times["total"] = float(sum(times.values()))
    return PlaceResult(pm.place, pm.distance, pm.z_contact, F, a, peaks, dict(pm.stats),
                       times, support, {"displacement": disp, "outer": fo, "inner": fi,
                                        "average": avg}, pm)


def place_case(force: float, place: str, *, cartridge: Any = None,
               distance: Optional[float] = None, level: float = 1.0,
               frictions: Sequence[float] = (0.0,), grading: Optional[Grading] = None,
               m_outer: float = 6.0, m_inner: float = 10.0,
               max_elements: float = 1.5e6) -> PlaceResult:
    """One case end to end: the crossed-cylinder contact of two ``cartridge`` bodies at 90°
    under ``force`` (N) at ``place`` (``distance`` m, :func:`contact_height`), meshed with
    :meth:`Grading.for_patch` scaled by ``level`` (or ``grading``), solved at ``frictions``."""
    c = _cartridge(cartridge)
    R = 0.5 * c.body_outer_diameter
    mat = c.material
    patch = crossed_cylinders_patch(force, R, mat.E, mat.nu)
    tube = TubeSegment(R, c.wall_thickness, c.length)
    g = grading if grading is not None else Grading.for_patch(patch, tube).scaled(
        check_positive("level", level))
    pm = build_place_mesh(patch, place, cartridge=c, distance=distance, grading=g,
                          max_elements=max_elements)
    return solve_place(pm, mat.E, mat.nu, frictions, m_outer=m_outer, m_inner=m_inner)
