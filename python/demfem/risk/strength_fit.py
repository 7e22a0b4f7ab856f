"""Weibull parameters of a user's own glass from strength tests (ASTM C1239, C1683; SI units).

**Fit (ASTM C1239).** N specimens, r of which failed from the flaw population of interest at
their nominal failure stress σ_i; the other N − r are right-censored at the stress σ_j they
reached (they broke from another flaw population, e.g. at the load ring or the edge, or did
not break at the test's maximum load). The two-parameter Weibull log-likelihood with survival
terms for the censored specimens,

    ln L = Σ_failed [ln m − m ln σ_θ + (m−1) ln σ_i] − Σ_all (σ_i/σ_θ)^m,

is maximal where (C1239 eqs. for censored samples)

    Σ_all σ_i^m ln σ_i / Σ_all σ_i^m − (1/r) Σ_failed ln σ_i − 1/m = 0,
    σ_θ = [(1/r) Σ_all σ_i^m]^{1/m}.

The left side is strictly increasing in m; it is solved by a bracketed Newton iteration, in
log space (exact for strengths of any magnitude).

**Unbiasing factor and 90 % bounds.** m̂/m and m̂ ln(σ̂_θ/σ_θ) are pivotal (their distribution
depends only on N for a complete sample); C1239 tabulates the unbiasing factor b(N) = 1/E[m̂/m]
and the percentiles q and t of these pivots, computed by Monte Carlo. This module computes
them the same way at fit time (``n_simulations`` samples, seeded: the same data give the same
numbers; cached per N for complete samples): m̂_unbiased = b m̂, and with confidence γ

    m ∈ [m̂ / q_{(1+γ)/2},  m̂ / q_{(1−γ)/2}],
    σ_θ ∈ [σ̂_θ exp(−t_{(1+γ)/2}/m̂),  σ̂_θ exp(−t_{(1−γ)/2}/m̂)].

With censored specimens the pivots are only approximately pivotal and C1239 gives no tables:
they come from a parametric bootstrap at the fitted (m̂, σ̂_θ) with each censored specimen
censored at its own recorded stress (fixed censoring), a documented extension.

**Size scaling (ASTM C1683).** σ_θ is the characteristic nominal stress of the test specimen;
the material's scale on a reference area A_0 is σ_0 = σ_θ (A_eff/A_0)^{1/m}, with A_eff the
test's effective area for that m (:mod:`demfem.risk.specimen_area`) and m the unbiased
estimate by default.

Files: :mod:`demfem.risk.strength_file` (the CSV of the tests, the JSON strength file that
``demfem assess --strength`` reads, ``demfem strength-fit``); see ``docs/strength.md``.
"""
from __future__ import annotations

import functools
import math
from dataclasses import asdict, dataclass
from typing import Any, Dict, Mapping, Optional, Tuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from demfem.errors import InvalidParameterError, check_count, check_positive, check_range
from demfem.risk.defaults import REFERENCE_AREA
from demfem.risk.specimen_area import SURFACES, TESTS, effective_area_of_test
from demfem.risk.surface import SurfaceStrength
from demfem.risk.weibull import CRITERIA

__all__ = [
    "DEFAULT_SEED",
    "DEFAULT_SIMULATIONS",
    "StrengthFit",
    "fit_strength",
    "pivot_samples",
    "unbiasing_factor",
    "weibull_mle",
]

#: Monte Carlo samples of the pivots (C1239's tables rest on Monte Carlo of this size).
DEFAULT_SIMULATIONS = 20000
#: Seed of the pivot simulation: the same data always give the same bounds.
DEFAULT_SEED = 1239
#: Which m converts σ_θ to σ_0: the unbiased (default) or the maximum-likelihood estimate.
MODULUS_CHOICES = ("unbiased", "ml")


# --- maximum likelihood ------------------------------------------------------------------------

