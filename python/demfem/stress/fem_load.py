"""Loads and supports of the resolved contact FEM (:mod:`demfem.stress.resolved_fem`).

The Hertz pressure of the contact and its sliding traction q = μ p as consistent nodal
forces of the quarter model (:func:`contact_loads`), which side of the contact's rim a
surface point lies on (:func:`contact_side`), and the support
(:func:`support_with_inertia_relief`): the symmetry planes x = 0 and z = 0, the block's
clamped base, and for the free tube the inertia relief that balances the contact force by
the d'Alembert force of its rigid-body acceleration.

Units: SI (m, N, Pa).
"""
from __future__ import annotations

from typing import Callable, Literal

import numpy as np

from demfem.errors import InvalidParameterError, NumericalError
from demfem.stress.fem_mesh import (
    Body,
    HalfSpaceBlock,
    ResolvedMesh,
    TubeSegment,
    surface_coordinates,
)
from demfem.stress.fem_quadrature import subdivided_triangle_rule, tet_body_loads, tri_shape

__all__ = [
    "Load",
    "surface_pressure",
    "contact_side",
    "contact_loads",
    "support_with_inertia_relief",
    "inertia_relief",
]

#: which part of the contact load: the normal pressure or the sliding traction.
Load = Literal["normal", "tangential"]


def _outward_normal(body: Body, P: np.ndarray) -> np.ndarray:
    if isinstance(body, TubeSegment):
        n = np.stack([P[:, 0], P[:, 1], np.zeros(len(P))], -1)
        return n / np.linalg.norm(n, axis=1, keepdims=True)
    return np.broadcast_to(np.array([0.0, 1.0, 0.0]), P.shape)


def surface_pressure(mesh: ResolvedMesh, P: np.ndarray) -> np.ndarray:
    """The contact pressure (Pa) at points P (n, 3) of the loaded surface: the patch on the
    top (y > 0 on a tube) and, for ``mesh.opposite``, its mirror on the bottom."""
    s, z = surface_coordinates(mesh.body, P)
    pr = mesh.patch.pressure(s, z)
    if isinstance(mesh.body, TubeSegment):
        keep = P[:, 1] > 0.0 if not mesh.opposite else np.ones(len(P), bool)
        pr = np.where(keep, pr, 0.0)
    return pr


def contact_side(mesh: ResolvedMesh, P: np.ndarray, tol: float = 1e-6) -> np.ndarray:
    """+1 inside a contact, −1 outside, 0 on its rim (within ``tol`` of the normalised
    radius 1), for points P (n, 3) of the loaded surface."""
    p = mesh.patch
    s, z = surface_coordinates(mesh.body, P)
    if p.kind == "ellipse":
        rho = np.hypot(s / p.semi_axis_s, z / p.semi_axis_z)
    else:
        rho = np.where(np.abs(z) <= p.semi_axis_z, np.abs(s) / p.semi_axis_s,
                       1.0 + 2.0 * tol + np.abs(z) - p.semi_axis_z)
    if isinstance(mesh.body, TubeSegment) and not mesh.opposite:
        rho = np.where(P[:, 1] > 0.0, rho, np.inf)
    return np.where(rho < 1.0 - tol, 1, np.where(rho > 1.0 + tol, -1, 0))


