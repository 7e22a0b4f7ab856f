"""Weibull weakest-link failure probability of a stressed glass surface (SI units: Pa, m²).

Glass fails from surface flaws. With a two-parameter Weibull flaw population on the surface,
the probability that a surface carrying the tensile stress field σ(x) breaks is

    P = 1 − exp(−R),    R = Σ_k (A_k / A_0) (σ_k / σ_0)^m          (tensile σ_k only)

over surface elements k of area A_k (Weibull 1951; ASTM C1239 and C1683 for the surface-flaw
form and its size scaling). m is the Weibull modulus, σ_0 the characteristic strength (the
stress at which a uniformly stressed surface of the reference area A_0 breaks with probability
1 − 1/e ≈ 63.2 %). Compressive (negative) stresses contribute nothing.

With the in-plane principal stresses (σ_1, σ_2) of each element, the principle of independent
action (PIA; Barnett et al. 1967, as used in NASA CARES/Life, Nemeth et al. 2003) treats each
tensile principal stress as an independent flaw-loading mode:

    R = Σ_k (A_k / A_0) [ ⟨σ_1k⟩^m + ⟨σ_2k⟩^m ] / σ_0^m,    ⟨x⟩ = max(x, 0).

The maximum-principal-stress criterion (``criterion="max_principal"``) keeps only the largest.
R is evaluated in log space (log-sum-exp) and P = −expm1(−R), so P stays accurate down to
1e-300 and saturates at 1 without overflow warnings.
"""
from __future__ import annotations

import math
from typing import Optional, Tuple

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.special import logsumexp

from demfem.errors import InvalidParameterError, check_positive, check_range
from demfem.risk._validate import RiskShapeError, as_array, check_same_shape

__all__ = [
    "CRITERIA",
    "effective_area",
    "failure_probability",
    "risk_of_rupture",
    "scale_strength",
    "weibull_strength_at_area",
]

#: Multiaxial criteria understood by :func:`failure_probability`.
CRITERIA = ("pia", "max_principal")

_Components = Tuple[NDArray[np.float64], NDArray[np.float64]]


def _tensile_components(
    stress: Optional[ArrayLike],
    area: ArrayLike,
    principal_stresses: Optional[ArrayLike],
    criterion: str,
) -> _Components:
    """Flattened (σ, A) pairs of the tensile stress components that enter the risk integral."""
    if criterion not in CRITERIA:
        raise InvalidParameterError(
            f"invalid criterion = {criterion!r}: must be one of {', '.join(map(repr, CRITERIA))}"
        )
    a = as_array("area", area, 0.0, math.inf, ndim=1, unit="m²")
    if principal_stresses is None:
        if stress is None:
            raise InvalidParameterError(
                "invalid stress = None: give stress (N,) or principal_stresses (N, 2), in Pa"
            )
        s = as_array("stress", stress, ndim=1, unit="Pa")
        check_same_shape(area=a, stress=s)
        comps, areas = s, a
    else:
        p = as_array("principal_stresses", principal_stresses, ndim=2, unit="Pa")
        if p.shape[1] not in (2, 3):
            raise RiskShapeError(
                f"invalid principal_stresses: shape {p.shape}, must be (N, 2) in-plane "
                "principal stresses (or (N, 3))"
            )
        if p.shape[0] != a.shape[0]:
            raise RiskShapeError(
                f"invalid principal_stresses: {p.shape[0]} rows do not match area shape {a.shape}"
            )
        if stress is not None:
            s = as_array("stress", stress, ndim=1, unit="Pa")
            check_same_shape(area=a, stress=s)
            smax = p.max(axis=1) if p.shape[0] else s
            if not np.allclose(s, smax, rtol=1e-9, atol=0.0):
                raise InvalidParameterError(
                    "invalid stress: must equal the largest principal stress of each row of "
                    "principal_stresses (or be None when principal_stresses is given)"
                )
        if criterion == "pia":
            comps = p.ravel()
            areas = np.repeat(a, p.shape[1])
        else:
            comps = p.max(axis=1) if p.shape[0] else np.zeros(0)
            areas = a
    tension = comps > 0.0
    return comps[tension], areas[tension]


def _log_risk(
    comps: NDArray[np.float64],
    areas: NDArray[np.float64],
    m: float,
    sigma0: float,
    a0: float,
) -> float:
    """log R of the tensile components (−inf when there are none)."""
    if comps.size == 0:
        return -math.inf
    terms = np.log(areas / a0) + m * (np.log(comps) - math.log(sigma0))
    return float(logsumexp(terms))


def _check_weibull(m: float, sigma0: float, a0: float) -> Tuple[float, float, float]:
    return (
        check_positive("weibull_modulus", m),
        check_positive("characteristic_strength", sigma0),
        check_positive("reference_area", a0),
    )


