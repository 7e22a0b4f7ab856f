"""Shape functions and quadrature of the resolved contact FEM
(:mod:`demfem.stress.resolved_fem`): 3-/6-node surface triangles and 4-/10-node tets
(CalculiX/Abaqus node order), a subdivided triangle rule for loads whose edge falls like a
square root, and consistent nodal loads of body-force fields.

Units: SI (m; loads in N from body forces in N/m³).
"""
from __future__ import annotations

from typing import Callable, Sequence

import numpy as np

from demfem.stress.fem_mesh import ABAQUS_EDGES, signed_volume

__all__ = [
    "subdivided_triangle_rule",
    "tri_shape",
    "tet_body_loads",
]


# 7-point degree-5 triangle rule (Dunavant), barycentric (l1, l2) and weights summing to 1
_A1, _B1 = 0.059715871789770, 0.470142064105115
_A2, _B2 = 0.797426985353087, 0.101286507323456
_TRI7 = np.array([[1 / 3, 1 / 3], [_A1, _B1], [_B1, _A1], [_B1, _B1],
                  [_A2, _B2], [_B2, _A2], [_B2, _B2]])
_TRI7_W = np.array([0.225] + [0.132394152788506] * 3 + [0.125939180544827] * 3)


def subdivided_triangle_rule(levels: int) -> tuple[np.ndarray, np.ndarray]:
    """Points (n, 2) in the reference triangle (ξ, η) and weights summing to ½ (its area):
    the 7-point rule on each of 4^levels sub-triangles."""
    tris = [np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])]
    for _ in range(levels):
        new = []
        for t in tris:
            m01, m12, m20 = 0.5 * (t[0] + t[1]), 0.5 * (t[1] + t[2]), 0.5 * (t[2] + t[0])
            new += [np.array([t[0], m01, m20]), np.array([m01, t[1], m12]),
                    np.array([m20, m12, t[2]]), np.array([m01, m12, m20])]
        tris = new
    pts, wts = [], []
    l3 = 1.0 - _TRI7.sum(1)
    for t in tris:
        e1, e2 = t[1] - t[0], t[2] - t[0]
        area = 0.5 * abs(e1[0] * e2[1] - e1[1] * e2[0])
        pts.append(np.outer(l3, t[0]) + np.outer(_TRI7[:, 0], t[1]) + np.outer(_TRI7[:, 1], t[2]))
        wts.append(_TRI7_W * area)
    return np.concatenate(pts), np.concatenate(wts)


def tri_shape(xi: np.ndarray, eta: np.ndarray, order: int) -> tuple[np.ndarray, np.ndarray]:
    """Shape functions (n, k) and their (ξ, η) derivatives (n, k, 2) of the 3- or 6-node
    triangle (corners, then midsides 1-2, 2-3, 3-1)."""
    L1, L2, L3 = 1.0 - xi - eta, xi, eta
    if order == 1:
        N = np.stack([L1, L2, L3], -1)
        dN = np.broadcast_to(np.array([[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]]),
                             (len(xi), 3, 2)).copy()
        return N, dN
    N = np.stack([L1 * (2 * L1 - 1), L2 * (2 * L2 - 1), L3 * (2 * L3 - 1),
                  4 * L1 * L2, 4 * L2 * L3, 4 * L3 * L1], -1)
    dL = np.array([[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]])
    Ls = np.stack([L1, L2, L3], -1)
    dN = np.zeros((len(xi), 6, 2))
    for i in range(3):
        dN[:, i] = (4 * Ls[:, i] - 1)[:, None] * dL[i]
    for k, (i, j) in enumerate([(0, 1), (1, 2), (2, 0)]):
        dN[:, 3 + k] = 4 * (Ls[:, i][:, None] * dL[j] + Ls[:, j][:, None] * dL[i])
    return N, dN


# 5-point degree-3 tet rule (Keast), barycentric coordinates and weights summing to 1
_TET5 = np.array([[0.25, 0.25, 0.25, 0.25],
                  [0.5, 1 / 6, 1 / 6, 1 / 6], [1 / 6, 0.5, 1 / 6, 1 / 6],
                  [1 / 6, 1 / 6, 0.5, 1 / 6], [1 / 6, 1 / 6, 1 / 6, 0.5]])
_TET5_W = np.array([-0.8, 0.45, 0.45, 0.45, 0.45])


def _tet_shape(L: np.ndarray, order: int) -> np.ndarray:
    """Shape functions (n, 4|10) at barycentric points L (n, 4), Abaqus node order."""
    if order == 1:
        return L.copy()
    corners = L * (2 * L - 1)
    mids = np.stack([4 * L[:, i] * L[:, j] for i, j in ABAQUS_EDGES], -1)
    return np.concatenate([corners, mids], -1)


def tet_body_loads(X: np.ndarray, T: np.ndarray, order: int,
                    fields: Sequence[Callable[[np.ndarray], np.ndarray]]) -> list[np.ndarray]:
    """Consistent nodal loads ∫ N_i b dV (N, 3) of the body-force fields b(x) (linear in x),
    exact for straight-sided elements (the 5-point degree-3 rule)."""
    N = _tet_shape(_TET5, order)  # (q, k)
    C = X[T[:, :4]]  # corners
    vol = np.abs(signed_volume(X, T))
    pts = np.einsum("qc,ecd->eqd", _TET5, C)  # straight-sided geometry
    out = []
    for fn in fields:
        b = fn(pts.reshape(-1, 3)).reshape(pts.shape)  # (e, q, 3)
        fe = np.einsum("q,qk,eqd,e->ekd", _TET5_W, N, b, vol)
        f = np.zeros((len(X), 3))
        for d in range(3):
            f[:, d] = np.bincount(T.ravel(), fe[..., d].ravel(), minlength=len(X))
        out.append(f)
    return out
