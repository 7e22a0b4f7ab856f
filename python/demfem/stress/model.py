"""The stress the glass sees at one contact: the contact field on top of the shell's bending.

:func:`contact_stresses` takes a contact's normal and tangential force (N; arrays of events
allowed, vectorised) and its geometry, and returns the peak max-principal stress σ1 (Pa) on the
outer and on the inner glass surface of the cartridge, the Weibull effective area (m²) of each
surface's field, and the terms they are made of. The model superposes, for each surface,

* the **local contact field** on the outer (touched) surface: Hertz (circular, elliptical or
  line contact, :mod:`demfem.stress.hertz`) with the tangential traction of full sliding at the
  effective friction coefficient μ = Q/F (Hamilton 1983, :mod:`demfem.stress.hamilton`;
  elliptical contacts :mod:`demfem.stress.surface_field`): the contact-edge tension
  p0 [(1 − 2ν)/3 + (4 + ν)πμ/8] for a circular contact, 2 μ p0 for a line contact;
* the **global field** of the wall: the body as a long cylindrical shell under the contact's
  radial load (:mod:`demfem.stress.cylinder_load`: the double Fourier series of the load,
  each harmonic in Sanders–Koiter theory, with the exact elastic-layer correction of the
  load's spread through the wall) — the Hertz circle (an ellipse as its equivalent circle
  √(ab)) on the free body held by its d'Alembert force for point contacts, a line load held
  by an equal one opposite (or by the d'Alembert force) for line contacts. Under the load it
  bends the wall inward: the inner surface in tension, the outer in compression.

Outer σ1: the contact-edge tension plus the bending stress at the same place and in the same
direction — radial at the edge of the contact (r = a for a circle, the distance of the peak for
an ellipse), the less compressive of along and around the axis (where the frictionless peak
stands; the worse sliding direction); hoop at the load line for a line contact — which is
compressive, so the superposition lowers the contact's peak; or, if larger, the bending field's
own tension away from the contact (the tube's sides). Inner σ1: the bending tension under the
load. Effective areas (ASTM C1683) of each term from the dimensionless tables of
:mod:`demfem.stress.effective_area` and :mod:`demfem.stress.cylinder_load`, combined as
A = Σ A_k (σ_k/σ1_max)^m.

Assumptions and range (docs/stress.md has the discussion): linear elastic glass, quasi-static
(the contact lasts 30–100 µs, the wall's local bending period under the load ≈ 5 µs), the
contact small against the wall (a < t for the half-space field, a < ℓ for the concentrated
load), a long straight tube free over the cartridge's body length (no rim, shoulder or free
ends), full sliding (no stick zone), mid-body (``location = "body"``). Near the open rim and below
the shoulder (``location = "rim"``, ``"shoulder"``; point contacts only) no closed form holds:
the global terms (the inner bending tension, the outer bending at the contact edge, the ring
tension away from it, and their effective areas) are multiplied by factors from a resolved
FEM of the whole cartridge at the place over the same at mid-body
(:mod:`demfem.stress.place_factors`), the local contact term kept, and the terms recombined as
at mid-body. Optional flaw-depth correction (:mod:`demfem.stress.flaw_depth`).

SI units: N, m, Pa, m².
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any, Optional

import numpy as np

from demfem.errors import InvalidParameterError, ShapeError, check_positive, check_range
from demfem.stress import effective_area as ea
from demfem.stress.flaw_depth import circle_flaw_table, flaw_factor, line_flaw_table
from demfem.stress.hamilton import trailing_edge_tension
from demfem.stress.hertz import (contact_modulus, crossed_cylinder_curvatures,
                                 ellipse_size_factors, line_contact)
from demfem.stress.cylinder_load import RHO, line_load_profile, point_load_table
from demfem.stress.ring import RING_SUPPORTS
from demfem.stress.shell import characteristic_length

__all__ = ["GEOMETRIES", "LOCATIONS", "PLACE_GEOMETRIES", "ContactStresses", "contact_stresses"]

#: Contact geometries (:func:`contact_stresses`).
GEOMETRIES = ("crossed", "parallel", "wall", "edge")
#: Places on the cartridge: mid-body (the closed forms), near the open rim and below the
#: shoulder (the closed forms times FEM factors, :mod:`demfem.stress.place_factors`).
LOCATIONS = ("body", "rim", "shoulder")
#: Geometries the place factors hold for (point contacts).
PLACE_GEOMETRIES = ("crossed", "edge")
#: Largest effective friction coefficient Q/F accepted without a ``friction_coefficient``.
DEFAULT_FRICTION_LIMIT = 1.0


@dataclass(frozen=True)
class ContactStresses:
    """Stresses of contact events (arrays of the forces' broadcast shape; SI units).

    Attributes:
        outer_sigma1_max: peak σ1 on the outer (touched) surface, Pa (≥ 0: 0 where that
            surface is nowhere in tension).
        inner_sigma1_max: peak σ1 on the inner surface, Pa.
        outer_effective_area: Weibull effective area of the outer σ1 field, m².
        inner_effective_area: the same for the inner surface, m².
        outer_contact_Pa: the contact-edge tension of the contact field with friction (and the
            flaw-depth correction when asked for), Pa.
        outer_bending_Pa: the wall's bending stress on the outer surface at the contact-edge
            peak and in its direction, Pa (negative: compression).
        inner_bending_Pa: the wall's bending (and membrane) tension on the inner surface under
            the load, Pa (the whole inner σ1).
        outer_ring_Pa: the bending field's largest outer tension away from the contact, Pa.
        outer_from_contact: True where the outer peak is the contact edge (contact tension plus
            bending), False where it is the bending field's own tension.
        p0: peak contact pressure, Pa.
        a: contact semi-axis along the larger dimension, m (half the contact length for a line
            contact).
        b: contact semi-axis along the smaller dimension (half-width of a line contact), m.
        friction: effective friction coefficient Q/F of each event.
        weibull_modulus_outer: m of the outer effective area.
        weibull_modulus_inner: m of the inner effective area.
    """

    outer_sigma1_max: np.ndarray
    inner_sigma1_max: np.ndarray
    outer_effective_area: np.ndarray
    inner_effective_area: np.ndarray
    outer_contact_Pa: np.ndarray
    outer_bending_Pa: np.ndarray
    inner_bending_Pa: np.ndarray
    outer_ring_Pa: np.ndarray
    outer_from_contact: np.ndarray
    p0: np.ndarray
    a: np.ndarray
    b: np.ndarray
    friction: np.ndarray
    weibull_modulus_outer: float
    weibull_modulus_inner: float

    def to_dict(self) -> dict[str, Any]:
        """The fields as a dict (arrays as they are)."""
        return asdict(self)


def _array(name: str, value: Any) -> np.ndarray:
    """``value`` as a float array; non-numbers and booleans name ``name``."""
    try:
        raw = np.asarray(value)
        if raw.dtype == bool:
            raise TypeError
        return np.asarray(raw, float)
    except (TypeError, ValueError):
        raise InvalidParameterError(f"invalid {name} = {value!r}: must be a real number or an "
                                    "array of them") from None


def _forces(normal_force: Any, tangential_force: Any) -> tuple[np.ndarray, np.ndarray]:
    f0, q0 = _array("normal_force", normal_force), _array("tangential_force", tangential_force)
    try:
        f, q = np.broadcast_arrays(f0, q0)
    except ValueError:
        raise ShapeError(f"invalid tangential_force: shape {np.shape(tangential_force)} does not "
                         f"broadcast with normal_force's {np.shape(normal_force)}") from None
    for name, arr, ok, rng in (("normal_force", f, np.isfinite(f) & (f > 0), "finite and > 0 N"),
                               ("tangential_force", q, np.isfinite(q) & (q >= 0),
                                "finite and >= 0 N (its magnitude)")):
        if not np.all(ok):
            k = int(np.flatnonzero(~ok.ravel())[0])
            raise InvalidParameterError(f"invalid {name} = {arr.ravel()[k]!r} (event {k}): must "
                                        f"be {rng}")
    return f, q


def _modulus(name: str, value: Optional[float], default: float) -> float:
    m = default if value is None else check_range(name, value, 1.0, 100.0, hi_open=False)
    return float(m)


def _material(name: str, value: Any, default: Any) -> Any:
    from demfem.materials import Material

    if value is None:
        return default
    if not isinstance(value, Material):
        raise InvalidParameterError(f"invalid {name} = {value!r}: must be a "
                                    "demfem.materials.Material")
    return value


def contact_stresses(normal_force: Any, tangential_force: Any = 0.0, *,
                     geometry: str = "crossed", crossing_angle_deg: float = 90.0,
                     contact_length: Optional[float] = None, location: str = "body",
                     cartridge: Any = None, material: Any = None,
                     weibull_modulus_outer: Optional[float] = None,
                     weibull_modulus_inner: Optional[float] = None,
                     friction_coefficient: Optional[float] = None,
                     edge_radius: Optional[float] = None, partner_material: Any = None,
                     sliding_direction: str = "worst", ring_support: str = "opposite",
                     flaw_depth: Any = None) -> ContactStresses:
    """Peak σ1 and effective areas on the outer and inner glass surface of a cartridge at a
    contact (module docstring).

    Args:
        normal_force: contact force F, N, > 0 (scalar or array: one value per event).
        tangential_force: tangential force Q, N, ≥ 0 (its magnitude; broadcast with F). The
            traction is that of full sliding at μ = Q/F.
        geometry: ``"crossed"`` — two cartridges (the body's outer radius) whose axes cross at
            ``crossing_angle_deg``: an elliptical Hertz contact, circular at 90°;
            ``"parallel"`` — two cartridges side by side touching along ``contact_length``: a
            line contact, the ring bending of each; ``"wall"`` — a cartridge pressed against a
            flat wall along ``contact_length`` (its axis parallel to the wall): a line contact
            (a tilted cartridge touches a wall with its rim or base edge: ``location`` "rim");
            ``"edge"`` — a cartridge against a rail or gate edge of radius ``edge_radius``
            crossing its axis at ``crossing_angle_deg``: crossed cylinders.
        crossing_angle_deg: angle between the axes, degrees, in (0, 90] ("crossed", "edge";
            ignored for line contacts).
        contact_length: length of a line contact, m, in (0, body length] ("parallel", "wall";
            required there, refused elsewhere).
        location: ``"body"`` (mid-body, away from the rim and the shoulder by a few bending
            lengths ℓ = √(R t)/(12(1 − ν²))^{1/4}); ``"rim"`` (the contact centre
            max(t/2, 1.5 a) from the open end face) or ``"shoulder"`` (max(t/2, 1.5 a) below
            the body–shoulder junction): the global terms times the FEM factors of
            :func:`demfem.stress.place_factors.place_factors` (interpolated in log F and μ,
            clamped at the table's ends: 1–100 N, μ 0–0.2), point contacts ("crossed",
            "edge") only — a line contact ("parallel", "wall") there is refused.
        cartridge: :class:`demfem.cartridge.Cartridge` (default: the default 3 mL cartridge).
        material: the cartridge's glass, :class:`demfem.materials.Material` (default: the
            cartridge's, the paper's E = 45 GPa, ν = 0.22).
        weibull_modulus_outer, weibull_modulus_inner: m of the effective areas, in [1, 100]
            (default: :data:`demfem.risk.OUTER_SURFACE`, :data:`demfem.risk.INNER_SURFACE`).
        friction_coefficient: Coulomb μ of the pair, in (0, 2]: events with Q > μ F are refused
            (default: Q/F up to 1 is accepted as the effective coefficient).
        edge_radius: radius of the rail or gate edge, m ("edge" only; required there).
        partner_material: the other body's material (default: the same glass).
        sliding_direction: for an elliptical contact, the axis the traction runs along:
            ``"major"``, ``"minor"`` or ``"worst"`` (the larger peak; default).
        ring_support: line contacts: how the tube is held, ``"opposite"`` (an equal line load
            on the other side; default) or ``"inertia"`` (an impact, the d'Alembert force of
            the free body).
        flaw_depth: depth c_f of the surface flaws, m (scalar or per event), for the
            stress-gradient correction of the contact-edge tension (:mod:`demfem.stress.
            flaw_depth`); None (default): the surface value, no correction.

    Returns:
        :class:`ContactStresses`.
    """
    from demfem.cartridge import Cartridge
    from demfem.risk.defaults import INNER_SURFACE, OUTER_SURFACE

    if geometry not in GEOMETRIES:
        raise InvalidParameterError(f"invalid geometry = {geometry!r}: must be one of "
                                    f"{', '.join(map(repr, GEOMETRIES))}")
    if location not in LOCATIONS:
        raise InvalidParameterError(f"invalid location = {location!r}: must be one of "
                                    f"{', '.join(map(repr, LOCATIONS))}")
    cart = Cartridge() if cartridge is None else cartridge
    if not isinstance(cart, Cartridge):
        raise InvalidParameterError(f"invalid cartridge = {cartridge!r}: must be a "
                                    "demfem.cartridge.Cartridge")
    mat = _material("material", material, cart.material)
    partner = _material("partner_material", partner_material, mat)
    t, r_mid, r_out = cart.wall_thickness, cart.body_mid_radius, 0.5 * cart.body_outer_diameter
    nu = mat.nu
    ell = characteristic_length(r_mid, t, nu)
    if location != "body" and geometry not in PLACE_GEOMETRIES:
        raise InvalidParameterError(
            f"invalid location = {location!r} with geometry = {geometry!r}: the rim and "
            "shoulder factors come from a FEM of a point contact (geometry 'crossed' or "
            "'edge'); a line contact's ring bending ends at the rim in a way that FEM does "
            f"not resolve — use location 'body' (mid-body, a few bending lengths "
            f"ell = {ell:.3g} m from the rim and the shoulder) for line contacts")
    if sliding_direction not in ("major", "minor", "worst"):
        raise InvalidParameterError(f"invalid sliding_direction = {sliding_direction!r}: must "
                                    "be 'major', 'minor' or 'worst'")
    if ring_support not in RING_SUPPORTS:
        raise InvalidParameterError(f"invalid ring_support = {ring_support!r}: must be one of "
                                    f"{', '.join(map(repr, RING_SUPPORTS))}")
    f, q = _forces(normal_force, tangential_force)
    mu = q / f
    limit = DEFAULT_FRICTION_LIMIT if friction_coefficient is None else check_range(
        "friction_coefficient", friction_coefficient, 0.0, 2.0, hi_open=False)
    if np.any(mu > limit * (1.0 + 1e-12)):
        k = int(np.argmax(mu.ravel()))
        hint = ("" if friction_coefficient is not None else
                "; give friction_coefficient (up to 2) to allow a larger ratio")
        raise InvalidParameterError(
            f"invalid tangential_force = {q.ravel()[k]!r} N (event {k}): exceeds "
            f"{limit:g} x normal_force = {limit * f.ravel()[k]:.6g} N, the friction limit "
            f"(tangential_force / normal_force must be in [0, {limit:g}]){hint}")
    m_out = _modulus("weibull_modulus_outer", weibull_modulus_outer,
                     OUTER_SURFACE.weibull_modulus)
    m_in = _modulus("weibull_modulus_inner", weibull_modulus_inner,
                    INNER_SURFACE.weibull_modulus)
    mu_cap = 1.0 if limit <= 1.0 else 2.0
    depth = None
    if flaw_depth is not None:
        d0 = _array("flaw_depth", flaw_depth)
        try:
            depth = np.broadcast_to(d0, f.shape)
        except ValueError:
            raise ShapeError(f"invalid flaw_depth: shape {np.shape(flaw_depth)} does not "
                             f"broadcast with normal_force's {f.shape}") from None
        if not np.all(np.isfinite(depth) & (depth > 0)):
            raise InvalidParameterError(f"invalid flaw_depth = {flaw_depth!r}: must be finite "
                                        "and > 0 m (or None: no correction)")
    e_star = contact_modulus(mat.E, nu, partner.E, partner.nu)
    common = dict(f=f, mu=mu, nu=nu, t=t, ell=ell, m_out=m_out, m_in=m_in, mu_cap=mu_cap,
                  depth=depth, r_mid=r_mid, free_length=cart.body_length)
    if geometry in ("crossed", "edge"):
        if contact_length is not None:
            raise InvalidParameterError(f"invalid contact_length = {contact_length!r}: only for "
                                        "geometry 'parallel' or 'wall' (a line contact)")
        if geometry == "edge":
            if edge_radius is None:
                raise InvalidParameterError("invalid edge_radius = None: geometry 'edge' needs "
                                            "the rail or gate edge's radius, m (> 0)")
            r2 = check_positive("edge_radius", edge_radius)
        elif edge_radius is not None:
            raise InvalidParameterError(f"invalid edge_radius = {edge_radius!r}: only for "
                                        "geometry 'edge'")
        else:
            r2 = r_out
        A, B = crossed_cylinder_curvatures(r_out, r2, crossing_angle_deg)
        factors = None
        if location != "body":
            from demfem.stress.place_factors import place_factors

            factors = place_factors(location, f, mu)
        out = _point(A, B, e_star, direction=sliding_direction, factors=factors, **common)
    else:
        if edge_radius is not None:
            raise InvalidParameterError(f"invalid edge_radius = {edge_radius!r}: only for "
                                        "geometry 'edge'")
        if contact_length is None:
            raise InvalidParameterError(f"invalid contact_length = None: geometry "
                                        f"{geometry!r} (a line contact) needs the contact's "
                                        f"length, m, in (0, {cart.body_length:g}]")
        length = check_range("contact_length", contact_length, 0.0, cart.body_length,
                             hi_open=False)
        r_star = 0.5 * r_out if geometry == "parallel" else r_out
        out = _line(length, r_star, e_star, ring_support, **common)
    return ContactStresses(**out, friction=mu, weibull_modulus_outer=m_out,
                           weibull_modulus_inner=m_in)


def _combine(near: np.ndarray, area_near: np.ndarray, ring: np.ndarray, area_ring: np.ndarray,
             m: float) -> tuple[np.ndarray, np.ndarray]:
    """Peak and effective area of two disjoint tensile regions (σ_k, A_k)."""
    peak = np.maximum(np.maximum(near, ring), 0.0)
    safe = np.where(peak > 0, peak, 1.0)
    area = (np.where(near > 0, area_near * (np.maximum(near, 0.0) / safe) ** m, 0.0)
            + np.where(ring > 0, area_ring * (np.maximum(ring, 0.0) / safe) ** m, 0.0))
    return peak, area


def _offset(contact: np.ndarray, bending: np.ndarray) -> np.ndarray:
    """τ = 1 + min(σ_b/σ_contact, 0): the bending offset as a fraction of the contact peak."""
    with np.errstate(divide="ignore", invalid="ignore"):
        rho = np.where(contact > 0, bending / np.where(contact > 0, contact, 1.0), -1.0)
    return 1.0 + np.minimum(rho, 0.0)


def _point(A: float, B: float, e_star: float, *, f: np.ndarray, mu: np.ndarray, nu: float,
           t: float, ell: float, m_out: float, m_in: float, mu_cap: float, depth: Any,
           r_mid: float, free_length: float, direction: str,
           factors: Optional[dict[str, np.ndarray]] = None) -> dict[str, np.ndarray]:
    """Crossed cylinders: elliptical (or circular) Hertz contact on the cylindrical wall (its
    field tabulated over c/t, c = √(ab), free over ``free_length``); ``factors`` (per event,
    :func:`demfem.stress.place_factors.place_factors`) scale the global terms at the rim or
    the shoulder."""
    alpha, beta, _ = ellipse_size_factors(A, B)
    a = alpha * np.cbrt(f / e_star)
    if np.any(a >= ell):
        f_max = e_star * (ell / alpha) ** 3
        k = int(np.argmax(a.ravel()))
        raise InvalidParameterError(
            f"invalid normal_force = {f.ravel()[k]!r} N (event {k}): the contact semi-axis "
            f"a = {a.ravel()[k]:.4g} m must be < the shell's bending length ell = {ell:.4g} m "
            f"(a concentrated load), i.e. normal_force < {f_max:.4g} N for this geometry; "
            "for near-parallel bodies use geometry 'parallel'")
    b = beta * a
    p0 = 3.0 * f / (2.0 * math.pi * a * b)
    c = np.sqrt(a * b)
    u = c / t
    wall = point_load_table(r_mid, t, nu, free_length, m_in, m_out)
    grid = wall["c_over_t"]
    inner = np.interp(u, grid, wall["inner_peak"]) * f / t**2
    inner_area = np.interp(u, grid, wall["inner_area"]) * t * t
    table = ea.contact_table(beta, nu, m_out, mu_cap, direction)
    if beta == 1.0:
        peak = trailing_edge_tension(nu, mu)
        radius = np.ones_like(f)
    else:
        peak = np.interp(mu, table["mu"], table["peak"])
        radius = table["peak_radius"][np.clip(np.rint(mu / ea.MU_STEP).astype(int), 0,
                                              table["mu"].size - 1)]
    contact = p0 * peak
    if depth is not None:
        mus = table["mu"]
        g = flaw_factor(circle_flaw_table(nu, tuple(mus)), mus, trailing_edge_tension(nu, mu),
                        depth / (a if beta == 1.0 else c), mu)
        contact = contact * g
    bending = _edge_bending(wall, u, radius) * f / t**2
    ring = np.interp(u, grid, wall["ring_peak"]) * f / t**2
    area_ring = np.interp(u, grid, wall["ring_area"]) * t * t
    if factors is not None:
        inner = inner * factors["inner"]
        inner_area = inner_area * factors["inner_area"]
        bending = bending * factors["outer_bending"]
        ring = ring * factors["ring"]
        area_ring = area_ring * factors["ring_area"]
    tau = _offset(contact, bending)
    near = contact + bending
    area_near = np.where(near > 0, a * b * ea.interp_mu_tau(table, mu, tau), 0.0)
    outer, outer_area = _combine(near, area_near, ring, area_ring, m_out)
    return {"outer_sigma1_max": outer, "inner_sigma1_max": inner,
            "outer_effective_area": outer_area, "inner_effective_area": inner_area,
            "outer_contact_Pa": contact, "outer_bending_Pa": bending, "inner_bending_Pa": inner,
            "outer_ring_Pa": ring, "outer_from_contact": near >= ring, "p0": p0, "a": a, "b": b}


def _edge_bending(wall: dict[str, np.ndarray], u: np.ndarray, radius: np.ndarray) -> np.ndarray:
    """Outer bending stress σ t²/F at the contact-edge peak, at ``radius`` × c from the load's
    centre (1 for a circle; below 1, inside the equivalent circle, the edge value): the
    less compressive of the axial stress along the axis and the hoop stress around it — the
    place on the rim where the contact-edge peak stands (μ = 0), or the worst sliding
    direction (μ > 0; the events do not give it). Bilinear in c/t and ρ/c."""
    rim = np.maximum(wall["rim_axial"], wall["rim_hoop"])
    grid = wall["c_over_t"]
    i = np.clip(np.searchsorted(grid, u) - 1, 0, grid.size - 2)
    fu = np.clip((u - grid[i]) / (grid[i + 1] - grid[i]), 0.0, 1.0)
    rho = np.clip(radius, RHO[0], RHO[-1])
    j = np.clip(np.searchsorted(RHO, rho) - 1, 0, RHO.size - 2)
    fr = (rho - RHO[j]) / (RHO[j + 1] - RHO[j])
    return ((1 - fu) * ((1 - fr) * rim[i, j] + fr * rim[i, j + 1])
            + fu * ((1 - fr) * rim[i + 1, j] + fr * rim[i + 1, j + 1]))


def _line(length: float, r_star: float, e_star: float, support: str, *,
          f: np.ndarray, mu: np.ndarray, nu: float, t: float, ell: float, m_out: float,
          m_in: float, mu_cap: float, depth: Any, r_mid: float,
          free_length: float) -> dict[str, np.ndarray]:
    """Line contacts: Hertz line contact (McEwen's sliding field) on the cylindrical wall."""
    w = f / length
    lc = line_contact(w, r_star, e_star)
    half = lc["b"]
    if np.any(half >= t):
        k = int(np.argmax(half.ravel()))
        raise InvalidParameterError(
            f"invalid normal_force = {f.ravel()[k]!r} N (event {k}): the line contact's "
            f"half-width b = {half.ravel()[k]:.4g} m must be < the wall thickness t = {t:.4g} m "
            "(a contact small against the wall)")
    p0 = lc["p0"]
    prof = line_load_profile(r_mid, t, nu, length, support, free_length, m_in, m_out)
    scale = f / t**2
    inner = prof["inner_peak"] * scale
    inner_area = prof["inner_area"] * np.ones_like(f)
    table = ea.line_table(m_out, mu_cap)
    contact = 2.0 * mu * p0
    if depth is not None:
        mus = table["mu"]
        contact = contact * flaw_factor(line_flaw_table(tuple(mus)), mus, 2.0 * mu,
                                        depth / half, mu)
    bending = prof["outer_load"] * scale
    tau = _offset(contact, bending)
    near = contact + bending
    area_near = np.where(near > 0, length * half * ea.interp_mu_tau(table, mu, tau), 0.0)
    ring = prof["outer_peak"] * scale
    area_ring = prof["outer_area"] * np.ones_like(f)
    outer, outer_area = _combine(near, area_near, ring, area_ring, m_out)
    return {"outer_sigma1_max": outer, "inner_sigma1_max": inner,
            "outer_effective_area": outer_area, "inner_effective_area": inner_area,
            "outer_contact_Pa": contact, "outer_bending_Pa": bending, "inner_bending_Pa": inner,
            "outer_ring_Pa": ring, "outer_from_contact": near >= ring, "p0": p0,
            "a": np.full(f.shape, 0.5 * length), "b": half}