def _ml_rows(y: NDArray[np.float64], failed: NDArray[np.bool_]
             ) -> Tuple[NDArray[np.float64], NDArray[np.float64]]:
    """ML (m̂, ln σ̂_θ) of each row of log strengths ``y`` (R, N); ``failed`` (R, N) marks the
    uncensored specimens (≥ 2 per row). Rows whose failures leave m unbounded give inf."""
    shift = y.max(axis=1, keepdims=True)
    z = y - shift                               # ≤ 0: σ^m / max σ^m never overflows
    r = failed.sum(axis=1)
    zbar = np.where(failed, z, 0.0).sum(axis=1) / r
    unbounded = ~(zbar < -1e-14)                # g(∞) = max z − mean z_failed ≤ 0

    def g_dg(m: NDArray[np.float64]) -> Tuple[NDArray[np.float64], NDArray[np.float64]]:
        w = np.exp(m[:, None] * z)
        s0 = w.sum(axis=1)
        mean = (w * z).sum(axis=1) / s0
        var = (w * z * z).sum(axis=1) / s0 - mean * mean
        return mean - 1.0 / m - zbar, np.maximum(var, 0.0) + 1.0 / (m * m)

    spread = np.sqrt(np.maximum(np.var(z, axis=1), 1e-300))
    m = np.where(unbounded, 1.0, 1.28 / spread)  # MIL-HDBK-17 start
    lo, hi = m.copy(), m.copy()
    g_lo, _ = g_dg(lo)
    g_hi = g_lo.copy()
    for _ in range(200):                        # bracket the root: g(lo) < 0 < g(hi)
        up = (g_hi <= 0.0) & ~unbounded
        down = g_lo >= 0.0
        if not (up.any() or down.any()):
            break
        hi = np.where(up, hi * 2.0, hi)
        lo = np.where(down, lo * 0.5, lo)
        g_lo, _ = g_dg(lo)
        g_hi, _ = g_dg(hi)
    hi = np.where(unbounded, 2.0, hi)
    lo = np.where(unbounded, 1.0, lo)
    x = np.clip(m, lo, hi)
    for _ in range(200):                         # safeguarded Newton
        g, dg = g_dg(x)
        lo = np.where(g < 0.0, x, lo)
        hi = np.where(g > 0.0, x, hi)
        newton = x - g / dg
        step = np.where((newton > lo) & (newton < hi), newton, 0.5 * (lo + hi))
        done = (np.abs(step - x) <= 1e-14 * x) | (g == 0.0)
        x = np.where(done, x, step)
        if np.all(done | unbounded):
            break
    w = np.exp(x[:, None] * z)
    log_theta = shift[:, 0] + np.log(w.sum(axis=1) / r) / x
    return np.where(unbounded, np.inf, x), np.where(unbounded, np.nan, log_theta)


def _check_data(strength: ArrayLike, censored: Optional[ArrayLike]
                ) -> Tuple[NDArray[np.float64], NDArray[np.bool_]]:
    try:
        s = np.asarray(strength, dtype=np.float64)
    except (TypeError, ValueError):
        raise InvalidParameterError(f"invalid strength_Pa = {strength!r}: must be an array of "
                                    "real numbers (Pa)") from None
    if s.ndim != 1:
        raise InvalidParameterError(f"invalid strength_Pa: shape {s.shape}, must be 1-D")
    bad = ~(np.isfinite(s) & (s > 0.0))
    if bad.any():
        i = int(np.argmax(bad))
        raise InvalidParameterError(f"invalid strength_Pa[{i}] = {s[i]!r}: must be finite "
                                    "and > 0 (Pa)")
    if censored is None:
        c = np.zeros(s.shape, dtype=bool)
    else:
        raw = np.asarray(censored)
        if raw.shape != s.shape:
            raise InvalidParameterError(f"invalid censored: shape {raw.shape} does not match "
                                        f"strength_Pa shape {s.shape}")
        if raw.dtype != bool and not np.all(np.isin(raw, (0, 1))):
            i = int(np.argmax(~np.isin(raw, (0, 1))))
            raise InvalidParameterError(f"invalid censored[{i}] = {raw[i]!r}: must be 0 or 1 "
                                        "(true or false)")
        c = raw.astype(bool)
    if int((~c).sum()) < 2:
        raise InvalidParameterError(f"invalid strength_Pa: {int((~c).sum())} failed "
                                    "(uncensored) specimen(s), at least 2 are needed")
    return s, c


