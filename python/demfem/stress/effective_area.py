"""Weibull effective areas of the stress fields, precomputed in dimensionless form.

The effective area of a surface field σ1 is A_eff = ∫ (σ1/σ1_max)^m dA over its tensile part
(ASTM C1683): the area of a uniformly stressed surface at σ1_max with the same probability of
failure. Every field of :func:`demfem.stress.contact_stresses` is a fixed shape scaled by the
event's load, so its effective area is a dimensionless number times a length² of the event
(a b for a contact, π c² or ℓ² for the shell, L b for a line contact). The numbers are
tabulated here once per Poisson ratio and Weibull modulus (``functools.lru_cache``) and
interpolated per event: a few table look-ups per event instead of a surface integral.

Tables:

* :func:`shell_table` — the shallow shell under a Hertzian load of radius c (the field of
  :func:`demfem.stress.shell.hertz_patch_surface_stresses`) on 110 values of x_c = c/ℓ in
  [1e-6, 0.999] (a contact radius of 1.3 nm to ℓ for the default cartridge): the inner peak
  σ1 t²/F and its effective area / (π c²); the outer radial stress at the contact edge r = c
  (the bending that superposes on the contact tension); the outer tensile ring's peak and its
  effective area / ℓ². Integrated on r ∈ [0, 12 ℓ].
* :func:`contact_table` — the outer surface near the contact: the contact field (circular:
  Johnson §3.4 + Hamilton 1983, explicit; elliptical: :mod:`demfem.stress.surface_field`) with
  friction μ on a grid of μ, plus a constant offset σ_b (the shell's bending stress at the
  contact edge, compressive): the peak σ1/p0 without the offset, the radius of the peak over
  √(ab), and A_eff/(a b) of ⟨σ1/p0 + ρ σ_peak⟩ for τ = 1 + ρ in [0.02, 1] (the offset as a
  fraction of the contact peak; τ = 1: no offset; below 0.02, where the grid no longer
  resolves the shrinking peak region, the area is extrapolated as a power of τ).
  Elliptic-polar grid x = a s cos φ, y = b s sin φ, s to 8 (68 cells graded towards the edge
  s = 1 from both sides, the first 2e-4 wide), 288 angles, the elliptical field with 512
  directions (about 1e-3 p0 next to the edge); the peak is searched on the edge at 720 angles
  (the singular part of the integrand subtracted: 1e-8 of p0).
* :func:`line_table` — the same for the sliding line contact per unit length (units of b).

Interpolation: linear in log x_c, in μ and in log τ (log of the area); the tests check the
shell's between nodes against its closed form, and the tables' nodes against quadrature of
the closed-form fields.
"""
from __future__ import annotations

import math
from functools import lru_cache
from typing import Any

import numpy as np
from scipy.integrate import trapezoid

from demfem.errors import InvalidParameterError, check_positive, check_range
from demfem.stress.hamilton import sliding_surface_stresses, trailing_edge_tension
from demfem.stress.hertz import circular_surface_stresses
from demfem.stress.shell import hertz_patch_surface_stresses, point_load_resultants
from demfem.stress.surface_field import elliptical_surface_stresses, principal_in_plane

__all__ = ["SHELL_XC", "TAU", "MU_STEP", "mu_grid", "shell_table", "contact_table",
           "line_table", "interp_log", "interp_mu_tau"]

#: x_c = c/ℓ of :func:`shell_table`.
SHELL_XC = np.geomspace(1e-6, 0.999, 110)
#: τ = 1 + σ_b/σ_peak of the offset tables (σ_b ≤ 0 the bending stress at the contact edge).
TAU = np.geomspace(0.02, 1.0, 18)
#: Spacing of the friction-coefficient grid.
MU_STEP = 0.05


def mu_grid(mu_max: float) -> tuple[float, ...]:
    """The μ grid 0, 0.05, … up to at least ``mu_max`` (≤ 2)."""
    top = check_range("mu_max", mu_max, 0.0, 2.0, lo_open=False, hi_open=False)
    n = int(math.ceil(top / MU_STEP - 1e-9)) + 1
    return tuple(round(k * MU_STEP, 10) for k in range(max(n, 2)))


