"""The cartridge wall as a cylindrical shell under a local radial load: its bending and
membrane field, with the through-thickness (thick-plate) correction near the load.

The global field of a contact in :func:`demfem.stress.contact_stresses`: the surface stresses of
a circular cylindrical shell (mid-surface radius R, wall t, E, ν) under a radial pressure patch
— the Hertz circle of a crossed contact, a uniform disc or rectangle, a line load of length L
(a parallel contact) — by the double Fourier series of the load (Bijlaard 1955; Timoshenko &
Woinowsky-Krieger 1959, ch. 15–16, the Navier solution of a simply supported cylinder),
each harmonic solved exactly.

**Shell theory.** Sanders–Koiter (Sanders 1959; Koiter 1960), the first-approximation theory
that is right for every harmonic — Donnell's is not at n ≤ 2, where the ovalisation of a
parallel contact lives: its ring limit has n⁴ where (n² − 1)² is right. With x along the axis,
s = Rθ around it, displacements u, v, w (w outward) and C = E t/(1 − ν²), D = E t³/(12(1 − ν²)):

    ε_x = u_x,   ε_θ = v_s + w/R,   γ = u_s + v_x,
    κ_x = −w_xx, κ_θ = −w_ss + v_s/R,   τ = −w_xs + (3 v_x − u_s)/(4R),
    U = ½ ∫ C[ε_x² + ε_θ² + 2ν ε_x ε_θ + (1 − ν)γ²/2] + D[κ_x² + κ_θ² + 2ν κ_x κ_θ
        + 2(1 − ν)τ²] dA.

The ends x = ±L_c/2 are simply supported (w = v = N_x = M_x = 0), so the harmonics
u = U sin λx cos nθ, v = V cos λx sin nθ, w = W cos λx cos nθ, λ = mπ/L_c (m odd: loads
symmetric about x = 0, the load's centre) decouple; each is a 3 × 3 system K(λ, n)(U, V, W) =
(0, q_θ, q_r) read off the energy (:func:`mode_stiffness`). The surface strains are ε + zκ
(z = ±t/2; the twist 2zτ), the stresses plane-stress Hooke's law; on the hoop bending part the
curved-bar (Winkler–Bach) factors of a wall with R/t ≈ 5 (:func:`demfem.stress.ring.
curved_beam_factors`, Roark §9.1: +7 % inside, −6 % outside), as the ring model applies them —
on the thick-plate correction's hoop part too, so that the two still cancel at short waves
(``curved=False``: without; an O(t/R) effect first-approximation theory leaves open). At short
waves Sanders' harmonics tend to the plate's 1/(D k⁴) within 0.6 % (its O(t²/R²) terms).

**The load's spread through the wall.** Under a contact smaller than the wall (a = t/19 … t/4
here) thin-shell theory is wrong within about t of the load: the plate moment under a load of
radius c grows like ln(1/c), the three-dimensional stress on the unloaded face does not (the
load spreads through the thickness first). The correction used here is the exact elasticity
solution of a free elastic layer of thickness t under a normal surface pressure (Love's
strain function in Hankel space: Sneddon 1951, *Fourier Transforms*, ch. 10; Lur'e 1964,
*Three-dimensional problems of the theory of elasticity*; the thick-plate theory of
Woinowsky-Krieger 1933 behind Timoshenko & Woinowsky-Krieger §19). For a harmonic of
wavenumber k and s = k t, the in-plane stresses on its two faces, per unit pressure, are

    loaded face:    σ_r + σ_θ = −[(1 + 2ν) sinh²s + s²]/(sinh²s − s²),
                    σ_r − σ_θ (J2) = [(1 − 2ν) sinh²s + s²]/(sinh²s − s²),
    the other face: σ_r + σ_θ = 2(1 + ν) s sinh s/(sinh²s − s²),
                    σ_r − σ_θ (J2) = −2(1 − ν) s sinh s/(sinh²s − s²),

which tend to the half-space (−(1 + 2ν), 1 − 2ν; Boussinesq) for s → ∞ and to the thin plate
(∓6(1 ± ν)/s²) for s → 0. The correction added to each harmonic of the contact load
(:func:`layer_correction`) is the layer's minus the thin plate's minus, on the loaded face, the
half-space's (which the Hertz/Hamilton contact field already is):

    loaded face:  ΔS = 2(1 + ν)[3/s² − s²/(sinh²s − s²)],  ΔD = −2(1 − ν)[3/s² − s²/(…)],
    other face:   ΔS = 2(1 + ν)[s sinh s/(sinh²s − s²) − 3/s²],  ΔD = −2(1 − ν)[… − 3/s²],

finite at s → 0 (4(1 + ν)/5, (1 + ν)/5, …). It is the flat layer's, local (it decays within
about t of the load, where the wall's curvature, R = 4.8 t, is a correction of order t/R),
applied in the same way to every load. Thin shell plus correction converges exponentially in
k t (the series is cut at k = 24/t whatever the contact radius), and stays finite for a
point load: the inner stress and its effective area hardly depend on the contact radius
a ≪ t. At the centre of the unloaded face it reproduces Timoshenko's equivalent radius
b' = √(1.6c² + t²) − 0.675t (§19) to 1.5 % for c = 0.05 … 1.5 t (the tests): the same
physics, the whole field instead of the one number.

**Support.** ``"inertia"``: the tube is free over ``free_length`` (the cartridge's body) and
the load is balanced by the d'Alembert force of its rigid-body acceleration, uniform over
the wall (an impact; what the resolved FEM's inertia relief does); its n = 1 harmonics carry
the beam bending of the free tube (M = F L/8 at the load), the simply supported ends of the
longer computational cylinder (L_c = 2 × free_length) then carry no net force.
``"opposite"``: an equal load on the diametrically opposite side (a cartridge squeezed
between neighbours; a self-balanced pair, even n only). ``"ends"``: the simply supported ends
carry the load (the closed-form checks). The tube is straight and long: the rim, the
shoulder and the free ends of a real body are not modelled (the computational cylinder runs
on beyond the body, so a line contact over the whole body sees a tube, not a ring with free
ends).

**Tables.** A harmonic's response does not depend on the load's size, so the modes are solved
once per shell (:func:`_unit_modes`) and a load is a product of spectra. The surface fields
on a (x, θ) grid are double sums done as two products (einsum). :func:`point_load_table`
tabulates the Hertz circle of radius c over c/t (:data:`C_OVER_T`): the inner peak σ1 t²/F and
its Weibull effective area / t², the outer bending stress at distances ρ = (1 … 4) c from the
centre along and across the axis, the outer field's own tensile peak and effective area;
:func:`line_load_profile` the line contact of a given length per unit force. Built once per
process and shell (``functools.lru_cache``), interpolated per event.

References: Bijlaard, P.P. (1955) Stresses from radial loads in cylindrical pressure vessels,
Welding J. Res. Suppl. 33, 615s–623s; Sanders, J.L. (1959) An improved first-approximation
theory for thin shells, NASA TR R-24; Koiter, W.T. (1960) A consistent first approximation in
the general theory of thin elastic shells, Proc. IUTAM Symp. Delft; Timoshenko, S.,
Woinowsky-Krieger, S. (1959) *Theory of Plates and Shells*, §19, ch. 15–16; Sneddon, I.N.
(1951) *Fourier Transforms*, ch. 10; Lur'e, A.I. (1964) *Three-dimensional problems of the
theory of elasticity*, Interscience; Woinowsky-Krieger, S. (1933) Der Spannungszustand in dicken
elastischen Platten, Ing.-Arch. 4, 203–226, 305–331; Young, W.C., Budynas, R.G. *Roark's
Formulas for Stress and Strain*, §9.1.

SI units: m, N, Pa, m²; wavenumbers in rad/m; angles in rad.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache, partial
from typing import Any, Callable

import numpy as np
from scipy.special import j1

from demfem.errors import InvalidParameterError, check_count, check_positive, check_range
from demfem.stress.ring import curved_beam_factors

__all__ = ["CylinderShell", "SUPPORTS", "C_OVER_T", "RHO", "mode_stiffness",
           "layer_correction", "hertz_disc_spectrum", "uniform_disc_spectrum",
           "rectangle_spectrum", "line_spectrum", "CylinderLoadField", "cylinder_load_field",
           "point_load_table", "line_load_profile"]

#: How the tube is held against the load (module docstring).
SUPPORTS = ("inertia", "opposite", "ends")
#: c/t of :func:`point_load_table` (c: the Hertz circle's radius, t: the wall).
C_OVER_T = np.concatenate([[0.0], np.geomspace(0.01, 1.4, 22)])
#: Distances from the load's centre of the tabulated outer bending stress, in units of c.
RHO = np.array([1.0, 1.25, 1.5, 2.0, 2.5, 3.0, 4.0])
#: The series' cut-off k t of the thick-corrected field (its terms fall like k t e^{−k t}).
K_T_MAX = 24.0

Spectrum = Callable[[np.ndarray, np.ndarray], np.ndarray]


@dataclass(frozen=True)
class CylinderShell:
    """A circular cylindrical shell (SI units).

    Attributes:
        radius: mid-surface radius R, m.
        thickness: wall t, m (< R).
        young_modulus: E, Pa (the stresses of a given load do not depend on it).
        nu: Poisson ratio, in (−1, 0.5).
        length: the simply supported length L_c of the computational cylinder, m; the load
            sits at its middle.
    """

    radius: float
    thickness: float
    young_modulus: float
    nu: float
    length: float

    def __post_init__(self) -> None:
        for name in ("radius", "thickness", "young_modulus", "length"):
            object.__setattr__(self, name, check_positive(name, getattr(self, name)))
        object.__setattr__(self, "nu", check_range("nu", self.nu, -1.0, 0.5))
        if self.thickness >= self.radius:
            raise InvalidParameterError(f"invalid thickness = {self.thickness!r}: must be < "
                                        f"radius = {self.radius!r} m (a shell)")


def mode_stiffness(lam: Any, n: Any, radius: float, thickness: float, young_modulus: float,
                   nu: float) -> np.ndarray:
    """The 3 × 3 Sanders–Koiter stiffness K (Pa/m², symmetric) of the harmonic
    (u, v, w) = (U sin λx cos nθ, V cos λx sin nθ, W cos λx cos nθ), ``lam`` = λ (rad/m, > 0)
    and ``n`` ≥ 0 broadcast together: K (U, V, W) = (q_x, q_θ, q_r), the load's amplitudes
    (Pa; q_r outward) of the same pattern. For n = 0 (no V) the V row is the identity."""
    R = check_positive("radius", radius)
    t = check_positive("thickness", thickness)
    E = check_positive("young_modulus", young_modulus)
    nu = check_range("nu", nu, -1.0, 0.5)
    lam, n = np.broadcast_arrays(np.asarray(lam, float), np.asarray(n, float))
    z = np.zeros(lam.shape)
    C, D = E * t / (1.0 - nu * nu), E * t**3 / (12.0 * (1.0 - nu * nu))
    ex = np.stack([lam, z, z], -1)
    et = np.stack([z, n / R, z + 1.0 / R], -1)
    g = np.stack([-n / R, -lam, z], -1)
    kx = np.stack([z, z, lam * lam], -1)
    kt = np.stack([z, n / R**2, n * n / R**2], -1)
    tw = np.stack([n / (4.0 * R * R), -3.0 * lam / (4.0 * R), -lam * n / R], -1)

    def o(a: np.ndarray, b: np.ndarray) -> np.ndarray:
        return a[..., :, None] * b[..., None, :]

    K = (C * (o(ex, ex) + o(et, et) + nu * (o(ex, et) + o(et, ex)) + 0.5 * (1.0 - nu) * o(g, g))
         + D * (o(kx, kx) + o(kt, kt) + nu * (o(kx, kt) + o(kt, kx))
                + 2.0 * (1.0 - nu) * o(tw, tw)))
    n0 = n == 0
    K[..., 1, :] = np.where(n0[..., None], 0.0, K[..., 1, :])
    K[..., :, 1] = np.where(n0[..., None], 0.0, K[..., :, 1])
    K[..., 1, 1] = np.where(n0, 1.0, K[..., 1, 1])
    return K


def layer_correction(s: Any, nu: float) -> dict[str, np.ndarray]:
    """The thick-plate correction of a surface-load harmonic of k t = ``s`` (module
    docstring), per unit pressure: ``loaded_sum``, ``loaded_diff`` (σ_r + σ_θ and the J2
    part σ_r − σ_θ on the loaded face: the elastic layer minus the thin plate minus the
    half-space), ``far_sum``, ``far_diff`` (the other face: layer minus thin plate).
    Dimensionless; exact series below s = 0.01, 0 above s = 300."""
    s = np.asarray(s, float)
    nu = check_range("nu", nu, -1.0, 0.5)
    if np.any(~np.isfinite(s)) or np.any(s < 0):
        raise InvalidParameterError("invalid s: must be finite and >= 0 (k t)")
    small, large = s < 0.01, s > 300.0
    x = np.where(small | large, 1.0, s)
    den = np.sinh(x) ** 2 - x * x
    # 3/s² − s²/(sinh² s − s²) and s sinh s/(sinh² s − s²) − 3/s², with their series at s → 0
    # (2/5 − 13 s²/525, 1/10 − 71 s²/4200)
    inv = 3.0 / np.where(large, s, 1.0) ** 2
    a = np.where(small, 0.4 - 13.0 / 525.0 * s * s,
                 np.where(large, inv, 3.0 / x**2 - x * x / den))
    b = np.where(small, 0.1 - 71.0 / 4200.0 * s * s,
                 np.where(large, -inv, x * np.sinh(x) / den - 3.0 / x**2))
    return {"loaded_sum": 2.0 * (1.0 + nu) * a, "loaded_diff": -2.0 * (1.0 - nu) * a,
            "far_sum": 2.0 * (1.0 + nu) * b, "far_diff": -2.0 * (1.0 - nu) * b}


def _sinc(x: np.ndarray) -> np.ndarray:
    return np.where(np.abs(x) < 1e-8, 1.0, np.sin(x) / np.where(np.abs(x) < 1e-8, 1.0, x))


def _jinc(x: np.ndarray) -> np.ndarray:
    """2 J1(x)/x (1 at x = 0)."""
    return np.where(np.abs(x) < 1e-8, 1.0, 2.0 * j1(x) / np.where(np.abs(x) < 1e-8, 1.0, x))


def hertz_disc_spectrum(kx: Any, ky: Any, radius: float) -> np.ndarray:
    """Fourier transform (normalised to 1 at k = 0) of the Hertz pressure
    p ∝ √(1 − r²/c²) on a circle of ``radius`` c (m): 3(sin x − x cos x)/x³, x = k c;
    ``kx``, ``ky``: wavenumbers along and around the axis, rad/m."""
    c = check_range("radius", radius, 0.0, math.inf, lo_open=False)
    x = np.hypot(np.asarray(kx, float), np.asarray(ky, float)) * c
    xs = np.where(x < 1e-3, 1.0, x)
    return np.where(x < 1e-3, 1.0 - x * x / 10.0, 3.0 * (np.sin(xs) - xs * np.cos(xs)) / xs**3)


def uniform_disc_spectrum(kx: Any, ky: Any, radius: float) -> np.ndarray:
    """The same for a uniform pressure on a circle of ``radius`` (m): 2 J1(k c)/(k c)."""
    c = check_range("radius", radius, 0.0, math.inf, lo_open=False)
    return _jinc(np.hypot(np.asarray(kx, float), np.asarray(ky, float)) * c)


def rectangle_spectrum(kx: Any, ky: Any, half_x: float, half_y: float) -> np.ndarray:
    """The same for a uniform pressure on |x| < ``half_x``, |s| < ``half_y`` (m, along and
    around the axis): sinc(kx h_x) sinc(ky h_y)."""
    hx = check_range("half_x", half_x, 0.0, math.inf, lo_open=False)
    hy = check_range("half_y", half_y, 0.0, math.inf, lo_open=False)
    return _sinc(np.asarray(kx, float) * hx) * _sinc(np.asarray(ky, float) * hy)


def line_spectrum(kx: Any, ky: Any, length: float, half_width: float = 0.0) -> np.ndarray:
    """The same for a line contact along the axis, ``length`` L (m) long, uniform along it,
    with the Hertz strip p ∝ √(1 − s²/b²) of ``half_width`` b (m) across:
    sinc(kx L/2) · 2 J1(ky b)/(ky b)."""
    L = check_positive("length", length)
    b = check_range("half_width", half_width, 0.0, math.inf, lo_open=False)
    return _sinc(np.asarray(kx, float) * 0.5 * L) * _jinc(np.asarray(ky, float) * b)


@lru_cache(maxsize=16)
def _unit_modes(shell: CylinderShell, k_max: float, curved: bool, n_max: int | None = None,
                m_max: int | None = None) -> dict[Any, Any]:
    """The harmonics up to k ≤ ``k_max`` (rad/m; or ``n_max`` around, the first ``m_max``
    along the axis) of ``shell`` and the surface stresses
    (Pa) of each per unit load amplitude (Pa): radial inward ``r``, circumferential ``th``
    (n = 1 body force), and the thick-plate correction ``layer`` of a surface pressure;
    keyed by surface ("outer", "inner") and component ("xx", "tt", "xt": xx and tt of the
    cos λx cos nθ pattern, xt of sin λx sin nθ)."""
    R, t, E, nu, Lc = shell.radius, shell.thickness, shell.young_modulus, shell.nu, shell.length
    n_max = int(math.ceil(k_max * R)) if n_max is None else n_max
    m_max = int(math.ceil(k_max * Lc / (2.0 * math.pi))) if m_max is None else m_max
    lam = (2.0 * np.arange(m_max) + 1.0) * math.pi / Lc
    n = np.arange(n_max + 1)
    L, N = np.meshgrid(lam, n.astype(float), indexing="ij")
    ky = N / R
    K = mode_stiffness(L, N, R, t, E, nu)
    Kinv = np.linalg.inv(K)
    f, G = E / (1.0 - nu * nu), E / (2.0 * (1.0 + nu))
    ki, ko = curved_beam_factors(R, t) if curved else (1.0, 1.0)
    k = np.hypot(L, ky)
    lay = layer_correction(k * t, nu)
    c2 = (L * L - ky * ky) / (k * k)
    sxy = L * ky / (k * k)
    out: dict[Any, Any] = {"lam": lam, "n": n}
    for name, col, sign in (("r", 2, -1.0), ("th", 1, 1.0)):
        U, V, W = (sign * Kinv[..., j, col] for j in range(3))
        ex, et = L * U, ky * V + W / R
        kx_, kt = L * L * W, ky / R * V + ky * ky * W
        g, tw = -ky * U - L * V, ky / (4.0 * R) * U - 0.75 * L / R * V - L * ky * W
        for surf, z, kb in (("outer", 0.5 * t, ko), ("inner", -0.5 * t, ki)):
            out[(name, surf)] = {
                "xx": f * (ex + z * kx_ + nu * (et + z * kt)),
                "tt": f * (et + nu * ex) + kb * f * z * (kt + nu * kx_),
                "xt": G * (g + 2.0 * z * tw)}
    for surf, s_key, d_key, kb in (("outer", "loaded_sum", "loaded_diff", ko),
                                   ("inner", "far_sum", "far_diff", ki)):
        # a correction of the bending stresses: the hoop part takes the curved-bar factor
        S, Dd = lay[s_key], lay[d_key]
        out[("layer", surf)] = {"xx": 0.5 * (S - Dd * c2), "tt": kb * 0.5 * (S + Dd * c2),
                                "xt": Dd * sxy}
    return out


@dataclass(frozen=True)
class CylinderLoadField:
    """The surface stresses of one load on a :class:`CylinderShell` as harmonic amplitudes
    (:func:`cylinder_load_field`); :meth:`surface_stresses` sums them."""

    shell: CylinderShell
    lam: np.ndarray
    n: np.ndarray
    coefficients: dict[str, dict[str, np.ndarray]]

    def surface_stresses(self, x: Any, theta: Any, surface: str = "inner",
                         grid: bool = False) -> dict[str, np.ndarray]:
        """Stresses (Pa) on the ``surface`` ("outer": the loaded side, "inner") at axial
        positions ``x`` (m from the load's centre) and angles ``theta`` (rad from it): keys
        ``xx`` (axial), ``tt`` (hoop), ``xt`` (shear), ``s1`` (largest principal). Pointwise
        (x and theta broadcast) or, with ``grid``, on the grid x × theta (shape
        (len(x), len(theta)))."""
        if surface not in ("outer", "inner"):
            raise InvalidParameterError(f"invalid surface = {surface!r}: must be 'outer' or "
                                        "'inner'")
        c = self.coefficients[surface]
        x, th = np.asarray(x, float), np.asarray(theta, float)
        if grid:
            return _grid_sum(_grid_trig(x.ravel(), th.ravel(), self.lam, self.n), c)
        else:
            x, th = np.broadcast_arrays(x, th)
            cx = np.cos(x[..., None] * self.lam)
            sx = np.sin(x[..., None] * self.lam)
            ct = np.cos(th[..., None] * self.n)
            st = np.sin(th[..., None] * self.n)
            out = {key: np.einsum("...m,mn,...n->...", a, c[key], b)
                   for key, a, b in (("xx", cx, ct), ("tt", cx, ct), ("xt", sx, st))}
        out["s1"] = _s1(out["xx"], out["tt"], out["xt"])
        return out


def _grid_trig(x: np.ndarray, th: np.ndarray, lam: np.ndarray,
               n: np.ndarray) -> tuple[np.ndarray, ...]:
    """cos λx, sin λx (len(x) × modes) and cos nθ, sin nθ (modes × len(θ))."""
    ax, at = np.outer(x, lam), np.outer(n, th)
    return np.cos(ax), np.sin(ax), np.cos(at), np.sin(at)


def _grid_sum(trig: tuple[np.ndarray, ...], c: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """The double sums of the amplitudes ``c`` on a grid (:func:`_grid_trig`), Pa. By einsum,
    not BLAS: a multi-threaded BLAS on a busy machine made these small products 100 × slower."""
    cx, sx, ct, st = trig

    def two(a: np.ndarray, m: np.ndarray, b: np.ndarray) -> np.ndarray:
        return np.einsum("in,nj->ij", np.einsum("im,mn->in", a, m), b)

    out = {"xx": two(cx, c["xx"], ct), "tt": two(cx, c["tt"], ct), "xt": two(sx, c["xt"], st)}
    out["s1"] = _s1(out["xx"], out["tt"], out["xt"])
    return out


def _s1(sxx: np.ndarray, stt: np.ndarray, sxt: np.ndarray) -> np.ndarray:
    return 0.5 * (sxx + stt) + np.sqrt(0.25 * (sxx - stt) ** 2 + sxt * sxt)


def _check_support(support: str) -> str:
    if support not in SUPPORTS:
        raise InvalidParameterError(f"invalid support = {support!r}: must be one of "
                                    f"{', '.join(map(repr, SUPPORTS))}")
    return support


def _amplitudes(shell: CylinderShell, modes: dict[Any, Any], force: float, spectra: np.ndarray,
                support: str, free_length: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(q_in, q_in of the body force, q_θ of the body force), Pa, per harmonic: the contact
    load's inward amplitude (``spectra``: its spectrum on the harmonics) and the d'Alembert
    force's (support "inertia")."""
    R, Lc = shell.radius, shell.length
    lam, n = modes["lam"], modes["n"]
    q = force * spectra / (0.5 * Lc * math.pi * R * np.where(n == 0, 2.0, 1.0))[None, :]
    if support == "opposite":
        q = q * (1.0 + (-1.0) ** n)[None, :]
    body_r = np.zeros_like(q)
    body_t = np.zeros_like(q)
    if support == "inertia":
        # uniform over the free tube, +y (away from the load): q_r = b cos θ, q_θ = −b sin θ
        b_m = force * _sinc(0.5 * lam * free_length) / (math.pi * R * Lc)
        if n.size > 1:
            body_r[:, 1] = -b_m          # inward amplitude: the body force pushes outward at θ=0
            body_t[:, 1] = -b_m
    return q, body_r, body_t


def cylinder_load_field(shell: CylinderShell, force: float, spectrum: Spectrum, *,
                        support: str = "inertia", free_length: float | None = None,
                        thick: bool = True, curved: bool = True, k_max: float | None = None,
                        n_max: int | None = None,
                        m_max: int | None = None) -> CylinderLoadField:
    """The surface field of a radial inward ``force`` (N) at the middle of ``shell``, spread
    as ``spectrum`` (a function of the wavenumbers along and around the axis, rad/m, → its
    normalised transform: :func:`hertz_disc_spectrum`, :func:`line_spectrum`, …; the load
    sits at x = 0, θ = 0).

    Args:
        support: ``"inertia"``, ``"opposite"`` or ``"ends"`` (module docstring).
        free_length: the free tube's length for ``"inertia"``, m (≤ shell.length; default
            shell.length).
        thick: add the thick-plate (elastic layer) correction of the contact load.
        curved: Winkler–Bach factors on the hoop bending stress.
        k_max: the series' cut-off wavenumber, rad/m (default 24/t; without ``thick`` the
            series converges only like the load's spectrum: give ≫ 1/(load size)).
        n_max, m_max: the number of harmonics around (n = 0 … n_max) and along the axis
            (the first m_max odd ones), instead of those of ``k_max``.
    """
    _check_support(support)
    P = check_positive("force", force)
    lf = shell.length if free_length is None else check_range(
        "free_length", free_length, 0.0, shell.length, hi_open=False)
    kk = K_T_MAX / shell.thickness if k_max is None else check_positive("k_max", k_max)
    modes = _unit_modes(shell, float(kk), bool(curved),
                        None if n_max is None else check_count("n_max", n_max),
                        None if m_max is None else check_count("m_max", m_max, 1))
    L, N = np.meshgrid(modes["lam"], modes["n"] / shell.radius, indexing="ij")
    q, body_r, body_t = _amplitudes(shell, modes, P, np.asarray(spectrum(L, N), float),
                                    support, lf)
    coeffs: dict[str, dict[str, np.ndarray]] = {}
    for surf in ("outer", "inner"):
        r, th, lay = modes[("r", surf)], modes[("th", surf)], modes[("layer", surf)]
        coeffs[surf] = {key: r[key] * (q + body_r) + th[key] * body_t
                        + (lay[key] * q if thick else 0.0) for key in ("xx", "tt", "xt")}
    return CylinderLoadField(shell, modes["lam"], modes["n"], coeffs)


def _surface_grid(shell: CylinderShell, free_length: float,
                  near: float) -> tuple[np.ndarray, np.ndarray]:
    """x ∈ [0, free_length/2] and θ ∈ [0, π] (a quarter of the tube: the fields here are
    symmetric in both), fine (t/12) within ``near`` of the load (the effective areas change
    by < 0.1 % on a grid 3 × finer)."""
    t, R = shell.thickness, shell.radius
    half = 0.5 * free_length
    x = np.unique(np.concatenate([np.linspace(0.0, min(near, half), int(near / (t / 12)) + 1),
                                  np.linspace(min(near, half), half, 50)]))
    th_near = min(near / R, math.pi)
    th = np.unique(np.concatenate([np.linspace(0.0, th_near, int(near / (t / 12)) + 1),
                                   np.linspace(th_near, math.pi, 70)]))
    return x, th


def _peak_area(field: np.ndarray, x: np.ndarray, th: np.ndarray, surface_radius: float,
               m: float) -> tuple[float, float, tuple[int, int]]:
    """Peak σ1 (≥ 0) of a quarter-tube ``field`` on the grid, its effective area (m², the
    whole tube: 4 quarters) and the peak's grid index."""
    k = np.unravel_index(int(np.argmax(field)), field.shape)
    peak = float(field[k])
    if peak <= 0:
        return 0.0, 0.0, (int(k[0]), int(k[1]))
    w = np.maximum(field / peak, 0.0) ** m
    area = 4.0 * surface_radius * np.trapezoid(np.trapezoid(w, th, axis=1), x)
    return peak, float(area), (int(k[0]), int(k[1]))


@lru_cache(maxsize=16)
def point_load_table(radius: float, thickness: float, nu: float, free_length: float,
                     m_inner: float, m_outer: float, curved: bool = True) -> dict[str, Any]:
    """The Hertz circle of radius c on a free tube (mid-surface ``radius``, ``thickness`` and
    ``free_length`` in m, Poisson ratio ``nu``; support "inertia", thick-plate correction),
    on :data:`C_OVER_T`: keys ``c_over_t``, ``inner_peak`` (σ1 t²/F), ``inner_area`` (A/t²,
    for ``m_inner``), ``rim_axial`` and ``rim_hoop`` (outer σ_xx at x = ρ and σ_θθ at arc ρ,
    σ t²/F, shape (c, :data:`RHO`)), ``ring_peak`` (the outer field's largest tension,
    σ t²/F, ≥ 0) and ``ring_area`` (its effective area / t², for ``m_outer``)."""
    t = check_positive("thickness", thickness)
    lf = check_positive("free_length", free_length)
    m_inner, m_outer = check_positive("m_inner", m_inner), check_positive("m_outer", m_outer)
    shell = CylinderShell(radius, t, 1.0, nu, 2.0 * lf)
    x, th = _surface_grid(shell, lf, 4.0 * t)
    r_in, r_out = shell.radius - 0.5 * t, shell.radius + 0.5 * t
    keys = ("inner_peak", "inner_area", "ring_peak", "ring_area")
    out: dict[str, Any] = {k: np.empty(C_OVER_T.size) for k in keys}
    out["c_over_t"] = C_OVER_T
    out["rim_axial"] = np.empty((C_OVER_T.size, RHO.size))
    out["rim_hoop"] = np.empty((C_OVER_T.size, RHO.size))
    trig = None
    for i, ct in enumerate(C_OVER_T):
        fld = cylinder_load_field(shell, 1.0, partial(hertz_disc_spectrum, radius=ct * t),
                                  support="inertia", free_length=lf, curved=curved)
        trig = _grid_trig(x, th, fld.lam, fld.n) if trig is None else trig
        inner = _grid_sum(trig, fld.coefficients["inner"])["s1"]
        outer = _grid_sum(trig, fld.coefficients["outer"])["s1"]
        p, a, _ = _peak_area(inner, x, th, r_in, m_inner)
        out["inner_peak"][i], out["inner_area"][i] = p * t * t, a / t**2
        p, a, _ = _peak_area(outer, x, th, r_out, m_outer)
        out["ring_peak"][i], out["ring_area"][i] = p * t * t, a / t**2
        rho = RHO * ct * t
        out["rim_axial"][i] = fld.surface_stresses(rho, 0.0, "outer")["xx"] * t * t
        out["rim_hoop"][i] = fld.surface_stresses(0.0, rho / r_out, "outer")["tt"] * t * t
    return out


@lru_cache(maxsize=64)
def line_load_profile(radius: float, thickness: float, nu: float, contact_length: float,
                      support: str, free_length: float, m_inner: float, m_outer: float,
                      curved: bool = True) -> dict[str, float]:
    """A line contact of ``contact_length`` (m) along a tube (mid-surface ``radius``,
    ``thickness``, ``free_length`` in m; ``support`` "opposite" or "inertia"), zero width
    (a Hertz strip is far narrower than the wall), thick-plate correction, per unit force:
    ``inner_peak`` (σ1 t²/F), ``inner_area`` (m², ``m_inner``), ``outer_load`` (the outer hoop
    stress at the load's centre, σ t²/F), ``outer_peak`` (the outer field's largest tension,
    σ t²/F, ≥ 0) and ``outer_area`` (m², ``m_outer``)."""
    t = check_positive("thickness", thickness)
    lf = check_positive("free_length", free_length)
    L = check_range("contact_length", contact_length, 0.0, lf, hi_open=False)
    if _check_support(support) == "ends":
        raise InvalidParameterError("invalid support = 'ends': a line contact is held by "
                                    "'opposite' or 'inertia'")
    shell = CylinderShell(radius, t, 1.0, nu, 2.0 * lf)
    fld = cylinder_load_field(shell, 1.0, lambda kx, ky: line_spectrum(kx, ky, L),
                              support=support, free_length=lf, curved=curved)
    x, th = _surface_grid(shell, lf, 4.0 * t)
    x = np.unique(np.concatenate([x, np.linspace(0.0, 0.5 * min(L + 8.0 * t, lf), 161)]))
    r_in, r_out = shell.radius - 0.5 * t, shell.radius + 0.5 * t
    inner = fld.surface_stresses(x, th, "inner", grid=True)["s1"]
    outer = fld.surface_stresses(x, th, "outer", grid=True)["s1"]
    pi_, ai, _ = _peak_area(inner, x, th, r_in, check_positive("m_inner", m_inner))
    po, ao, _ = _peak_area(outer, x, th, r_out, check_positive("m_outer", m_outer))
    load = float(fld.surface_stresses(0.0, 0.0, "outer")["tt"])
    return {"inner_peak": pi_ * t * t, "inner_area": ai, "outer_load": load * t * t,
            "outer_peak": po * t * t, "outer_area": ao}