def contact_loads(mesh: ResolvedMesh, part: Load, levels: int = 2) -> np.ndarray:
    """Consistent nodal forces (N, 3) of the quarter model: ``"normal"`` the Hertz pressure
    (acting along −n), ``"tangential"`` the traction μ p along +z (zero when μ = 0); for
    ``mesh.opposite`` the same pressure on the bottom too. The normal part is scaled so that
    its resultant is exactly the quarter of the force (the curvature of the tube makes
    ∫ p n_y dA differ from F by O(a²/R²))."""
    body, p = mesh.body, mesh.patch
    F = mesh.outer_faces
    X = mesh.nodes
    xi_eta, w = subdivided_triangle_rule(levels)
    N, dN = tri_shape(xi_eta[:, 0], xi_eta[:, 1], mesh.order)
    # only triangles near the contact carry load
    C = X[F[:, :3]].mean(1)
    sides = [1.0, -1.0] if mesh.opposite else [1.0]
    f = np.zeros((len(X), 3))
    reach = 1.5 * max(p.semi_axis_s, p.semi_axis_z) + 4.0 * np.linalg.norm(
        X[F[:, 0]] - X[F[:, 1]], axis=1).max()
    for side in sides:
        s_c, z_c = surface_coordinates(body, C)
        if p.kind == "ellipse":
            near = np.hypot(s_c, z_c) < reach
        else:
            near = (np.abs(s_c) < reach) & (np.abs(z_c) < p.semi_axis_z + reach)
        if isinstance(body, TubeSegment):
            near &= side * C[:, 1] > 0.0
        Fn = F[near]
        if len(Fn) == 0:
            raise NumericalError("no surface triangle under the contact patch")
        Xe = X[Fn]  # (e, k, 3)
        P = np.einsum("qk,ekd->eqd", N, Xe)
        J = np.einsum("qka,ekd->eqda", dN, Xe)
        dA = np.linalg.norm(np.cross(J[..., 0], J[..., 1]), axis=-1) * w  # (e, q)
        Pf = P.reshape(-1, 3)
        s, z = surface_coordinates(body, Pf)
        pr = p.pressure(s, z).reshape(dA.shape)
        if part == "normal":
            n = _outward_normal(body, Pf).reshape(P.shape)
            trac = -pr[..., None] * n
            fe = np.einsum("qk,eqd,eq->ekd", N, trac, dA)
            total_y = float(np.einsum("eq,eq,eq->", -n[..., 1], pr, dA))
            quarter = p.normal_force / 4.0
            fe *= quarter / abs(total_y) if total_y != 0 else 0.0
        elif part == "tangential":
            if side < 0:
                continue  # the opposite contact carries no traction in this model
            trac = np.zeros(P.shape)
            trac[..., 2] = p.friction * pr
            fe = np.einsum("qk,eqd,eq->ekd", N, trac, dA)
        else:
            raise InvalidParameterError(f"invalid part = {part!r}: must be 'normal' or "
                                        "'tangential'")
        for d in range(3):
            f[:, d] += np.bincount(Fn.ravel(), fe[..., d].ravel(), minlength=len(X))
    return f


def _plane_constraints(mesh: ResolvedMesh, part: Load) -> list[tuple[np.ndarray, int]]:
    """(nodes, component) pairs fixed to zero: the symmetry planes, the block's base."""
    X = mesh.nodes
    tol = 1e-9 * mesh.body.size
    x0 = np.flatnonzero(np.abs(X[:, 0]) < tol)
    z0 = np.flatnonzero(np.abs(X[:, 2]) < tol)
    out = [(x0, 0)]
    if part == "normal":
        out.append((z0, 2))
    else:
        out += [(z0, 0), (z0, 1)]
    if isinstance(mesh.body, HalfSpaceBlock):
        base = np.flatnonzero(np.abs(X[:, 1] + mesh.body.depth) < tol)
        out += [(base, 0), (base, 1), (base, 2)]
    return out


def _rigid_modes(X: np.ndarray) -> list[Callable[[np.ndarray], np.ndarray]]:
    def trans(k: int) -> Callable[[np.ndarray], np.ndarray]:
        return lambda P: np.broadcast_to(np.eye(3)[k], P.shape).copy()

    def rot(k: int) -> Callable[[np.ndarray], np.ndarray]:
        return lambda P: np.cross(np.eye(3)[k], P)

    return [trans(0), trans(1), trans(2), rot(0), rot(1), rot(2)]


