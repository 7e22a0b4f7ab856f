"""Combining failure probabilities: collisions → cartridge → expected breakage rate.

A cartridge on the accumulation table suffers many collisions. If the collisions break it
independently (each one's probability computed from the pristine flaw population, so that
sub-critical damage carried from one collision to the next is neglected), the cartridge
survives only if it survives every one:

    P_cartridge = 1 − Π_k (1 − P_k) = −expm1( Σ_k log1p(−P_k) ).

The log1p/expm1 form keeps full relative precision for tiny probabilities (P ~ 1e-15, where
1 − Π(1 − P_k) computed directly loses every digit). The same rule combines the inner and outer
surfaces of one collision (separate flaw populations).

Caveat: the independence assumption is exact only for disjoint stressed areas or independent
flaw populations. Repeated hits on the same spot re-sample the same flaws, so the product rule
is conservative (over-predicts) when the same region is loaded again at a lower stress; using
the weakest-link sum on the envelope of stresses is the other bound.
"""
from __future__ import annotations

from typing import Optional, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

from demfem.errors import check_range
from demfem.risk._validate import as_array

__all__ = ["cartridge_failure_probability", "expected_broken_per_hour"]


def cartridge_failure_probability(
    p_collisions: ArrayLike, axis: Optional[int] = None
) -> Union[float, NDArray[np.float64]]:
    """Probability that a cartridge breaks in at least one of its collisions, in [0, 1].

    Parameters
    ----------
    p_collisions:
        Failure probability of each collision, dimensionless, each in [0, 1], finite. An empty
        sequence gives 0.
    axis:
        None: combine all values into one probability (float). An integer: combine along that
        axis, e.g. shape (n_cartridges, n_collisions) with ``axis=1`` (ndarray).

    Assumes the collisions break the cartridge independently (see the module docstring):
    P = 1 − Π_k (1 − P_k), evaluated as −expm1(Σ log1p(−P_k)).
    """
    p = as_array("p_collisions", p_collisions, 0.0, 1.0, lo_open=False, hi_open=False)
    with np.errstate(divide="ignore"):
        log_survival = np.sum(np.log1p(-p), axis=axis)
    out = 0.0 - np.expm1(log_survival)  # 0.0 - ... turns -0.0 into 0.0
    return float(out) if np.ndim(out) == 0 else np.asarray(out, dtype=np.float64)


def expected_broken_per_hour(p_per_cartridge: ArrayLike, throughput_per_hour: float) -> float:
    """Expected number of broken cartridges per hour, 1/h.

    ``p_per_cartridge``: the failure probability of one cartridge's passage over the table
    (dimensionless, in [0, 1]); an array is a sample of cartridges (e.g. the tagged spheres of
    a DEM run) and its mean is used. ``throughput_per_hour``: cartridges per hour, finite and
    ≥ 0. Returns throughput × mean(P).
    """
    p = as_array("p_per_cartridge", p_per_cartridge, 0.0, 1.0, lo_open=False, hi_open=False)
    q = check_range("throughput_per_hour", throughput_per_hour, 0.0, np.inf, lo_open=False)
    if p.size == 0:
        return 0.0
    return float(q * np.mean(p))
