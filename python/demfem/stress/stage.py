"""The stress stage of an assessment: each collision event → its loads (peak normal and
tangential force, contact duration) → peak σ1 and Weibull effective area on the outer and on
the inner glass surface.

**Loads.** Where the DEM measured the contact (``measured_force``, N, and
``measured_impulse``, N s, finite; :mod:`demfem.assess.events`) and ran at the modulus the
stresses are evaluated at, the peak force is the measured one and the duration that of the
half-sine pulse with the measured peak and impulse, τ = (π/2) J / F_max (the pulse the
slow-crack-growth equivalent assumes); elsewhere the calibrated Hertz–Reissner law at the
onset speed (:mod:`demfem.assess.impact`), whose force is kept beside it (``law_force_N``).
The peak tangential (friction) force is the measured one where there is one (capped at the
pair's Coulomb limit μ F), else 0.

**Stresses** (``model="contact"``, the default): :func:`demfem.stress.contact_stresses`, the
local contact field with friction (Hertz, Hamilton 1983) on the outer surface on top of the
shell's bending, for the contact geometry of each partner:

* cartridge–cartridge: ``pair_geometry`` — ``"crossed"`` (default: the axes crossing at 90°,
  a point contact, the severe case of two cartridges that tilt against each other) or
  ``"parallel"`` (upright neighbours touching along their body: a line contact);
* cartridge–wall, gate: ``"wall"``, the upright body against the flat along its length.

The equivalent spheres of the DEM carry no axis, so the geometry is an assumption stated in
the report; ``model="shell"`` gives the former shell-only model
(:class:`demfem.stress.StressModel`, σ1 = β F/t²) for comparison.

**Places on the cartridge** (``place_weights``, :mod:`demfem.assess.places`): nor do the
spheres carry a height. Given each event's probabilities of landing on the body, at the rim
or at the shoulder, the stresses are computed at every place with a weight
(``location`` of :func:`demfem.stress.contact_stresses`) into the ``*_by_place`` arrays
(n, 3), and the one-value fields are those of the event's worst place (the largest outer σ1
among the places it may land on; ``place_index``). The risk stage takes the expectation
over the places. Only point contacts (:data:`demfem.stress.model.PLACE_GEOMETRIES`) have a
model at the rim and the shoulder; line contacts (walls and gate, and pairs with
``pair_geometry="parallel"``) take the body's model at every place, as the report states.

SI units: m/s, N, m, s, Pa, m².
"""
from __future__ import annotations

from typing import Any, Optional

import numpy as np

from demfem.assess.impact import ImpactLaw, cartridge_body, flat_partner
from demfem.errors import InvalidParameterError, check_positive, check_range
from demfem.stress.stress_model import StressModel

__all__ = ["collision_stresses", "STRESS_FIELDS", "PLACE_FIELDS", "PAIR_GEOMETRIES",
           "STRESS_MODELS", "characteristic_flaw_depth", "FRACTURE_TOUGHNESS"]

#: Arrays of the stress stage, one value per event (units in the names).
STRESS_FIELDS = ("force_N", "tangential_force_N", "contact_radius_m", "duration_s",
                 "sigma_inner_Pa", "sigma_outer_Pa", "area_inner_m2", "area_outer_m2",
                 "law_force_N", "sigma_outer_contact_Pa", "sigma_outer_bending_Pa", "p0_Pa")
#: The fields computed per place when place weights are given: ``<field>_by_place``, (n, 3).
PLACE_FIELDS = ("sigma_inner_Pa", "sigma_outer_Pa", "area_inner_m2", "area_outer_m2",
                "sigma_outer_contact_Pa", "sigma_outer_bending_Pa", "p0_Pa")

#: Fracture toughness K_Ic of the glass, Pa √m: 0.75 MPa √m, soda-lime and borosilicate
#: glasses 0.7–0.8 (Wiederhorn 1969, J. Am. Ceram. Soc. 52, 99; Lawn 1993, Table 2.2).
FRACTURE_TOUGHNESS = 0.75e6
#: Free-surface factor of a straight edge flaw (K = 1.12 σ √(π c)).
SURFACE_FLAW_FACTOR = 1.12


