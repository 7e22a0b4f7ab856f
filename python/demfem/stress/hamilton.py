"""Stresses under a sliding contact: the tangential traction's share of the contact-edge tension.

When the two glass surfaces slide (or the contact carries a tangential force Q), the
traction q = (Q/F) p — full sliding at the effective friction coefficient μ = Q/F, the
distribution of Hamilton & Goodman (1966) and Hamilton (1983) — adds a tension behind the
contact that the normal load alone does not give. For the circular Hertz contact of radius a
the surface stresses are explicit (Hamilton 1983, "Explicit equations for the stresses
beneath a sliding spherical contact", Proc. IMechE 197C, 53–59). Per unit μ p0, lengths in
units of a, traction along +x (trailing edge at x = −a):

* inside the contact (r < a): σ_xx = −π(4 + ν) x/8, σ_yy = −3πν x/8, σ_xy = −π(2 − ν) y/8;
* outside (r > a), with α = arccos(a/r), L = π − 2α and, for n = 2, 4,
  C_n = −(2/n) cos(nφ) sin(nα), S_n = −(2/n) sin(nφ) sin(nα) (φ the polar angle of (x, y)):

      σ_xx = −[x (L + C_2)/2 + y S_2/2 + ν x (L − C_4)/8 + ν y (2 S_2 − S_4)/8]
      σ_yy = −ν [x (3L + 4 C_2 + C_4)/8 + y (2 S_2 + S_4)/8]
      σ_xy = −[x S_2/2 + y (L − C_2)/2 − ν x (2 S_2 + S_4)/4 − ν y (L − C_4)/4]/2

  (inside: α = 0, the same expressions). These are the surface values of Hamilton's
  equations, written here from the projection integral of :mod:`demfem.stress.surface_field`
  evaluated in closed form; the tests check them against that integral and against Hamilton's
  published interior values and maximum.

With the normal load's field (Johnson §3.4) the largest surface tension is at the trailing
edge, along the sliding direction:

    σ_max = p0 [(1 − 2ν)/3 + (4 + ν) π μ / 8]          (Hamilton 1983)

For a sliding line contact (parallel cylinders, traction across the line) the tangential
traction gives σ_x = 2 μ p0 at the trailing edge and the normal load none (plane strain;
McEwen 1949, Smith & Liu 1953; :func:`demfem.stress.hertz.line_sliding_stresses`).

Beneath the surface, :func:`tangential_depth_profile` evaluates σ_xx of the sliding traction
along the normal to the surface at the trailing edge, by quadrature of Cerruti's point-force
solution (Johnson ch. 2) over the contact; the normal load's profile is Hamilton's explicit
:func:`demfem.stress.hertz.circular_subsurface_stresses`.

Dimensionless throughout (stresses / p0 and per unit μ where said, lengths / a).
"""
from __future__ import annotations

import math
from functools import lru_cache
from typing import Any

import numpy as np

from demfem.errors import InvalidParameterError, check_range
from demfem.stress.hertz import circular_surface_stresses

__all__ = ["sliding_surface_stresses", "hamilton_surface_stresses", "trailing_edge_tension",
           "line_trailing_edge_tension", "cerruti_stress_xx", "tangential_depth_profile",
           "tangential_depth_parts"]


def sliding_surface_stresses(x: Any, y: Any, nu: float) -> dict[str, np.ndarray]:
    """Surface stresses of the tangential traction q = p (along +x) of a circular Hertz
    contact, per unit μ p0, at (x, y) in units of a (module docstring): keys ``xx``, ``yy``,
    ``xy``."""
    nu = check_range("nu", nu, -1.0, 0.5)
    x, y = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float))
    r2 = x * x + y * y
    outside = r2 > 1.0
    rs = np.where(outside, r2, 1.0)
    w = np.sqrt(np.where(outside, r2 - 1.0, 0.0))
    alpha = np.where(outside, np.arccos(1.0 / np.sqrt(rs)), 0.0)
    L = math.pi - 2.0 * alpha
    sin2a = 2.0 * w / rs
    sin4a = 4.0 * w * (2.0 - rs) / rs**2
    r2s = np.where(r2 > 0, r2, 1.0)
    cos2p = np.where(r2 > 0, (x * x - y * y) / r2s, 1.0)
    sin2p = np.where(r2 > 0, 2.0 * x * y / r2s, 0.0)
    cos4p = 2.0 * cos2p**2 - 1.0
    sin4p = 2.0 * sin2p * cos2p
    C2, S2 = -cos2p * sin2a, -sin2p * sin2a
    C4, S4 = -0.5 * cos4p * sin4a, -0.5 * sin4p * sin4a
    sxx = -(x * (L + C2) / 2 + y * S2 / 2 + nu * x * (L - C4) / 8 + nu * y * (2 * S2 - S4) / 8)
    syy = -nu * (x * (3 * L + 4 * C2 + C4) / 8 + y * (2 * S2 + S4) / 8)
    sxy = -0.5 * (x * S2 / 2 + y * (L - C2) / 2 - nu * x * (2 * S2 + S4) / 4
                  - nu * y * (L - C4) / 4)
    return {"xx": sxx, "yy": syy, "xy": sxy}