def weibull_mle(strength: ArrayLike, censored: Optional[ArrayLike] = None
                ) -> Tuple[float, float]:
    """Maximum-likelihood Weibull modulus m̂ and characteristic strength σ̂_θ (Pa) of the
    nominal failure stresses ``strength`` (Pa, shape (N,)), ``censored`` (N,) 0/1 marking
    right-censored specimens (ASTM C1239). At least 2 uncensored specimens; raises
    :class:`~demfem.errors.InvalidParameterError` naming the field otherwise, and when the
    failed strengths are all equal (m unbounded)."""
    s, c = _check_data(strength, censored)
    m, log_theta = _ml_rows(np.log(s)[None, :], ~c[None, :])
    if not np.isfinite(m[0]):
        raise InvalidParameterError("invalid strength_Pa: the failed specimens all have the "
                                    "same strength and none censored above them: the Weibull "
                                    "modulus is unbounded")
    return float(m[0]), float(math.exp(log_theta[0]))


# --- pivots: unbiasing factor and bounds --------------------------------------------------------

@functools.lru_cache(maxsize=64)
def _complete_pivots(n: int, n_simulations: int, seed: int
                     ) -> Tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(m̂/m, m̂ ln(σ̂_θ/σ_θ)) of complete samples of size n from the standard Weibull."""
    rng = np.random.default_rng([seed, n])
    y = np.log(rng.standard_exponential((n_simulations, n)))  # ln of Weibull(m=1, σ_θ=1)
    m, log_theta = _ml_rows(y, np.ones(y.shape, dtype=bool))
    ok = np.isfinite(m)                     # (ties have probability zero; drop if any)
    m, t = m[ok], m[ok] * log_theta[ok]
    m.setflags(write=False)
    t.setflags(write=False)
    return m, t


def pivot_samples(strength: ArrayLike, censored: Optional[ArrayLike] = None, *,
                  n_simulations: int = DEFAULT_SIMULATIONS, seed: int = DEFAULT_SEED
                  ) -> Tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Monte Carlo samples of the pivots (m̂/m, m̂ ln(σ̂_θ/σ_θ)) for a data set like this one.

    Complete samples: ``n_simulations`` samples of the same size from the standard Weibull
    (exactly pivotal; cached). With censored specimens: a parametric bootstrap from the fitted
    Weibull, each censored specimen censored at its recorded stress, the others failing.
    Seeded by ``seed`` and the sample size."""
    s, c = _check_data(strength, censored)
    n_sim = check_count("n_simulations", n_simulations, 200)
    seed = check_count("seed", seed, 0)
    if not c.any():
        return _complete_pivots(s.size, n_sim, seed)
    m_hat, theta_hat = weibull_mle(s, c)
    rng = np.random.default_rng([seed, s.size, int(c.sum())])
    x = theta_hat * rng.standard_exponential((n_sim, s.size)) ** (1.0 / m_hat)
    limit = np.where(c, s, np.inf)[None, :]
    failed = x < limit
    y = np.log(np.minimum(x, limit))
    m, log_theta = _ml_rows(y, failed)
    ok = np.isfinite(m)
    return m[ok] / m_hat, m[ok] * (log_theta[ok] - math.log(theta_hat))


def unbiasing_factor(n: int, *, n_simulations: int = DEFAULT_SIMULATIONS,
                     seed: int = DEFAULT_SEED) -> float:
    """ASTM C1239 unbiasing factor b(N) = 1/E[m̂/m] of the ML Weibull modulus of a complete
    sample of ``n`` ≥ 2 specimens, by seeded Monte Carlo (C1239 tabulates it for N = 5–120:
    e.g. b(10) ≈ 0.86, b(30) ≈ 0.955)."""
    n = check_count("n", n, 2)
    m, _ = _complete_pivots(n, check_count("n_simulations", n_simulations, 200),
                            check_count("seed", seed, 0))
    return float(1.0 / np.mean(m))


# --- the fit ------------------------------------------------------------------------------

