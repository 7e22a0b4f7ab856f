"""The stress stage: each impact event → peak contact force, contact radius and duration
(calibrated Hertz–Reissner law, :mod:`demfem.assess.impact`) → peak σ1 and effective area on
the inner and on the outer surface (:class:`demfem.assess.StressModel`).

The collision's inputs are its normal relative speed at onset (m/s), its partner type
(sphere: another cartridge's equivalent body; wall: a flat immovable half-space of the wall's
glass) and the Young's modulus E (Pa) at which the forces are evaluated.

Measured contacts: where the DEM measured the contact (``measured_force``, N, and
``measured_impulse``, N s, finite; :mod:`demfem.assess.events`) and ran at the modulus the
stresses are evaluated at, the peak force is the measured one, and the duration is that of the
half-sine pulse with the measured peak and impulse, τ = (π/2) J / F_max (the pulse the
slow-crack-growth equivalent assumes; for a binary impact it is the Hertz–Reissner duration to
a few per cent). The law's force at the onset speed is kept beside it (``law_force_N``): in a
packed table the two differ where the queue presses on a contact. The tangential speed
is not used: the stress model is that of a radial load (the paper's FEM shows tangential
forces of ≈ 1/6 of the normal ones, Fig. 11).

SI units: m/s, N, m, s, Pa, m².
"""
from __future__ import annotations

from typing import Optional

import numpy as np

from demfem.assess.impact import ImpactLaw, cartridge_body, flat_partner
from demfem.assess.stress_model import StressModel
from demfem.errors import InvalidParameterError, check_positive

__all__ = ["collision_stresses", "STRESS_FIELDS"]

#: Arrays of the stress stage, one value per event (units in the names).
STRESS_FIELDS = ("force_N", "contact_radius_m", "duration_s", "sigma_inner_Pa",
                 "sigma_outer_Pa", "area_inner_m2", "area_outer_m2", "law_force_N")


def collision_stresses(normal_speed: np.ndarray, partner: np.ndarray, model: StressModel,
                       young_modulus: float, poisson_ratio: Optional[float] = None,
                       wall_modulus: Optional[float] = None,
                       measured_force: Optional[np.ndarray] = None,
                       measured_impulse: Optional[np.ndarray] = None) -> dict[str, np.ndarray]:
    """Loads and stresses of collisions at normal speeds ``normal_speed`` (m/s, > 0) with
    partner codes ``partner`` (0 sphere, 1 wall), for glass of ``young_modulus`` (Pa) and
    ``poisson_ratio`` (default: the cartridge glass's), walls of ``wall_modulus`` (Pa,
    default: the same glass); where ``measured_force`` (N) and ``measured_impulse`` (N s) are
    given and finite, with the measured peak force and its half-sine duration (module
    docstring). Returns the :data:`STRESS_FIELDS` arrays."""
    v = np.asarray(normal_speed, float)
    code = np.asarray(partner, np.int64)
    E = check_positive("young_modulus", young_modulus)
    body = cartridge_body(E, poisson_ratio)
    laws = {0: ImpactLaw(body, body),
            1: ImpactLaw(body, flat_partner(E if wall_modulus is None else
                                            check_positive("wall_modulus", wall_modulus),
                                            body.nu))}
    out = {k: np.zeros(v.shape) for k in STRESS_FIELDS}
    f_meas = np.full(v.shape, np.nan) if measured_force is None else np.asarray(
        measured_force, float)
    j_meas = np.full(v.shape, np.nan) if measured_impulse is None else np.asarray(
        measured_impulse, float)
    if f_meas.shape != v.shape or j_meas.shape != v.shape:
        raise InvalidParameterError("invalid measured_force or measured_impulse: must have "
                                    f"the shape of normal_speed {v.shape}")
    use = np.isfinite(f_meas) & np.isfinite(j_meas) & (f_meas > 0) & (j_meas > 0)
    for c, law in laws.items():
        sel = code == c
        if not np.any(sel):
            continue
        # the law where the DEM did not measure (speeds > 0 there; measured ones may be 0)
        f_law = np.zeros(int(sel.sum()))
        tau = np.zeros(int(sel.sum()))
        moving = v[sel] > 0
        f_law[moving] = law.force(v[sel][moving])
        tau[moving] = law.duration(v[sel][moving])
        m = use[sel]
        if np.any(~moving & ~m):
            law.force(v[sel][~moving & ~m])  # raises: a law's impact needs a speed > 0
        f = np.where(m, f_meas[sel], f_law)
        tau = np.where(m, 0.5 * np.pi * j_meas[sel] / np.where(m, f_meas[sel], 1.0), tau)
        a = law.contact_radius(f)
        out["force_N"][sel] = f
        out["law_force_N"][sel] = f_law
        out["contact_radius_m"][sel] = a
        out["duration_s"][sel] = tau
        out["sigma_inner_Pa"][sel] = model.sigma_inner(f)
        out["sigma_outer_Pa"][sel] = model.sigma_outer(f)
        a_in, a_out = model.stressed_areas(a)
        out["area_inner_m2"][sel] = a_in
        out["area_outer_m2"][sel] = a_out
    return out