def hamilton_surface_stresses(x: Any, y: Any, nu: float, mu: float) -> dict[str, np.ndarray]:
    """Surface stresses of a circular Hertz contact sliding along +x with friction
    coefficient ``mu`` (full sliding, q = μ p), in units of p0 at (x, y) in units of a:
    the normal load's field (Johnson §3.4) plus μ times :func:`sliding_surface_stresses`.
    Keys ``xx``, ``yy``, ``xy``."""
    mu = check_range("mu", mu, 0.0, math.inf, lo_open=False)
    n = circular_surface_stresses(x, y, nu)
    t = sliding_surface_stresses(x, y, nu)
    return {k: n[k] + mu * t[k] for k in ("xx", "yy", "xy")}


def trailing_edge_tension(nu: float, mu: Any) -> np.ndarray:
    """σ_xx / p0 at the trailing edge of a sliding circular contact, the largest surface
    tension: (1 − 2ν)/3 + (4 + ν) π μ / 8 (Hamilton 1983)."""
    nu = check_range("nu", nu, -1.0, 0.5)
    return (1.0 - 2.0 * nu) / 3.0 + (4.0 + nu) * math.pi * np.asarray(mu, float) / 8.0


def line_trailing_edge_tension(mu: Any) -> np.ndarray:
    """σ_x / p0 at the trailing edge of a sliding Hertz line contact: 2 μ (McEwen 1949;
    Smith & Liu 1953)."""
    return 2.0 * np.asarray(mu, float)