def characteristic_flaw_depth(characteristic_strength: float,
                              toughness: float = FRACTURE_TOUGHNESS) -> float:
    """Depth c (m) of the surface flaw that fails at the surface's characteristic strength σ_0
    (Pa) under uniform tension: K_Ic = 1.12 σ_0 √(π c), c = (K_Ic / (1.12 σ_0))² / π
    (≈ 30 µm for the handled outer surface's planning σ_0 = 70 MPa)."""
    s0 = check_positive("characteristic_strength", characteristic_strength)
    k = check_positive("toughness", toughness)
    return (k / (SURFACE_FLAW_FACTOR * s0)) ** 2 / np.pi


#: Contact geometries a cartridge–cartridge event may be given.
PAIR_GEOMETRIES = ("crossed", "parallel")
#: The stress models of the stage.
STRESS_MODELS = ("contact", "shell")


def _loads(v: np.ndarray, code: np.ndarray, laws: dict[int, ImpactLaw], f_meas: np.ndarray,
           j_meas: np.ndarray, out: dict[str, np.ndarray]) -> None:
    """Force, law force, contact radius and duration per event into ``out``."""
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
        out["force_N"][sel] = f
        out["law_force_N"][sel] = f_law
        out["contact_radius_m"][sel] = law.contact_radius(f)
        out["duration_s"][sel] = np.where(
            m, 0.5 * np.pi * j_meas[sel] / np.where(m, f_meas[sel], 1.0), tau)