@lru_cache(maxsize=32)
def shell_table(nu: float, m_inner: float, m_outer: float) -> dict[str, np.ndarray]:
    """The shell's dimensionless numbers on :data:`SHELL_XC` (module docstring): keys
    ``inner_peak`` (σ1 t²/F), ``inner_area`` (A/(π c²)), ``edge_outer_r`` (σ_r t²/F at
    r = c, outer surface), ``ring_peak`` (σ1 t²/F of the outer tensile ring, ≥ 0),
    ``ring_area`` (A/ℓ²)."""
    nu = check_range("nu", nu, -1.0, 0.5)
    m_inner, m_outer = check_positive("m_inner", m_inner), check_positive("m_outer", m_outer)
    keys = ("inner_peak", "inner_area", "edge_outer_r", "ring_peak", "ring_area")
    out = {k: np.empty(SHELL_XC.size) for k in keys}
    # beyond the patch the field is the point solution's plus a correction: its Kelvin
    # functions once on a common grid, the patch's own on 240 points per x_c
    far = np.geomspace(SHELL_XC[0], 12.0, 3000)
    far_point = point_load_resultants(far, nu)
    for k, xc in enumerate(SHELL_XC):
        keep = far > xc
        near_x = np.linspace(0.0, xc, 241)          # the last point is the edge r = c
        fn = hertz_patch_surface_stresses(near_x, float(xc), nu)
        ff = hertz_patch_surface_stresses(far[keep], float(xc), nu,
                                          tuple(v[keep] for v in far_point))
        x = np.concatenate([near_x, far[keep]])
        f = {key: np.concatenate([fn[key], ff[key]]) for key in fn}
        inner, outer = f["inner_s1"], f["outer_s1"]
        peak = float(np.max(inner))
        out["inner_peak"][k] = peak
        out["inner_area"][k] = trapezoid(np.maximum(inner / peak, 0.0) ** m_inner
                                         * 2.0 * math.pi * x, x) / (math.pi * xc * xc)
        out["edge_outer_r"][k] = float(fn["outer_r"][-1])
        ring = float(np.max(outer))
        out["ring_peak"][k] = max(ring, 0.0)
        out["ring_area"][k] = (trapezoid(np.maximum(outer / ring, 0.0) ** m_outer * 2.0
                                         * math.pi * x, x) if ring > 0 else 0.0)
    return out


def _graded(lo: float, hi: float, n: int, first: float) -> np.ndarray:
    """n + 1 edges from lo to hi, the first cell of width ``first``, growing geometrically."""
    return lo + (hi - lo) * np.concatenate([[0.0], np.geomspace(first / (hi - lo), 1.0, n)])


def _polar_cells(s_max: float = 8.0, n_phi: int = 288) -> tuple[np.ndarray, ...]:
    """Cell centres (s, φ) and weights s ds dφ of the elliptic-polar grid over the whole
    plane, graded towards the contact edge s = 1 from both sides."""
    inner = 1.0 - _graded(0.0, 1.0, 28, 2e-4)[::-1]
    outer = _graded(1.0, s_max, 40, 2e-4)
    edges = np.concatenate([inner, outer[1:]])
    s = 0.5 * (edges[1:] + edges[:-1])
    ds = np.diff(edges)
    phi = (np.arange(n_phi) + 0.5) * (2.0 * math.pi / n_phi)
    S, P = np.meshgrid(s, phi, indexing="ij")
    W = (s * ds)[:, None] * (2.0 * math.pi / n_phi) * np.ones_like(P)
    return S.ravel(), P.ravel(), W.ravel()


def _areas(s1: np.ndarray, weight: np.ndarray, peak: float, m: float) -> np.ndarray:
    """A_eff / (a b) of ⟨s1/peak − 1 + τ⟩/τ for each τ of :data:`TAU`."""
    if peak <= 0:
        return np.zeros(TAU.size)
    ratio = s1 / peak
    keep = ratio > 1.0 - TAU[-1]
    r, w = ratio[keep], weight[keep]
    return w @ (np.maximum((r[:, None] - 1.0 + TAU[None, :]) / TAU[None, :], 0.0) ** m)