def _cerruti_parts(x: np.ndarray, y: np.ndarray, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(K0, K1) with Cerruti's σ_xx = K0 + ν K1 (see :func:`cerruti_stress_xx`)."""
    inv = 1.0 / np.sqrt(x * x + y * y + z * z)
    irz = 1.0 / (1.0 / inv + z)                       # 1 / (ρ + z)
    x2 = x * x
    xi3 = x * inv * inv * inv                         # x / ρ³
    irz2 = irz * irz
    brace = xi3 - 3.0 * x * inv * irz2 + x2 * xi3 * irz2 + 2.0 * x2 * x * inv * inv * irz2 * irz
    return (-3.0 * x2 * xi3 * inv * inv + brace) / (2.0 * math.pi), -brace / math.pi


def cerruti_stress_xx(x: Any, y: Any, z: Any, nu: float) -> np.ndarray:
    """σ_xx at (x, y, z) (z ≥ 0 into the body) of a unit tangential point force along +x on
    the surface of a half-space at the origin (Cerruti; Johnson ch. 2), 1/m² per N:

        σ_xx = (1/2π)[−3x³/ρ⁵ + (1−2ν){x/ρ³ − 3x/(ρ(ρ+z)²) + x³/(ρ³(ρ+z)²)
               + 2x³/(ρ²(ρ+z)³)}],   ρ = √(x² + y² + z²).

    On the surface: −[(1 − 2ν) x/r³ + 3ν x³/r⁵]/π (tension behind the force)."""
    nu = check_range("nu", nu, -1.0, 0.5)
    x, y, z = np.broadcast_arrays(*(np.asarray(v, float) for v in (x, y, z)))
    k0, k1 = _cerruti_parts(x, y, z)
    return k0 + nu * k1


@lru_cache(maxsize=16)
def _gauss(n: int) -> tuple[np.ndarray, np.ndarray]:
    x, w = np.polynomial.legendre.leggauss(n)
    return 0.5 * (x + 1.0), 0.5 * w


def tangential_depth_profile(r: Any, z: Any, nu: float, n_theta: int = 64,
                             n_panels: int = 8) -> np.ndarray:
    """σ_xx / (μ p0) of the sliding traction q = μ p (along +x) of a circular Hertz contact at
    the points (−r, 0, z) behind the contact — on the normal to the surface at distance r ≥ 1
    from the centre, the line a flaw at the surface there grows along — with r, z in units of
    a (z > 0 into the body). Quadrature of Cerruti's solution over the contact in polar
    coordinates (ρ, θ) centred on (−r, 0): along each ray the contact lies between ρ1 and ρ2,
    ρ = ρ1 + (ρ2 − ρ1)(1 − cos τ)/2 makes the traction's square-root edges smooth, and
    ``n_panels`` τ panels of 12 Gauss points are graded towards the near edge; ``n_theta``
    Gauss points in θ. Accurate to 1e-4 of μ p0 for z ≥ 1e-3 (the tests check the surface
    limit π(4 + ν)/8 at r = 1 and the same quadrature of Boussinesq's solution against
    Hamilton's explicit normal-load field)."""
    nu = check_range("nu", nu, -1.0, 0.5)
    t0, t1 = tangential_depth_parts(r, z, n_theta, n_panels)
    return t0 + nu * t1


def tangential_depth_parts(r: Any, z: Any, n_theta: int = 64,
                           n_panels: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """(T0, T1) with :func:`tangential_depth_profile` = T0 + ν T1 (Cerruti's kernel is linear
    in ν), so that one quadrature serves every Poisson ratio."""
    rr, zz = np.broadcast_arrays(np.asarray(r, float), np.asarray(z, float))
    if np.any(~np.isfinite(zz)) or np.any(zz <= 0):
        raise InvalidParameterError("invalid z: must be finite and > 0 (depth, units of a)")
    if np.any(~np.isfinite(rr)) or np.any(rr < 1.0):
        raise InvalidParameterError("invalid r: must be finite and >= 1 (outside the contact, "
                                    "units of a)")
    gt, wt = _gauss(int(n_theta))
    edges = np.concatenate([[0.0], np.geomspace(10.0 ** (-(int(n_panels) - 1) * 3.0 / 11.0),
                                                1.0, int(n_panels))]) * math.pi
    gu, wu = _gauss(12)
    tau = np.concatenate([lo + (hi - lo) * gu for lo, hi in zip(edges[:-1], edges[1:])])
    wtau = np.concatenate([(hi - lo) * wu for lo, hi in zip(edges[:-1], edges[1:])])
    rf, zf = rr.ravel(), zz.ravel()
    out0, out1 = np.empty(rf.size), np.empty(rf.size)
    block = max(1, 2_000_000 // (gt.size * tau.size))
    for lo in range(0, rf.size, block):
        rk = rf[lo:lo + block, None, None]
        zk = zf[lo:lo + block, None, None]
        tmax = np.where(rk > 1.0, np.arcsin(1.0 / np.maximum(rk, 1.0)), 0.5 * math.pi)
        theta = (2.0 * gt[None, :, None] - 1.0) * tmax
        ct, st = np.cos(theta), np.sin(theta)
        half = np.sqrt(np.maximum(1.0 - (rk * st) ** 2, 0.0))
        rho1 = np.maximum(rk * ct - half, 0.0)
        chord = 2.0 * half
        tk = tau[None, None, :]
        rho = rho1 + chord * 0.5 * (1.0 - np.cos(tk))
        # q dρ = √((ρ − ρ1)(ρ2 − ρ)) dρ = (chord/2)² sin²τ dτ; dA = ρ dρ dθ
        weight = (2.0 * tmax * wt[None, :, None]) * wtau[None, None, :] * (0.5 * chord) ** 2 \
            * np.sin(tk) ** 2 * rho
        k0, k1 = _cerruti_parts(-rho * ct, -rho * st, zk)   # field − source point
        out0[lo:lo + block] = np.sum(weight * k0, axis=(1, 2))
        out1[lo:lo + block] = np.sum(weight * k1, axis=(1, 2))
    return out0.reshape(rr.shape), out1.reshape(rr.shape)