def support_with_inertia_relief(mesh: ResolvedMesh, part: Load, f: np.ndarray
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray, dict[str, float]]:
    """Fixed (node, component) pairs, their values (zeros) and the load with the inertia
    relief added: the rigid-body modes the symmetry planes leave free are balanced by
    d'Alembert body forces, then fixed at far-end dofs (whose reactions must then vanish)."""
    planes = _plane_constraints(mesh, part)
    fixed = np.concatenate([np.stack([n, np.full(len(n), c)], -1) for n, c in planes])
    return inertia_relief(mesh, fixed, f)


def inertia_relief(mesh: ResolvedMesh, fixed: np.ndarray, f: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray, dict[str, float]]:
    """The inertia relief of a free body whose only supports are the (node, component) pairs
    ``fixed`` (k, 2; symmetry planes): the load ``f`` (N, 3; N)'s projection on the rigid-body
    modes those pairs leave free is balanced by the d'Alembert body force −ρ(ä + α × r) (as
    consistent nodal loads; ρ cancels), and the free modes are then fixed at far dofs (from
    ``mesh.body.contact_point``) whose reactions must vanish. Returns the fixed pairs (the
    given ones, then ``info["relief_dofs"]`` more), their values (zeros), the balanced load
    and ``info`` (``free_rigid_modes``, ``inertia_relief_force_N``, ``relief_dofs``)."""
    X = mesh.nodes
    modes = _rigid_modes(X)
    Phi = np.stack([m(X) for m in modes], -1)  # (N, 3, 6)
    Cphi = Phi[fixed[:, 0], fixed[:, 1], :]  # (k, 6)
    scale = np.linalg.norm(Cphi, axis=0).max() if len(Cphi) else 1.0
    _, sv, vt = np.linalg.svd(Cphi / max(scale, 1e-300), full_matrices=True)
    rank = int(np.sum(sv > 1e-8 * max(sv.max(initial=0.0), 1e-300)))
    free = vt[rank:].T  # (6, r): combinations of modes the constraints allow
    info = {"free_rigid_modes": float(free.shape[1])}
    if free.shape[1] == 0:
        return fixed, np.zeros(len(fixed)), f, info
    # modes as fields: phi_k(P) = Σ_j free[j, k] mode_j(P)
    fields = [(lambda P, c=free[:, k]: sum(c[j] * modes[j](P) for j in range(6)))
              for k in range(free.shape[1])]
    body_f = tet_body_loads(X, mesh.tets, mesh.order, fields)  # ∫ N phi_k dV
    Phin = [fl(X) for fl in fields]  # nodal values (N, 3)
    G = np.array([[np.sum(Phin[k] * body_f[l]) for l in range(len(fields))]
                  for k in range(len(fields))])
    rhs = np.array([np.sum(Phin[k] * f) for k in range(len(fields))])
    acc = np.linalg.solve(G, rhs)
    f2 = f - sum(acc[k] * body_f[k] for k in range(len(fields)))
    info["inertia_relief_force_N"] = float(np.abs(f - f2).sum(0).max())
    # minimal fixing: far corner nodes, dofs chosen by pivoted QR on the mode rows
    from scipy.linalg import qr

    dist = np.linalg.norm(X - mesh.body.contact_point, axis=1)
    corner = np.zeros(len(X), bool)
    corner[np.unique(mesh.tets[:, :4])] = True
    cand = np.flatnonzero(corner)[np.argsort(-dist[corner])][:200]
    rows = np.stack([Phin[k][cand] for k in range(len(fields))], -1).reshape(-1, len(fields))
    _, _, piv = qr(rows.T, pivoting=True)
    pick = piv[:len(fields)]
    extra = np.stack([cand[pick // 3], pick % 3], -1)
    sub = rows[pick]
    if np.linalg.matrix_rank(sub) < len(fields):
        raise NumericalError("could not find dofs that fix the free rigid-body modes")
    fixed = np.concatenate([fixed, extra])
    info["relief_dofs"] = float(len(extra))
    return fixed, np.zeros(len(fixed)), f2, info
