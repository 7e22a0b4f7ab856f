"""An FEM-calibrated normal law for cartridges that meet side by side.

Upright cartridges on the belt collide with parallel axes, a line contact along their
bodies, which the equivalent sphere's point-contact law (Hertz in series with Reissner) was
not made for: the explicit FEM of two default cartridges side by side (``tilt_deg = 0``)
gives a peak force 3–4× the law's at every modulus (docs/fem.md). The FEM's response is
linear: the peak force is proportional to the closing speed (F/v = 397, 397 and 403 N s/m at
0.05, 0.2 and 0.5 m/s, 45 GPa) and to √E, and its duration does not depend on the speed. A
linear spring reproduces it: F_max = v √(k m*), so

    k_n = (F_max / v)² / m*,

with m* = m/2 for two equal cartridges, from the stored FEM runs
(``data/fig3_fem.json``, parallel, 0.2 m/s), interpolated as k ∝ E between them. The
tangential stiffness takes Mindlin's ratio k_t/k_n = 2(1 − ν)/(2 − ν).
"""
from __future__ import annotations

import math
from typing import Optional

import numpy as np

from demfem.cartridge import Cartridge
from demfem.errors import InvalidParameterError, check_positive, check_range


def line_contact_stiffness(young_modulus: float, poisson_ratio: float,
                           cartridge: Optional[Cartridge] = None,
                           data: Optional[dict] = None) -> tuple[float, float]:
    """(k_n, k_t) in N/m of the FEM-calibrated linear law for two cartridges meeting side
    by side, at Young's modulus ``young_modulus`` (Pa) and Poisson's ratio
    ``poisson_ratio``. ``cartridge`` gives the mass (default: the default cartridge, whose
    geometry the stored FEM runs used); ``data``: FEM runs as stored by
    :mod:`demfem.fem.fig3` (default: the shipped ones)."""
    from demfem.fem import fig3

    e = check_positive("young_modulus", young_modulus)
    nu = check_range("poisson_ratio", poisson_ratio, -1.0, 0.5)
    data = data if data is not None else fig3.load_stored()
    rows = sorted((r for r in data["runs"] if r["tilt_deg"] == 0.0), key=lambda r: r["E_Pa"])
    if not rows:
        raise InvalidParameterError("invalid data: no side-by-side (tilt_deg = 0) FEM runs")
    v = float(data["v_rel_m_per_s"])
    m_star = 0.5 * (cartridge or Cartridge()).mass
    ee = np.array([r["E_Pa"] for r in rows])
    k = np.array([(r["max_force_N"] / v) ** 2 / m_star for r in rows])
    # k ∝ E (the FEM is linear): interpolate k/E in log E, hold the ends.
    ratio = float(np.interp(math.log(e), np.log(ee), k / ee))
    k_n = ratio * e
    return k_n, k_n * 2.0 * (1.0 - nu) / (2.0 - nu)