@dataclass(frozen=True)
class StrengthFit:
    """An ASTM C1239 Weibull fit of strength tests, and the scaling to the material (C1683).

    Attributes: ``m`` (ML Weibull modulus), ``m_unbiased`` (b(N) m), ``sigma_theta_Pa`` (ML
    characteristic nominal strength of the test specimen, Pa), ``bounds`` (``{"m": (lo, hi),
    "sigma_theta_Pa": (lo, hi)}`` at ``confidence``), ``n`` specimens, ``n_censored``,
    ``unbiasing_factor``, ``test`` (one of :data:`~demfem.risk.specimen_area.TESTS`),
    ``geometry`` (SI), ``surface`` ("inner"/"outer": the glass surface whose flaws failed),
    ``criterion`` of the effective area, ``scaling_modulus`` ("unbiased" or "ml": the m used
    for A_eff and σ_0), ``effective_area_m2`` (A_eff for that m), ``source`` (where the data
    come from), ``time_to_failure_s`` (typical test duration, for slow crack growth; None if
    not given), ``n_simulations`` and ``seed`` of the pivot Monte Carlo.
    """

    m: float
    m_unbiased: float
    sigma_theta_Pa: float
    bounds: Dict[str, Tuple[float, float]]
    confidence: float
    n: int
    n_censored: int
    unbiasing_factor: float
    test: str
    geometry: Dict[str, Any]
    surface: str
    criterion: str
    scaling_modulus: str
    effective_area_m2: float
    source: str
    time_to_failure_s: Optional[float] = None
    n_simulations: int = DEFAULT_SIMULATIONS
    seed: int = DEFAULT_SEED

    @property
    def weibull_modulus(self) -> float:
        """The m that goes into the material's :class:`SurfaceStrength`."""
        return self.m_unbiased if self.scaling_modulus == "unbiased" else self.m

    def characteristic_strength_at(self, reference_area: float = REFERENCE_AREA) -> float:
        """σ_0 = σ_θ (A_eff/A_0)^{1/m} (Pa) on ``reference_area`` A_0 (m², ASTM C1683)."""
        a0 = check_positive("reference_area", reference_area)
        return self.sigma_theta_Pa * (self.effective_area_m2 / a0) ** (1.0 / self.weibull_modulus)

    def describe(self) -> str:
        """One line: what was fitted, from what, and the bounds."""
        lo_m, hi_m = self.bounds["m"]
        lo_s, hi_s = self.bounds["sigma_theta_Pa"]
        pct = f"{self.confidence:.0%}"
        return (f"ASTM C1239 maximum-likelihood fit of {self.n} {self.test} specimens "
                f"({self.n_censored} censored) from {self.source}, {self.surface} surface: "
                f"m = {self.m_unbiased:.3g} unbiased (ML {self.m:.3g}, {pct} bounds "
                f"{lo_m:.3g}-{hi_m:.3g}), sigma_theta = {self.sigma_theta_Pa / 1e6:.1f} MPa "
                f"({pct} bounds {lo_s / 1e6:.1f}-{hi_s / 1e6:.1f} MPa) at A_eff = "
                f"{self.effective_area_m2:.3g} m^2 ({self.criterion}, m = "
                f"{self.weibull_modulus:.3g}; ASTM C1683)")

    def to_surface_strength(self, reference_area: float = REFERENCE_AREA) -> SurfaceStrength:
        """The fitted surface's :class:`SurfaceStrength` on ``reference_area`` (m²)."""
        return SurfaceStrength(weibull_modulus=self.weibull_modulus,
                               characteristic_strength=self.characteristic_strength_at(
                                   reference_area),
                               reference_area=reference_area, source=self.describe())

    def to_dict(self) -> Dict[str, Any]:
        """Plain JSON-ready dict (tuples as lists)."""
        d = asdict(self)
        d["bounds"] = {k: list(v) for k, v in self.bounds.items()}
        return d