@lru_cache(maxsize=8)
def _contact_fields(b_over_a: float, nu: float) -> dict[str, Any]:
    """The contact's surface fields on the area grid and on the edge ring (s = 1, 720
    angles), per unit p0: ``normal``, ``tx`` (traction along the major axis, +x), ``ty``
    (along the minor axis, +y), each a dict of xx, yy, xy arrays; and the grid weights."""
    beta = b_over_a
    s, phi, w = _polar_cells()
    ring_phi = np.arange(720) * (2.0 * math.pi / 720)
    out: dict[str, Any] = {"weight": w, "ring_x": np.cos(ring_phi),
                           "ring_y": beta * np.sin(ring_phi)}
    for where, (xx, yy), edge in (("grid", (s * np.cos(phi), beta * s * np.sin(phi)), False),
                                  ("ring", (out["ring_x"], out["ring_y"]), True)):
        if beta == 1.0:   # the circle: explicit fields; a traction along y is one along x turned
            n = circular_surface_stresses(xx, yy, nu)
            tx = sliding_surface_stresses(xx, yy, nu)
            rot = sliding_surface_stresses(yy, -xx, nu)
            ty = {"xx": rot["yy"], "yy": rot["xx"], "xy": -rot["xy"]}
            out[where] = {"normal": {k: n[k] for k in ("xx", "yy", "xy")}, "tx": tx, "ty": ty}
        else:
            f = elliptical_surface_stresses(xx, yy, beta, nu, 512, on_edge=edge)
            out[where] = {part: {k: f[prefix + k] for k in ("xx", "yy", "xy")}
                          for part, prefix in (("normal", "normal_"), ("tx", "tx_"),
                                               ("ty", "ty_"))}
    return out


@lru_cache(maxsize=32)
def contact_table(b_over_a: float, nu: float, m: float, mu_max: float,
                  direction: str = "major") -> dict[str, Any]:
    """The contact-field table of an elliptical (``b_over_a`` < 1) or circular (= 1) Hertz
    contact sliding along the ``direction`` axis ("major", "minor", or "worst": per μ the one
    with the larger peak), for Weibull modulus ``m`` (module docstring). Keys ``mu`` (grid),
    ``peak`` (σ1/p0), ``peak_radius`` (distance of the peak from the centre / √(ab)),
    ``area`` (shape (n_mu, n_tau), A_eff/(a b)) and its log ``log_area``."""
    beta = check_range("b_over_a", b_over_a, 0.0, 1.0, hi_open=False)
    nu = check_range("nu", nu, -1.0, 0.5)
    m = check_positive("m", m)
    if direction not in ("major", "minor", "worst"):
        raise InvalidParameterError(f"invalid sliding_direction = {direction!r}: must be "
                                    "'major', 'minor' or 'worst'")
    if direction == "worst" or (beta == 1.0 and direction == "minor"):
        a = contact_table(beta, nu, m, mu_max, "major")
        if beta == 1.0:
            return a
        b = contact_table(beta, nu, m, mu_max, "minor")
        pick = a["peak"] >= b["peak"]
        area = np.where(pick[:, None], a["area"], b["area"])
        return {"mu": a["mu"], "peak": np.where(pick, a["peak"], b["peak"]),
                "peak_radius": np.where(pick, a["peak_radius"], b["peak_radius"]),
                "area": area, "log_area": np.log(np.maximum(area, 1e-300))}
    mus = np.asarray(mu_grid(mu_max))
    fields = _contact_fields(beta, nu)
    part = "tx" if direction == "major" else "ty"
    peak = np.empty(mus.size)
    radius = np.empty(mus.size)
    area = np.empty((mus.size, TAU.size))
    for i, mu in enumerate(mus):
        grid_s1, ring_s1 = (principal_in_plane(*(fields[w]["normal"][k] + mu * fields[w][part][k]
                                                 for k in ("xx", "yy", "xy")))[0]
                            for w in ("grid", "ring"))
        if beta == 1.0:   # Hamilton's maximum, at the trailing edge
            peak[i], radius[i] = float(trailing_edge_tension(nu, mu)), 1.0
        else:
            j = int(np.argmax(ring_s1))   # the largest tension is on the edge
            peak[i] = float(ring_s1[j])
            radius[i] = math.hypot(fields["ring_x"][j], fields["ring_y"][j]) / math.sqrt(beta)
        area[i] = _areas(grid_s1, fields["weight"], peak[i], m)
    return {"mu": mus, "peak": peak, "peak_radius": radius, "area": area,
            "log_area": np.log(np.maximum(area, 1e-300))}


