"""The cartridge body as a ring: bending of a tube under line loads along its length.

Two cartridges side by side (or one against a flat wall) touch along a line of length L. Far
from the ends of that line the tube deforms in plane strain, and a slice of unit length is a
circular ring of mid-surface radius R and wall t loaded by F' = F/L per unit length. Two ways
to hold the ring against the contact force W = F' (per unit length, at θ = 0, θ measured from
the load point):

* ``"opposite"`` — an equal and opposite line load at θ = π (a cartridge squeezed between two
  neighbours, the queue pressing it against a wall): the ring under diametral compression,

      M(θ) = W R (1/π − sin θ / 2),  N(θ) = −(W/2) sin θ           (0 ≤ θ ≤ π)

  (Roark's Formulas for Stress and Strain, Table 9.2 case 1; Timoshenko, Strength of
  Materials I, §84): M(0) = W R/π at the load point, M(π/2) = −W R (1/2 − 1/π);
* ``"inertia"`` — the d'Alembert force of the ring's own acceleration, uniform over its
  circumference (an impact: nothing else holds the cartridge during the contact):

      M(θ) = (W R / 4π) [2 + cos θ − 2 (π − θ) sin θ],
      N(θ) = −(W/4π) cos θ − (W/2)(1 − θ/π) sin θ                  (0 ≤ θ ≤ π)

  (Castigliano on the half ring; Roark Table 9.2 case 15, a ring supported at one point and
  loaded by its weight: M = 3 W R/(4π) at the load point, W R/(4π) opposite).

M > 0 straightens the wall at θ (puts the inner surface in tension); N > 0 is tension. The
wall is thick enough (R/t ≈ 5 for the default cartridge) for the curved-beam (Winkler–Bach)
stresses to differ from ±6 M/t² by ≈ 7 %: with r_i = R − t/2, r_o = R + t/2 and the neutral
radius r_n = t / ln(r_o/r_i), e = R − r_n,

    σ_inner = N/t + M (r_n − r_i)/(t e r_i),   σ_outer = N/t + M (r_n − r_o)/(t e r_o)

(Roark §9.1; Boresi & Schmidt, Advanced Mechanics of Materials, ch. 9), which tend to
N/t ± 6M/t² for R/t → ∞. ``curved=False`` gives the thin-ring ±6M/t².

SI units: N/m (line loads), m, Pa; angles in radians.
"""
from __future__ import annotations

import math
from functools import lru_cache
from typing import Any

import numpy as np

from demfem.errors import InvalidParameterError, check_positive

__all__ = ["RING_SUPPORTS", "ring_resultants", "curved_beam_factors", "ring_surface_stresses",
           "ring_stress_profile"]

#: How the ring is held against the contact (module docstring).
RING_SUPPORTS = ("opposite", "inertia")


def _check_support(support: str) -> str:
    if support not in RING_SUPPORTS:
        raise InvalidParameterError(f"invalid ring_support = {support!r}: must be one of "
                                    f"{', '.join(map(repr, RING_SUPPORTS))}")
    return support


def ring_resultants(theta: Any, support: str = "opposite") -> tuple[np.ndarray, np.ndarray]:
    """(M/(W R), N/W) of the ring at angles ``theta`` (rad, from the load point; any real,
    folded onto [0, π] by symmetry) for a unit line load W (module docstring)."""
    _check_support(support)
    th = np.abs(np.remainder(np.asarray(theta, float) + math.pi, 2.0 * math.pi) - math.pi)
    s, c = np.sin(th), np.cos(th)
    if support == "opposite":
        return 1.0 / math.pi - 0.5 * s, -0.5 * s
    m = (2.0 + c - 2.0 * (math.pi - th) * s) / (4.0 * math.pi)
    n = -c / (4.0 * math.pi) - 0.5 * (1.0 - th / math.pi) * s
    return m, n


def curved_beam_factors(mid_radius: float, thickness: float) -> tuple[float, float]:
    """(k_i, k_o): the inner and outer fibre bending stress of a curved bar of rectangular
    section over the straight-beam 6 M/t² (Winkler–Bach; Roark §9.1): k_i > 1 > k_o."""
    R = check_positive("mid_radius", mid_radius)
    t = check_positive("thickness", thickness)
    if t >= 2.0 * R:
        raise InvalidParameterError(f"invalid thickness = {t!r}: must be < 2 * mid_radius = "
                                    f"{2 * R!r} m")
    ri, ro = R - 0.5 * t, R + 0.5 * t
    rn = t / math.log(ro / ri)
    e = R - rn
    if e <= 1e-9 * R:      # the thin limit: r_n → R
        return 1.0, 1.0
    return ((rn - ri) / (t * e * ri)) / (6.0 / t**2), -((rn - ro) / (t * e * ro)) / (6.0 / t**2)


def ring_surface_stresses(theta: Any, force_per_length: Any, mid_radius: float,
                          thickness: float, support: str = "opposite",
                          curved: bool = True) -> dict[str, np.ndarray]:
    """Hoop stresses (Pa) on the inner and outer surface of the ring at ``theta`` (rad from the
    load point) under ``force_per_length`` W (N/m): keys ``inner``, ``outer``, and the bending
    moment ``moment`` (N m/m) and hoop force ``hoop_force`` (N/m)."""
    R = check_positive("mid_radius", mid_radius)
    t = check_positive("thickness", thickness)
    w = np.asarray(force_per_length, float)
    ki, ko = curved_beam_factors(R, t) if curved else (1.0, 1.0)
    m, n = ring_resultants(theta, support)
    moment, hoop = m * w * R, n * w
    bend = 6.0 * moment / t**2
    return {"inner": hoop / t + ki * bend, "outer": hoop / t - ko * bend, "moment": moment,
            "hoop_force": hoop}


@lru_cache(maxsize=64)
def ring_stress_profile(mid_radius: float, thickness: float, support: str,
                        m_inner: float, m_outer: float,
                        curved: bool = True) -> dict[str, float]:
    """Dimensionless summary of the ring's hoop stresses per unit W (σ t²/(W R)): at the load
    point (``inner_load``, ``outer_load``), the largest outer tension away from the load
    (``outer_peak``) and its angle (``outer_peak_theta``, rad), the largest inner tension
    (``inner_peak``), and the Weibull effective lengths of the tensile parts of each surface,
    ∫ (σ/σ_max)^m dθ over the whole circumference (rad; multiply by the surface radius and the
    contact length for an area): ``inner_angle``, ``outer_angle``."""
    R, t = check_positive("mid_radius", mid_radius), check_positive("thickness", thickness)
    theta = np.linspace(0.0, math.pi, 20001)
    st = ring_surface_stresses(theta, 1.0, R, t, support, curved)
    scale = t * t / R
    inner, outer = st["inner"] * scale, st["outer"] * scale
    out = {"inner_load": float(inner[0]), "outer_load": float(outer[0])}
    k = int(np.argmax(outer))
    out["outer_peak"], out["outer_peak_theta"] = float(outer[k]), float(theta[k])
    out["inner_peak"] = float(np.max(inner))
    for name, field, m in (("inner_angle", inner, m_inner), ("outer_angle", outer, m_outer)):
        peak = float(np.max(field))
        if peak <= 0:
            out[name] = 0.0
            continue
        f = np.maximum(field / peak, 0.0) ** m
        # [0, π] is half the ring: the other half is its mirror image
        out[name] = 2.0 * float(np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(theta)))
    return out