def fit_strength(strength_Pa: ArrayLike, censored: Optional[ArrayLike] = None, *,
                 test: str = "none", geometry: Optional[Mapping[str, Any]] = None,
                 surface: str = "outer", criterion: str = "max_principal",
                 scaling_modulus: str = "unbiased", confidence: float = 0.90,
                 source: str = "user data", time_to_failure_s: Optional[float] = None,
                 n_simulations: int = DEFAULT_SIMULATIONS, seed: int = DEFAULT_SEED
                 ) -> StrengthFit:
    """Fit strength tests (ASTM C1239) and scale them to the material (ASTM C1683).

    Parameters
    ----------
    strength_Pa:
        Nominal failure stress of each specimen, Pa, shape (N,), finite and > 0 (for a
        censored specimen: the stress it reached).
    censored:
        (N,) 0/1: 1 for a specimen that did not fail from this flaw population (another
        origin, or no failure at the maximum load). At least 2 must be 0.
    test, geometry:
        The test (``"ring-on-ring"``, ``"side-compression"``, ``"burst"``, ``"none"``) and
        its geometry in SI units (see :func:`demfem.risk.specimen_area.effective_area_of_test`;
        ``"none"`` takes ``{"effective_area_m2": A}``, default the 1e-4 m² reference area).
    surface:
        ``"inner"`` or ``"outer"``: the cartridge surface whose flaws the specimens failed from.
    criterion:
        Effective-area criterion, ``"max_principal"`` (what ``demfem assess`` uses) or ``"pia"``.
    scaling_modulus:
        ``"unbiased"`` (default) or ``"ml"``: the m used for A_eff, σ_0 and the SurfaceStrength.
    confidence:
        Two-sided confidence of the bounds, in (0, 1) (C1239 reports 90 %).
    source, time_to_failure_s:
        Where the data come from (text); typical time to failure of the test, s (optional).
    n_simulations, seed:
        Monte Carlo of the pivots (≥ 200; seeded).
    """
    s, c = _check_data(strength_Pa, censored)
    if test not in TESTS:
        raise InvalidParameterError(f"invalid test = {test!r}: must be one of "
                                    f"{', '.join(map(repr, TESTS))}")
    if surface not in SURFACES:
        raise InvalidParameterError(f"invalid surface = {surface!r}: must be 'inner' or 'outer'")
    if criterion not in CRITERIA:
        raise InvalidParameterError(f"invalid criterion = {criterion!r}: must be one of "
                                    f"{', '.join(map(repr, CRITERIA))}")
    if scaling_modulus not in MODULUS_CHOICES:
        raise InvalidParameterError(f"invalid scaling_modulus = {scaling_modulus!r}: must be "
                                    "'unbiased' or 'ml'")
    gamma = check_range("confidence", confidence, 0.0, 1.0)
    t_f = None if time_to_failure_s is None else check_positive("time_to_failure_s",
                                                                time_to_failure_s)
    geom = dict(geometry or {})
    if test == "none" and geom.get("effective_area_m2") is None:
        geom["effective_area_m2"] = REFERENCE_AREA  # σ_θ taken as σ_0 on the default A_0
    effective_area_of_test(test, 1.0, geom, surface=surface, criterion=criterion)  # validate
    m_hat, theta = weibull_mle(s, c)
    q, t = pivot_samples(s, c, n_simulations=n_simulations, seed=seed)
    b = float(1.0 / np.mean(q))
    hi_p, lo_p = 0.5 * (1.0 + gamma), 0.5 * (1.0 - gamma)
    q_lo, q_hi = np.quantile(q, [lo_p, hi_p])
    t_lo, t_hi = np.quantile(t, [lo_p, hi_p])
    m_used = b * m_hat if scaling_modulus == "unbiased" else m_hat
    a_eff = effective_area_of_test(test, m_used, geom, surface=surface, criterion=criterion)
    return StrengthFit(
        m=m_hat, m_unbiased=b * m_hat, sigma_theta_Pa=theta,
        bounds={"m": (float(m_hat / q_hi), float(m_hat / q_lo)),
                "sigma_theta_Pa": (float(theta * math.exp(-t_hi / m_hat)),
                                   float(theta * math.exp(-t_lo / m_hat)))},
        confidence=gamma, n=int(s.size), n_censored=int(c.sum()), unbiasing_factor=b,
        test=test, geometry=geom, surface=surface, criterion=criterion,
        scaling_modulus=scaling_modulus, effective_area_m2=float(a_eff), source=str(source),
        time_to_failure_s=t_f, n_simulations=int(n_simulations), seed=int(seed))


def __getattr__(name: str) -> Any:
    # the file functions live in demfem.risk.strength_file (which imports this module)
    if name in ("load_strength_file", "read_strength_csv", "write_strength_file",
                "strength_document"):
        from demfem.risk import strength_file

        return getattr(strength_file, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

