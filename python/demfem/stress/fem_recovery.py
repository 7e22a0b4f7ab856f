"""Surface-stress recovery and effective areas of the resolved contact FEM
(:mod:`demfem.stress.resolved_fem`).

Linear tets cannot show the tension at the rim of a Hertz contact (it lives in a layer a few
hundredths of a deep); :func:`surface_fit_stresses` recovers the in-plane surface stresses
from the surface's displacements instead (local quadratic fits, one-sided across the rim,
Hooke's law with the known normal stress), also at points on the rim itself
(:func:`rim_points`). :func:`surface_peak` takes the peak in-plane σ1 over a surface (σ1
along the rim smoothed by a Fourier series) and the Weibull effective area
A_eff = ∫ ⟨σ1/σ1,max⟩^m dA; :func:`nodal_average` gives the volume-averaged nodal stresses
reported beside them.

Units: SI (m, Pa, m²); stresses in Voigt order xx, yy, zz, yz, xz, xy.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Literal, Optional

import numpy as np

from demfem.errors import InvalidParameterError, NumericalError, check_positive
from demfem.stress.fem_load import contact_side
from demfem.stress.fem_mesh import (
    Body,
    ResolvedMesh,
    TubeSegment,
    signed_volume,
    surface_coordinates,
)
from demfem.stress.fem_patch import check_material
from demfem.stress.fem_quadrature import subdivided_triangle_rule, tri_shape

__all__ = [
    "SurfacePeak",
    "nodal_average",
    "in_plane_sigma1",
    "rim_points",
    "surface_fit_stresses",
    "surface_peak",
    "RIM_FOURIER_ORDER",
    "smooth_rim",
]


@dataclass
class SurfacePeak:
    """The largest σ1 on one surface (Pa), where (``position`` m in the whole body's frame;
    ``surface_s``/``surface_z``: its coordinates in the contact's tangent plane, m), and the
    effective area (m²) for ``weibull_modulus``; ``recovery``: how the surface stress was
    obtained ("surface_fit", "nodal_average" or "calculix")."""

    sigma1_max: float
    position: np.ndarray
    surface_s: float
    surface_z: float
    effective_area: float
    weibull_modulus: float
    recovery: str = "surface_fit"

    def as_dict(self) -> dict[str, Any]:
        return {"sigma1_max_Pa": self.sigma1_max,
                "position_m": [float(v) for v in self.position],
                "s_m": self.surface_s, "z_m": self.surface_z,
                "effective_area_m2": self.effective_area, "weibull_modulus": self.weibull_modulus,
                "recovery": self.recovery}


def nodal_average(X: np.ndarray, T: np.ndarray, s_elem: np.ndarray) -> np.ndarray:
    """Volume-weighted average at the nodes (N, 6) of element stresses (E, 6) of Tet4."""
    vol = np.abs(signed_volume(X, T))
    wsum = np.bincount(T.ravel(), np.repeat(vol, 4), minlength=len(X))
    out = np.empty((len(X), s_elem.shape[1]))
    for c in range(s_elem.shape[1]):
        out[:, c] = np.bincount(T.ravel(), np.repeat(vol * s_elem[:, c], 4),
                                minlength=len(X)) / np.where(wsum > 0, wsum, 1.0)
    return out


def _surface_normal(body: Body, P: np.ndarray) -> np.ndarray:
    """Unit normal (either sign) of the body's outer/inner surface at points P (n, 3)."""
    if isinstance(body, TubeSegment):
        n = np.stack([P[:, 0], P[:, 1], np.zeros(len(P))], -1)
        return n / np.linalg.norm(n, axis=1, keepdims=True)
    return np.broadcast_to(np.array([0.0, 1.0, 0.0]), P.shape).copy()


def _tensor(s: np.ndarray) -> np.ndarray:
    S = np.empty((len(s), 3, 3))
    S[:, 0, 0], S[:, 1, 1], S[:, 2, 2] = s[:, 0], s[:, 1], s[:, 2]
    S[:, 1, 2] = S[:, 2, 1] = s[:, 3]
    S[:, 0, 2] = S[:, 2, 0] = s[:, 4]
    S[:, 0, 1] = S[:, 1, 0] = s[:, 5]
    return S


def _voigt(S: np.ndarray) -> np.ndarray:
    return np.stack([S[:, 0, 0], S[:, 1, 1], S[:, 2, 2], S[:, 1, 2], S[:, 0, 2], S[:, 0, 1]],
                    -1)


def in_plane_sigma1(s: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """Largest principal stress of the surface (in-plane) part P σ P, P = I − n n, of the
    stresses s (n, 6; xx, yy, zz, yz, xz, xy) at points of unit normal ``normals`` (n, 3), Pa:
    what the surface flaws see (at a free surface the other components vanish; a nodal
    average of element stresses does not give them zero)."""
    S = _tensor(s)
    n = normals / np.linalg.norm(normals, axis=1, keepdims=True)
    P = np.eye(3)[None] - n[:, :, None] * n[:, None, :]
    w, v = np.linalg.eigh(P @ S @ P)
    normal_like = np.abs(np.einsum("nij,ni->nj", v, n))
    w = w.copy()
    w[np.arange(len(w)), np.argmax(normal_like, axis=1)] = -np.inf
    return w.max(axis=1)


def _tangent_basis(n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    ref = np.where(np.abs(n[:, 2:3]) < 0.9, np.array([[0.0, 0.0, 1.0]]),
                   np.array([[1.0, 0.0, 0.0]]))
    e1 = np.cross(n, ref)
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    return e1, np.cross(n, e1)


def _fit_surface_gradients(Xs: np.ndarray, us: np.ndarray, node_side: np.ndarray,
                           centers: np.ndarray, center_side: np.ndarray, radius: np.ndarray,
                           e1: np.ndarray, e2: np.ndarray, min_neighbours: int
                           ) -> tuple[np.ndarray, np.ndarray]:
    """∂u/∂ξ, ∂u/∂η (k, 3) at ``centers`` from least-squares quadratics of the surface nodes'
    displacements ``us`` over the nodes within ``radius`` (grown ×1.4 until at least
    ``min_neighbours`` usable ones) on the centre's side (+1 inside: nodes with side ≥ 0;
    −1 outside: side ≤ 0)."""
    from scipy.spatial import cKDTree

    tree = cKDTree(Xs)
    radius = radius.copy()
    out = np.zeros((len(centers), 2, 3))
    todo = np.arange(len(centers))
    for _ in range(10):
        if len(todo) == 0:
            break
        lists = tree.query_ball_point(centers[todo], radius[todo])
        lens = np.array([len(x) for x in lists], dtype=np.int64)
        ii = np.repeat(np.arange(len(todo)), lens)
        jj = (np.concatenate([np.asarray(x, dtype=np.int64) for x in lists]) if lens.sum()
              else np.zeros(0, np.int64))
        gi = todo[ii]
        ok = np.where(center_side[gi] == 1, node_side[jj] >= 0, node_side[jj] <= 0)
        gi, ii, jj = gi[ok], ii[ok], jj[ok]
        count = np.bincount(ii, minlength=len(todo))
        d = Xs[jj] - centers[gi]
        rad = radius[gi]
        xi = np.einsum("ij,ij->i", d, e1[gi]) / rad
        et = np.einsum("ij,ij->i", d, e2[gi]) / rad
        A = np.stack([np.ones_like(xi), xi, et, xi * xi, xi * et, et * et], -1)
        AtA = np.zeros((len(todo), 6, 6))
        AtU = np.zeros((len(todo), 6, 3))
        for r in range(6):
            for c in range(r, 6):
                AtA[:, r, c] = AtA[:, c, r] = np.bincount(ii, A[:, r] * A[:, c],
                                                          minlength=len(todo))
            for c in range(3):
                AtU[:, r, c] = np.bincount(ii, A[:, r] * us[jj, c], minlength=len(todo))
        good = count >= min_neighbours
        if good.any():
            idx = np.flatnonzero(good)
            good[idx[np.linalg.cond(AtA[idx]) > 1e10]] = False
        if good.any():
            sol = np.linalg.solve(AtA[good], AtU[good])
            out[todo[good]] = sol[:, 1:3, :] / radius[todo[good]][:, None, None]
        todo = todo[~good]
        radius[todo] *= 1.4
    if len(todo):
        raise NumericalError(f"surface fit: {len(todo)} surface points without a usable patch")
    return out[:, 0, :], out[:, 1, :]


def _hooke_in_plane(du1: np.ndarray, du2: np.ndarray, e1: np.ndarray, e2: np.ndarray,
                    snn: np.ndarray, E: float, nu: float) -> np.ndarray:
    """In-plane stresses (k, 6) from the surface gradients and the normal stress σ_nn."""
    e11 = np.einsum("ij,ij->i", du1, e1)
    e22 = np.einsum("ij,ij->i", du2, e2)
    e12 = 0.5 * (np.einsum("ij,ij->i", du2, e1) + np.einsum("ij,ij->i", du1, e2))
    k = E / (1.0 - nu * nu)
    tr = e11 + e22
    s11 = k * ((1.0 - nu) * e11 + nu * tr) + nu / (1.0 - nu) * snn
    s22 = k * ((1.0 - nu) * e22 + nu * tr) + nu / (1.0 - nu) * snn
    s12 = k * (1.0 - nu) * e12
    S = (s11[:, None, None] * np.einsum("ni,nj->nij", e1, e1)
         + s22[:, None, None] * np.einsum("ni,nj->nij", e2, e2)
         + s12[:, None, None] * (np.einsum("ni,nj->nij", e1, e2)
                                 + np.einsum("ni,nj->nij", e2, e1)))
    return _voigt(S)


def _local_spacing(mesh: ResolvedMesh, faces: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    X = mesh.nodes
    ce = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    L = np.linalg.norm(X[ce[:, 0]] - X[ce[:, 1]], axis=1)
    cnt = np.bincount(ce.ravel(), minlength=len(X))
    h = np.bincount(ce.ravel(), np.repeat(L, 2), minlength=len(X)) / np.maximum(cnt, 1)
    hn = h[nodes]
    if np.any(hn == 0):  # midside nodes of quadratic faces: twice the nearest spacing
        from scipy.spatial import cKDTree

        dd, _ = cKDTree(X[nodes]).query(X[nodes], k=2)
        hn = np.where(hn > 0, hn, 2.0 * dd[:, 1])
    return hn


def rim_points(mesh: ResolvedMesh, spacing: Optional[float] = None) -> np.ndarray:
    """Points (k, 3) on the rim of an elliptical contact on the loaded surface (the quarter
    x ≥ 0, z ≥ 0), every ``spacing`` m (default: the mesh's edge length at the rim / 2):
    where the surface stresses of a Hertz contact peak; empty for a line contact."""
    p = mesh.patch
    if p.kind != "ellipse":
        return np.zeros((0, 3))
    h = spacing if spacing is not None else 0.5 * mesh.grading.edge_size
    perim = 0.5 * math.pi * max(p.semi_axis_s, p.semi_axis_z)
    n = max(8, int(math.ceil(perim / h)) + 1)
    phi = np.linspace(0.0, 0.5 * math.pi, n)
    x, z = p.semi_axis_s * np.cos(phi), p.semi_axis_z * np.sin(phi)
    if isinstance(mesh.body, TubeSegment):
        y = np.sqrt(mesh.body.outer_radius ** 2 - x * x)
    else:
        y = np.zeros_like(x)
    return np.stack([x, y, z], -1)


def surface_fit_stresses(mesh: ResolvedMesh, u: np.ndarray, faces: np.ndarray, E: float,
                         nu: float, normal_stress: Optional[np.ndarray] = None, *,
                         window: float = 0.0, per_edge: float = 4.0, min_neighbours: int = 15,
                         one_sided: bool = True,
                         rim: Literal["outside", "inside"] = "outside",
                         extra_points: Optional[np.ndarray] = None
                         ) -> tuple[np.ndarray, np.ndarray]:
    """In-plane surface stresses recovered from the surface's displacements: (N, 6) at the
    surface nodes (zeros off the surface) and (k, 6) at ``extra_points`` (on the surface; the
    rim of the contact, :func:`rim_points`). At each point a least-squares quadratic u(ξ, η)
    over the surface nodes within max(``per_edge`` × the local edge length, ``window``) in
    the tangent plane, its derivatives the surface strains ε_αβ, and the stresses by Hooke's
    law with the normal stress σ_nn known from the load (``normal_stress`` per node, Pa: −p
    under the contact, 0 elsewhere; 0 at the extra points):

        σ_αβ = E/(1−ν²) [(1−ν) ε_αβ + ν ε_γγ δ_αβ] + ν/(1−ν) σ_nn δ_αβ.

    Why: the tension at the rim of a Hertz contact lives in a surface layer a few hundredths
    of a deep (at r = 1.02 a, σ_r falls from 0.18 p0 at the surface to 0.05 p0 at 0.02 a);
    element stresses, constant over elements deeper than that, average it away, while the
    surface displacements carry it. With ``one_sided`` the fit at a point outside a contact
    uses no node inside it and vice versa: across the rim the load falls like a square root
    and no polynomial fits both sides. ``rim`` says which side points on the rim take: the
    smooth one, "outside" for the normal pressure (its surface field is (1−2ν)/3 p0 (a/r)²
    outside, with the square-root fall inside), "inside" for a sliding traction (linear in x
    inside, the square-root terms outside: Hamilton 1983).
    """
    E, nu = check_material(E, nu)
    if rim not in ("outside", "inside"):
        raise InvalidParameterError(f"invalid rim = {rim!r}: must be 'outside' or 'inside'")
    rim_as = -1 if rim == "outside" else 1
    X = mesh.nodes
    nodes = np.unique(faces)
    Xs = X[nodes]
    us = np.asarray(u)[nodes]
    hn = _local_spacing(mesh, faces, nodes)
    side = contact_side(mesh, Xs) if one_sided else np.full(len(nodes), -1)
    c_side = np.where(side == 0, rim_as, side)
    centers, radius = Xs, np.maximum(per_edge * hn, window)
    snn = np.zeros(len(nodes)) if normal_stress is None else np.asarray(normal_stress)[nodes]
    n_extra = 0 if extra_points is None else len(extra_points)
    if n_extra:
        from scipy.spatial import cKDTree

        _, near = cKDTree(Xs).query(extra_points)
        centers = np.concatenate([Xs, extra_points])
        radius = np.concatenate([radius, np.maximum(per_edge * hn[near], window)])
        c_side = np.concatenate([c_side, np.full(n_extra, rim_as if one_sided else -1)])
        snn = np.concatenate([snn, np.zeros(n_extra)])
    n = _surface_normal(mesh.body, centers)
    e1, e2 = _tangent_basis(n)
    du1, du2 = _fit_surface_gradients(Xs, us, side, centers, c_side, radius, e1, e2,
                                      min_neighbours)
    S = _hooke_in_plane(du1, du2, e1, e2, snn, E, nu)
    out = np.zeros((len(X), 6))
    out[nodes] = S[:len(nodes)]
    return out, S[len(nodes):]


def surface_peak(mesh: ResolvedMesh, faces: np.ndarray, s_normal: np.ndarray,
                 s_tangential: Optional[np.ndarray], weibull_modulus: float,
                 recovery: str = "surface_fit", extra_points: Optional[np.ndarray] = None,
                 extra_normal: Optional[np.ndarray] = None,
                 extra_tangential: Optional[np.ndarray] = None) -> SurfacePeak:
    """Peak σ1 over a surface (both z-images of the quarter model; the surface nodes and the
    ``extra_points`` with their stresses — on the rim of an elliptical contact: σ1 along the
    rim is smoothed by a Fourier series (:func:`smooth_rim`) and stands for the nodes within
    0.1 a of it) and the effective area ∫ ⟨σ1/σ_max⟩^m dA over the
    whole body (4 images of the quarter surface); σ1 is the largest in-plane principal stress
    (:func:`in_plane_sigma1`), interpolated over each surface triangle with its shape
    functions."""
    m = check_positive("weibull_modulus", weibull_modulus)
    nodes = np.unique(faces)
    images = [(s_normal, extra_normal, 1.0)]
    if s_tangential is not None:
        images = [(s_normal + s_tangential,
                   None if extra_normal is None else extra_normal + extra_tangential, 1.0),
                  (s_normal - s_tangential,
                   None if extra_normal is None else extra_normal - extra_tangential, -1.0)]
    s1 = np.zeros((len(images), len(mesh.nodes)))
    normals = _surface_normal(mesh.body, mesh.nodes[nodes])
    best = (-math.inf, np.zeros(3))
    use_rim = (extra_points is not None and len(extra_points) > 0 and extra_normal is not None
               and len(extra_normal) > 0 and mesh.patch.kind == "ellipse")
    candidates = nodes
    if use_rim:
        # the nodes next to the rim are represented by the rim itself (their fits are the
        # noisiest: one-sided, extrapolated)
        p = mesh.patch
        sx_, zx_ = surface_coordinates(mesh.body, mesh.nodes[nodes])
        rho = np.hypot(sx_ / p.semi_axis_s, zx_ / p.semi_axis_z)
        if isinstance(mesh.body, TubeSegment):
            rho = np.where(mesh.nodes[nodes, 1] > 0, rho, np.inf)
        candidates = nodes[np.abs(rho - 1.0) > 0.1]
    rim_phi: list[np.ndarray] = []
    rim_val: list[np.ndarray] = []
    for k, (s, sx, sign) in enumerate(images):
        s1[k, nodes] = in_plane_sigma1(s[nodes], normals)
        if len(candidates):
            j = int(np.argmax(s1[k, candidates]))
            if s1[k, candidates[j]] > best[0]:
                best = (float(s1[k, candidates[j]]),
                        mesh.nodes[candidates[j]] * np.array([1.0, 1.0, sign]))
        if use_rim and sx is not None:
            assert extra_points is not None
            v = in_plane_sigma1(sx, _surface_normal(mesh.body, extra_points))
            phi = np.arctan2(extra_points[:, 2] / mesh.patch.semi_axis_z,
                             extra_points[:, 0] / mesh.patch.semi_axis_s)
            # the x-mirror and, for the symmetric field, the z-mirror
            rim_phi += [sign * phi, sign * (math.pi - phi)]
            rim_val += [v, v]
            if len(images) == 1:
                rim_phi += [-phi, phi - math.pi]
                rim_val += [v, v]
    if use_rim:
        phi_r, smooth = smooth_rim(np.concatenate(rim_phi), np.concatenate(rim_val))
        if smooth > best[0]:
            p = mesh.patch
            x = p.semi_axis_s * math.cos(phi_r)
            z = p.semi_axis_z * math.sin(phi_r)
            y = (math.sqrt(mesh.body.outer_radius ** 2 - x * x)
                 if isinstance(mesh.body, TubeSegment) else 0.0)
            best = (smooth, np.array([x, y, z]))
    smax, pos = best
    ss, zz = surface_coordinates(mesh.body, pos[None])
    xi_eta, w = subdivided_triangle_rule(1)
    N, dN = tri_shape(xi_eta[:, 0], xi_eta[:, 1], mesh.order)
    Xe = mesh.nodes[faces]
    J = np.einsum("qka,ekd->eqda", dN, Xe)
    dA = np.linalg.norm(np.cross(J[..., 0], J[..., 1]), axis=-1) * w
    area = 0.0
    if smax > 0.0:
        for k2 in range(len(images)):
            sq = np.einsum("qk,ek->eq", N, s1[k2][faces])
            area += float(np.sum(dA * (np.maximum(sq, 0.0) / smax) ** m))
    mult = 2.0 if s_tangential is not None else 4.0  # x-mirror (and z-mirror when symmetric)
    return SurfacePeak(smax, pos, float(ss[0]), float(zz[0]), mult * area, m, recovery)


#: Fourier order of the smoothing of σ1 along the rim (wavelengths ≥ 2π a / 8 ≈ 0.8 a: the
#: field's variation along the rim; the mesh-scale scatter of the fits, ±5 %, is shorter).
RIM_FOURIER_ORDER = 8


def smooth_rim(phi: np.ndarray, value: np.ndarray) -> tuple[float, float]:
    """Least-squares Fourier series (order :data:`RIM_FOURIER_ORDER`) of σ1 (Pa) along the
    whole rim of an elliptical contact (parametric angle φ, rad), and the angle (rad) and
    value (Pa) of its maximum."""
    k = np.arange(1, RIM_FOURIER_ORDER + 1)
    def basis(f: np.ndarray) -> np.ndarray:
        return np.concatenate([np.ones((len(f), 1)), np.cos(np.outer(f, k)),
                               np.sin(np.outer(f, k))], axis=1)
    coef, *_ = np.linalg.lstsq(basis(phi), value, rcond=None)
    grid = np.linspace(-math.pi, math.pi, 2881)
    fit = basis(grid) @ coef
    j = int(np.argmax(fit))
    return float(grid[j]), float(fit[j])
