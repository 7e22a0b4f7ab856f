"""Results of an explicit FEM run as numpy arrays: contact force histories per pair of
parties and region (normal and tangential resultants, as Abaqus's CFNM/CFSM, contact area,
largest penetration), energies over time, snapshots of the fields (σ1 per element, contact
pressure), and writers for VTK series. SI units: s, N, m², m, J, Pa.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Optional, Sequence, Union

import numpy as np

from demfem.errors import InvalidParameterError

if TYPE_CHECKING:  # pragma: no cover
    from demfem.fem.model import FemModel

#: Columns of :attr:`FemResult.energy`.
ENERGY_COLUMNS = ("time_s", "kinetic_J", "internal_J", "external_work_J", "damping_work_J",
                  "contact_elastic_J", "spring_J", "friction_work_J", "rigid_work_J",
                  "contact_work_J")


@dataclass(frozen=True)
class Snapshot:
    """The fields at one instant: time (s), displacement (N,3) m, element σ1 (E,) Pa,
    contact pressure per node (N,) Pa (and for shells σ1 on both faces)."""

    time: float
    displacement: np.ndarray
    sigma1_element: np.ndarray
    contact_pressure: np.ndarray
    #: Shells only: σ1 (E, 3) Pa at each triangle's bottom (−t/2 along its normal), middle
    #: and top (+t/2) surfaces; ``sigma1_element`` is then the larger of bottom and top.
    sigma1_surfaces: Optional[np.ndarray] = None


@dataclass
class FemResult:
    """What a run produced.

    ``time`` (n,) s of the contact samples; ``channels``: (party a, party b, region of a)
    names per column; ``normal_force``, ``tangential_force`` (n, C) N: magnitudes of the
    resultant contact force on party a; ``contact_area`` (n, C) m²; ``max_penetration``
    (n, C) m; ``energy`` (m, 10) J with :data:`ENERGY_COLUMNS`; ``snapshots``; ``final``:
    the last state; ``step``: the step report (dt, limits, whether contact reduced it).
    """

    time: np.ndarray
    channels: list[tuple[str, str, int]]
    normal_force: np.ndarray
    tangential_force: np.ndarray
    contact_area: np.ndarray
    max_penetration: np.ndarray
    energy: np.ndarray
    snapshots: list[Snapshot]
    final: Snapshot
    step: dict
    contact_info: dict = field(default_factory=dict)

    @classmethod
    def from_model(cls, model: "FemModel", energy: np.ndarray, snapshots: list[Snapshot],
                   t0: float) -> "FemResult":
        s = model.solver
        hist = np.asarray(s.contact_history())
        hist = hist[hist[:, 0] >= t0 - 1e-15] if hist.size else hist
        chans = [(model.party_names[a], model.party_names[b], int(r))
                 for a, b, r in s.contact_channels()]
        c = len(chans)
        if hist.size == 0:
            hist = np.zeros((0, 1 + 4 * c))
        body = hist[:, 1:].reshape(len(hist), c, 4)
        return cls(time=hist[:, 0].copy(), channels=chans,
                   normal_force=body[:, :, 0].copy(), tangential_force=body[:, :, 1].copy(),
                   contact_area=body[:, :, 2].copy(), max_penetration=body[:, :, 3].copy(),
                   energy=energy, snapshots=snapshots, final=model.snapshot(),
                   step=model.step_report(), contact_info=dict(s.contact_info() or {}))

    def channel(self, a: str, b: str, region: int = 0) -> int:
        """Column of the channel between parties ``a`` and ``b`` (in either order) for the
        region of the lower-numbered one."""
        for i, (x, y, r) in enumerate(self.channels):
            if r == region and {x, y} == {a, b}:
                return i
        raise InvalidParameterError(
            f"invalid channel ({a!r}, {b!r}, region {region}): known are {sorted(set(self.channels))}")

    def pair_force(self, a: str, b: str, regions: Sequence[int] = (0,),
                   smooth: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """Normal and tangential force (N) between ``a`` and ``b`` summed over ``regions``,
        optionally smoothed by a centred moving average over ``smooth`` s."""
        fn = sum(self.normal_force[:, self.channel(a, b, r)] for r in regions)
        ft = sum(self.tangential_force[:, self.channel(a, b, r)] for r in regions)
        fn, ft = np.asarray(fn, dtype=float), np.asarray(ft, dtype=float)
        if smooth > 0 and len(self.time) > 2:
            dt = float(np.median(np.diff(self.time)))
            w = max(1, int(round(smooth / dt)))
            fn, ft = moving_average(fn, w), moving_average(ft, w)
        return fn, ft

    def energy_balance_error(self) -> float:
        """Largest |E_kin + E_int + E_contact + E_springs + W_friction + W_damping − W_loads −
        W_rigid − E_0| over the run, relative to the largest energy term (0 when all vanish).
        W_loads is the external work less the contact forces' work."""
        e = self.energy
        if e.size == 0:
            return 0.0
        kin, inte, wext, wd, el, sp, fr, rig, wc = (e[:, i] for i in range(1, 10))
        total = kin + inte + el + sp + fr + wd - (wext - wc) - rig
        err = np.abs(total - total[0])
        scale = np.max(np.abs(e[:, 1:]))
        return float(err.max() / scale) if scale > 0 else 0.0


def moving_average(x: np.ndarray, w: int) -> np.ndarray:
    """Centred moving average of ``x`` over ``w`` samples (shorter windows at the ends)."""
    if w <= 1:
        return np.asarray(x, dtype=float)
    c = np.concatenate([[0.0], np.cumsum(x, dtype=float)])
    n = len(x)
    i = np.arange(n)
    lo = np.maximum(i - w // 2, 0)
    hi = np.minimum(i + w // 2 + 1, n)
    return (c[hi] - c[lo]) / (hi - lo)