@lru_cache(maxsize=32)
def line_table(m: float, mu_max: float) -> dict[str, Any]:
    """The sliding line contact's table per unit length, lengths in units of b: keys ``mu``,
    ``peak`` (σ/p0 = 2μ), ``area`` (A_eff/(L b), shape (n_mu, n_tau)), ``log_area``. Surface
    σ_x: −√(1 − ξ²) − 2μξ inside, 2μ(|ξ| − √(ξ² − 1)) behind the trailing edge ξ = −1,
    compressive ahead (Johnson §7.2)."""
    m = check_positive("m", m)
    mus = np.asarray(mu_grid(mu_max))
    inside = -1.0 + _graded(0.0, 2.0, 400, 1e-5)
    behind = -1.0 - _graded(0.0, 400.0, 400, 1e-5)[::-1]
    xi_edges = np.concatenate([behind, inside[1:]])
    xi = 0.5 * (xi_edges[1:] + xi_edges[:-1])
    dxi = np.diff(xi_edges)
    area = np.zeros((mus.size, TAU.size))
    for i, mu in enumerate(mus):
        if mu <= 0:
            continue
        sig = np.where(xi < -1.0, 2 * mu * (np.abs(xi) - np.sqrt(np.maximum(xi * xi - 1, 0))),
                       -np.sqrt(np.maximum(1 - xi * xi, 0)) - 2 * mu * xi)
        area[i] = _areas(sig, dxi, 2.0 * mu, m)
    return {"mu": mus, "peak": 2.0 * mus, "area": area,
            "log_area": np.log(np.maximum(area, 1e-300))}


def interp_log(x: Any, grid: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Linear interpolation of ``values`` in log ``x`` over the log of the increasing
    ``grid`` (x clipped to the grid)."""
    return np.interp(np.log(np.asarray(x, float)), np.log(grid), values)


def interp_mu_tau(table: dict[str, Any], mu: Any, tau: Any) -> np.ndarray:
    """Bilinear interpolation of ``table["area"]`` at friction ``mu`` (linear) and offset
    ``tau`` (linear in log τ, on log area; below the first τ extrapolated along the first
    interval, i.e. as a power of τ). Zero where τ ≤ 0."""
    mus = table["mu"]
    m = np.asarray(mu, float)
    t = np.asarray(tau, float)
    lt = np.log(np.clip(t, 1e-12, 1.0))
    grid_t = np.log(TAU)
    i = np.clip(np.searchsorted(mus, m) - 1, 0, mus.size - 2)
    fm = np.clip((m - mus[i]) / (mus[i + 1] - mus[i]), 0.0, 1.0)
    j = np.clip(np.searchsorted(grid_t, lt) - 1, 0, grid_t.size - 2)
    ft = (lt - grid_t[j]) / (grid_t[j + 1] - grid_t[j])
    la = table["log_area"] if "log_area" in table else np.log(np.maximum(table["area"], 1e-300))
    v = ((1 - fm) * ((1 - ft) * la[i, j] + ft * la[i, j + 1])
         + fm * ((1 - ft) * la[i + 1, j] + ft * la[i + 1, j + 1]))
    out = np.exp(v)
    out = np.where(table["area"][i, j] + table["area"][i + 1, j + 1] > 0, out, 0.0)
    return np.where(t > 0, out, 0.0)