def collision_stresses(normal_speed: np.ndarray, partner: np.ndarray, young_modulus: float,
                       poisson_ratio: Optional[float] = None,
                       wall_modulus: Optional[float] = None,
                       measured_force: Optional[np.ndarray] = None,
                       measured_impulse: Optional[np.ndarray] = None,
                       measured_tangential: Optional[np.ndarray] = None, *,
                       model: str | StressModel = "contact", cartridge: Any = None,
                       pair_geometry: str = "crossed", friction: Optional[float] = None,
                       weibull_modulus_inner: Optional[float] = None,
                       weibull_modulus_outer: Optional[float] = None,
                       flaw_depth: Optional[float] = None,
                       place_weights: Optional[np.ndarray] = None) -> dict[str, np.ndarray]:
    """Loads and stresses of collisions (module docstring).

    Args:
        normal_speed: (n,) normal speed at onset, m/s (> 0 where not measured).
        partner: (n,) 0 for another cartridge, 1 for a wall or the gate.
        young_modulus: glass modulus E at which the loads and stresses are evaluated, Pa.
        poisson_ratio: the glass's ν (default: the cartridge's).
        wall_modulus: the walls' E, Pa (default: the same glass).
        measured_force, measured_impulse, measured_tangential: the DEM's peak normal force
            (N), normal impulse (N s) and peak tangential force (N) per event; NaN where not
            measured.
        model: ``"contact"`` (default), ``"shell"`` (the default shell-only model) or a
            :class:`StressModel` (σ1 = β F/t²).
        cartridge: :class:`demfem.cartridge.Cartridge` (default: the default 3 mL one).
        pair_geometry: cartridge–cartridge contact geometry, one of :data:`PAIR_GEOMETRIES`.
        friction: the pair's Coulomb coefficient μ: measured tangential forces are capped at
            μ F (default: no cap; Q/F must then stay ≤ 1).
        weibull_modulus_inner, weibull_modulus_outer: m of the effective areas (default:
            :data:`demfem.risk.INNER_SURFACE`, :data:`demfem.risk.OUTER_SURFACE`).
        flaw_depth: depth of the outer surface's flaws, m: the contact-edge tension is taken
            as the flaws feel it (:mod:`demfem.stress.flaw_depth`); None: the surface value.
        place_weights: (n, 3) probabilities of each event's place on the cartridge, in
            :data:`demfem.stress.model.LOCATIONS` order (body, rim, shoulder; rows sum to 1;
            :mod:`demfem.assess.places`); None: every event on the body.

    Returns:
        The :data:`STRESS_FIELDS` arrays; with ``place_weights``, also ``place_weight``
        (n, 3), ``place_index`` (n,: the worst place, whose values the one-value fields
        hold) and the ``<field>_by_place`` arrays (n, 3) of :data:`PLACE_FIELDS`.
    """
    from demfem.cartridge import Cartridge

    v = np.asarray(normal_speed, float)
    code = np.asarray(partner, np.int64)
    if code.shape != v.shape or np.any((code != 0) & (code != 1)):
        raise InvalidParameterError("invalid partner: one code per event, 0 (cartridge) or 1 "
                                    "(wall)")
    E = check_positive("young_modulus", young_modulus)
    cart = Cartridge() if cartridge is None else cartridge
    body = cartridge_body(E, poisson_ratio, cart)
    e_wall = E if wall_modulus is None else check_positive("wall_modulus", wall_modulus)
    laws = {0: ImpactLaw(body, body), 1: ImpactLaw(body, flat_partner(e_wall, body.nu))}
    measured = []
    for name, arr in (("measured_force", measured_force),
                      ("measured_impulse", measured_impulse),
                      ("measured_tangential", measured_tangential)):
        a = np.full(v.shape, np.nan) if arr is None else np.asarray(arr, float)
        if a.shape != v.shape:
            raise InvalidParameterError(f"invalid {name}: must have the shape of normal_speed "
                                        f"{v.shape}")
        measured.append(a)
    weights = _place_weights(place_weights, v.shape)
    out = {k: np.zeros(v.shape) for k in STRESS_FIELDS}
    _loads(v, code, laws, measured[0], measured[1], out)
    f = out["force_N"]
    q = np.where(np.isfinite(measured[2]) & (measured[2] > 0), measured[2], 0.0)
    if friction is not None:
        mu_cap = check_range("friction", friction, 0.0, np.inf, lo_open=False)
        q = np.minimum(q, mu_cap * f)
        friction = mu_cap if mu_cap > 0 else None
    out["tangential_force_N"] = q
    if isinstance(model, StressModel) or model == "shell":
        m = model if isinstance(model, StressModel) else StressModel.default()
        out["sigma_inner_Pa"] = m.sigma_inner(f)
        out["sigma_outer_Pa"] = m.sigma_outer(f)
        out["area_inner_m2"], out["area_outer_m2"] = m.stressed_areas(
            out["contact_radius_m"])
        out["sigma_outer_contact_Pa"][:] = np.nan
        out["sigma_outer_bending_Pa"][:] = np.nan
        out["p0_Pa"][:] = np.nan
        if weights is not None:
            # the shell-only model has no place: the same stresses wherever the event lands
            for k in PLACE_FIELDS:
                out[f"{k}_by_place"] = np.repeat(out[k][:, None], weights.shape[1], axis=1)
            out["place_weight"] = weights
            out["place_index"] = np.argmax(weights > 0, axis=1).astype(np.int64)
        return out
    if model != "contact":
        raise InvalidParameterError(f"invalid model = {model!r}: must be one of {STRESS_MODELS} "
                                    "or a StressModel")
    if pair_geometry not in PAIR_GEOMETRIES:
        raise InvalidParameterError(f"invalid pair_geometry = {pair_geometry!r}: must be one "
                                    f"of {PAIR_GEOMETRIES}")
    if weights is None:
        _contact_model(out, f, q, code, cart, body, e_wall, pair_geometry, friction,
                       weibull_modulus_inner, weibull_modulus_outer, flaw_depth)
        return out
    _by_place(out, weights, f, q, code, cart, body, e_wall, pair_geometry, friction,
              weibull_modulus_inner, weibull_modulus_outer, flaw_depth)
    return out