def risk_of_rupture(
    stress: Optional[ArrayLike],
    area: ArrayLike,
    weibull_modulus: float,
    characteristic_strength: float,
    reference_area: float,
    *,
    principal_stresses: Optional[ArrayLike] = None,
    criterion: str = "pia",
) -> float:
    """The risk-of-rupture integral R = −ln(1 − P) (dimensionless, ≥ 0).

    Same arguments as :func:`failure_probability`. Risks of independent loadings add.
    """
    m, sigma0, a0 = _check_weibull(weibull_modulus, characteristic_strength, reference_area)
    comps, areas = _tensile_components(stress, area, principal_stresses, criterion)
    log_r = _log_risk(comps, areas, m, sigma0, a0)
    return math.exp(log_r) if log_r < 709.0 else math.inf


def failure_probability(
    stress: Optional[ArrayLike],
    area: ArrayLike,
    weibull_modulus: float,
    characteristic_strength: float,
    reference_area: float,
    *,
    principal_stresses: Optional[ArrayLike] = None,
    criterion: str = "pia",
) -> float:
    """Weibull weakest-link probability that a stressed surface breaks, in [0, 1].

    Parameters
    ----------
    stress:
        Maximum principal stress of each surface element, Pa, shape (N,); finite; compressive
        (≤ 0) values contribute nothing. May be None when ``principal_stresses`` is given; if both
        are given, ``stress`` must equal the row maxima of ``principal_stresses``.
    area:
        Element areas, m², shape (N,); finite and > 0.
    weibull_modulus:
        m, dimensionless; finite and > 0.
    characteristic_strength:
        σ_0, Pa; finite and > 0 (the strength at 63.2 % failure probability of the reference
        area under uniform stress).
    reference_area:
        A_0, m²; finite and > 0: the area to which σ_0 refers.
    principal_stresses:
        In-plane principal stresses of each element, Pa, shape (N, 2) (or (N, 3)).
    criterion:
        ``"pia"``: principle of independent action, each tensile principal stress contributes
        (A_k/A_0)(σ_ik/σ_0)^m; ``"max_principal"``: only the largest principal stress.
        Used only with ``principal_stresses``.

    Returns
    -------
    float
        P = 1 − exp(−Σ_k (A_k/A_0)(σ_k/σ_0)^m), tension only.

    Raises
    ------
    demfem.errors.InvalidParameterError
        m ≤ 0, σ_0 or A_0 ≤ 0, areas ≤ 0, NaN or infinite values, mismatched shapes, unknown
        criterion; the message names the field and the allowed range.
    """
    r = risk_of_rupture(
        stress,
        area,
        weibull_modulus,
        characteristic_strength,
        reference_area,
        principal_stresses=principal_stresses,
        criterion=criterion,
    )
    return float(-math.expm1(-r)) if math.isfinite(r) else 1.0


def effective_area(
    stress: Optional[ArrayLike],
    area: ArrayLike,
    weibull_modulus: float,
    *,
    principal_stresses: Optional[ArrayLike] = None,
    criterion: str = "pia",
) -> float:
    """Effective area A_eff = Σ_k A_k (σ_k / σ_max)^m over the tensile components, m².

    ASTM C1683 style: the area of a uniformly stressed surface at the peak stress σ_max that has
    the same failure probability, P = 1 − exp(−(A_eff/A_0)(σ_max/σ_0)^m). With
    ``principal_stresses`` and ``"pia"`` both principal stresses of each element count and
    σ_max is the largest principal stress anywhere. Returns 0.0 when nothing is in tension.
    Arguments as in :func:`failure_probability`.
    """
    m = check_positive("weibull_modulus", weibull_modulus)
    comps, areas = _tensile_components(stress, area, principal_stresses, criterion)
    if comps.size == 0:
        return 0.0
    smax = float(comps.max())
    return float(np.sum(areas * (comps / smax) ** m))


def weibull_strength_at_area(
    area: float,
    weibull_modulus: float,
    characteristic_strength: float,
    reference_area: float,
    probability: float = 1.0 - math.exp(-1.0),
) -> float:
    """Uniform tensile stress (Pa) at which a surface of ``area`` (m²) breaks with ``probability``.

    σ = σ_0 (A_0 / A)^{1/m} [−ln(1 − P)]^{1/m}; with the default P = 1 − 1/e this is the
    characteristic strength scaled to ``area``. ``area`` may be an effective area.
    ``probability`` must be in (0, 1).
    """
    m, sigma0, a0 = _check_weibull(weibull_modulus, characteristic_strength, reference_area)
    a = check_positive("area", area)
    p = check_range("probability", probability, 0.0, 1.0)
    return float(sigma0 * (a0 / a) ** (1.0 / m) * (-math.log1p(-p)) ** (1.0 / m))


def scale_strength(
    strength: float, area_from: float, area_to: float, weibull_modulus: float
) -> float:
    """Size scaling of a strength (Pa) between effective areas (m²), ASTM C1683:
    σ_to = σ_from (A_from / A_to)^{1/m}, at equal failure probability."""
    s = check_positive("strength", strength)
    a1 = check_positive("area_from", area_from)
    a2 = check_positive("area_to", area_to)
    m = check_positive("weibull_modulus", weibull_modulus)
    return float(s * (a1 / a2) ** (1.0 / m))