def _place_weights(w: Any, shape: tuple[int, ...]) -> Optional[np.ndarray]:
    """``place_weights`` checked: (n, 3) finite, ≥ 0, rows summing to 1."""
    from demfem.stress.model import LOCATIONS

    if w is None:
        return None
    a = np.asarray(w, float)
    if a.shape != shape + (len(LOCATIONS),):
        raise InvalidParameterError(f"invalid place_weights: shape {a.shape} must be "
                                    f"{shape + (len(LOCATIONS),)} (one row of {LOCATIONS} per "
                                    "event)")
    if np.any(~np.isfinite(a)) or np.any(a < 0) or np.any(np.abs(a.sum(axis=1) - 1.0) > 1e-9):
        raise InvalidParameterError("invalid place_weights: every row must be finite "
                                    "fractions >= 0 summing to 1")
    return a


def _by_place(out: dict[str, np.ndarray], weights: np.ndarray, f: np.ndarray, q: np.ndarray,
              code: np.ndarray, cart: Any, body: Any, e_wall: float, pair_geometry: str,
              friction: Optional[float], m_inner: Optional[float], m_outer: Optional[float],
              flaw_depth: Optional[float]) -> None:
    """The contact model at every place an event may land on (weight > 0); the one-value
    fields from each event's worst place (largest outer σ1, then the first place)."""
    from demfem.stress.model import LOCATIONS

    n = len(f)
    by = {k: np.zeros((n, len(LOCATIONS))) for k in PLACE_FIELDS}
    for j, place in enumerate(LOCATIONS):
        sel = weights[:, j] > 0
        if not np.any(sel):
            continue
        part = {k: np.zeros(int(sel.sum())) for k in STRESS_FIELDS}
        _contact_model(part, f[sel], q[sel], code[sel], cart, body, e_wall, pair_geometry,
                       friction, m_inner, m_outer, flaw_depth, location=place)
        for k in PLACE_FIELDS:
            by[k][sel, j] = part[k]
    outer = np.where(weights > 0, by["sigma_outer_Pa"], -np.inf)
    worst = np.argmax(outer, axis=1).astype(np.int64)
    rows = np.arange(n)
    for k in PLACE_FIELDS:
        out[k] = by[k][rows, worst]
        out[f"{k}_by_place"] = by[k]
    out["place_weight"] = weights
    out["place_index"] = worst


def _contact_model(out: dict[str, np.ndarray], f: np.ndarray, q: np.ndarray, code: np.ndarray,
                   cart: Any, body: Any, e_wall: float, pair_geometry: str,
                   friction: Optional[float], m_inner: Optional[float],
                   m_outer: Optional[float], flaw_depth: Optional[float],
                   location: str = "body") -> None:
    """The contact-stress model's fields of every event into ``out`` (at ``location``)."""
    from dataclasses import replace

    from demfem.materials import Material
    from demfem.stress.model import PLACE_GEOMETRIES, contact_stresses

    glass = replace(cart.material, E=body.E, nu=body.nu)
    wall = Material(E=e_wall, nu=body.nu, density=glass.density, name="wall")
    length = cart.body_length
    mu = None if friction is None else float(friction)
    cases = {0: dict(geometry=pair_geometry,
                     contact_length=length if pair_geometry == "parallel" else None),
             1: dict(geometry="wall", contact_length=length, partner_material=wall)}
    for c, kw in cases.items():
        sel = code == c
        if not np.any(sel):
            continue
        r = contact_stresses(f[sel], q[sel], cartridge=cart, material=glass,
                             weibull_modulus_outer=m_outer, weibull_modulus_inner=m_inner,
                             friction_coefficient=mu, flaw_depth=flaw_depth,
                             location=location if kw["geometry"] in PLACE_GEOMETRIES
                             else "body", **kw)
        out["sigma_outer_Pa"][sel] = r.outer_sigma1_max
        out["sigma_inner_Pa"][sel] = r.inner_sigma1_max
        out["area_outer_m2"][sel] = r.outer_effective_area
        out["area_inner_m2"][sel] = r.inner_effective_area
        out["sigma_outer_contact_Pa"][sel] = r.outer_contact_Pa
        out["sigma_outer_bending_Pa"][sel] = r.outer_bending_Pa
        out["p0_Pa"][sel] = r.p0
