"""Converged stress on cartridge 1 from the cluster's contact forces: a closed-form submodel.

The cluster's FEM (:func:`demfem.fem.cluster_run.run_cluster`) resolves the contact forces
well (they converge with the mesh, docs/cluster.md) but not σ1 at the contact: its elements are
~2 mm against contact patches of 0.01–0.5 mm. This module takes the force histories of a
finished run — normal F and tangential Q on cartridge 1 from 2 and from 3, in 1's bottom and
top half (``run.npz``, the same as ``forces.csv``) — smooths them as the run's summary does
(centred moving average over :data:`demfem.fem.cluster_run.SMOOTH_S` = 10 µs, which removes the
penalty contact's node-to-node ringing) and evaluates :func:`demfem.stress.contact_stresses`
(verified against a resolved FEM and CalculiX, docs/stress-verification.md) at every sample
with F > 0, vectorised over time: peak σ1 on 1's outer and inner surface and their Weibull
effective areas, per pair and region, and their peaks.

**The contact geometry each pair-region gets** (:func:`contact_geometry`):

* **hitter upright** (its tilt 0): its body lies along 1's, a line contact — ``"parallel"``
  over the length where the two cylindrical bodies face each other inside that half of 1
  (bottom z in [0, length/2), top [length/2, length], the hitter's body lifted by its offset),
  ring support ``"opposite"`` (1 is pressed between the hitter and the touching neighbour on
  the far side: 5 opposite 2, 6 opposite 3). The force of that half is spread over that half's
  length. A half with no facing bodies (a lifted hitter's bottom) gets the point contact below.
* **hitter tilted**: the axes lie in one vertical plane at the tilt angle; they intersect,
  they do not cross, and the bodies first meet where the leading end of the hitter — the
  outer edge of its open end (tilt < 0) or its body's shoulder edge (tilt > 0) — presses on
  1's body. That is a point contact whose curvatures are 1's hoop (1/R), the end ring of the
  hitter along it (1/R), and the hitter's edge across it. It is evaluated as ``"crossed"`` at
  a crossing angle of 90° (the edge runs horizontally, 1's axis vertically, whatever the tilt)
  with both radii R = the body's outer radius: the Hertz idealisation of the end ring on the
  body. Taking the crossing angle equal to the tilt (2°) would describe two bodies crossing
  along their lengths, which these do not; it also puts the contact ellipse's semi-axis beyond
  the shell's bending length ℓ at these forces (refused by the model). The edge across is
  sharper than R (a ground end, or the node ring of the FEM), so the outer (contact) σ1 is a
  lower bound there; the inner (bending) σ1 depends on the contact size only weakly.
* **where on 1**: the height of the contact (from :meth:`CartridgeCluster.first_contact` for
  the leading end; the hitter's other end for the other half) gives the location passed to
  the model: ``"rim"`` within :data:`END_BAND_ELL` bending lengths ℓ of 1's open end,
  ``"shoulder"`` within as much of its shoulder, else ``"body"``. When the stress model has no
  model for that location (it refuses ``"rim"`` and ``"shoulder"`` today), the mid-body model
  is used and the entry says so (``in_model_range`` false, ``model_location`` "body"): near a
  free end the wall bends more, so that value is not an upper bound.

Friction: the smoothed Q is at most μ F when every node slid at the run's Coulomb μ; samples
above (smoothing edges, roundoff) are clipped to μ F and counted (``clipped_tangential``).

SI units: N, m, Pa, m², s.
"""
from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Optional, Union

import numpy as np

from demfem.errors import DemfemIOError, InvalidParameterError
from demfem.fem.cluster_run import PAIRS, REGIONS, SMOOTH_S
from demfem.fem.result import moving_average
from demfem.scenes.cluster import CartridgeCluster

__all__ = ["PairContact", "PairHistory", "ClusterSubmodel", "contact_geometry",
           "evaluate_submodel", "submodel_from_folder", "SUBMODEL_CSV", "END_BAND_ELL",
           "smooth_history"]

#: The CSV the cluster run writes (one row per output step).
SUBMODEL_CSV = "cluster_submodel.csv"
#: A contact closer than this many bending lengths ℓ to 1's open end or shoulder is there.
END_BAND_ELL = 3.0
#: The CSV's quantities per pair-region, in column order (suffix: unit).
CSV_QUANTITIES = (("normal_force", "N"), ("tangential_force", "N"),
                  ("outer_sigma1", "Pa"), ("inner_sigma1", "Pa"),
                  ("outer_effective_area", "m2"), ("inner_effective_area", "m2"))


@dataclass(frozen=True)
class PairContact:
    """The contact model of one pair and half of 1 (module text).

    ``geometry``: "parallel" or "crossed"; ``crossing_angle_deg`` (crossed) or
    ``contact_length_m`` (parallel); ``z_m``: height of the contact on 1 from its open end, m
    (a line contact: its middle); ``location``: where that is ("body", "rim", "shoulder");
    ``why``: one line on the choice."""

    pair: str
    region: str
    geometry: str
    crossing_angle_deg: Optional[float]
    contact_length_m: Optional[float]
    z_m: float
    location: str
    why: str


@dataclass(frozen=True)
class PairHistory:
    """The submodel of one pair-region over time (arrays on the run's output times).

    ``normal_force``, ``tangential_force`` (N, smoothed; Q clipped to μ F);
    ``outer_sigma1``, ``inner_sigma1`` (Pa) and ``outer_effective_area``,
    ``inner_effective_area`` (m²), 0 where F = 0; ``model_location``: what the stress model
    was asked for; ``in_model_range``: whether that is where the contact is;
    ``clipped_tangential``: samples whose Q was clipped; ``max_friction_ratio``: the largest
    Q/F before clipping."""

    contact: PairContact
    normal_force: np.ndarray
    tangential_force: np.ndarray
    outer_sigma1: np.ndarray
    inner_sigma1: np.ndarray
    outer_effective_area: np.ndarray
    inner_effective_area: np.ndarray
    model_location: str
    in_model_range: bool
    clipped_tangential: int
    max_friction_ratio: float

    def peaks(self, time: np.ndarray) -> dict[str, Any]:
        """Peaks: the largest F, outer σ1 and inner σ1, each with its time and the force
        there, and the effective area at each σ1 peak (plain floats)."""
        out: dict[str, Any] = {}
        if not np.any(self.normal_force > 0):
            return {"normal_force_N": 0.0, "outer_sigma1_Pa": 0.0, "inner_sigma1_Pa": 0.0}
        k = int(np.argmax(self.normal_force))
        out["normal_force_N"] = float(self.normal_force[k])
        out["normal_force_time_s"] = float(time[k])
        for side in ("outer", "inner"):
            s = getattr(self, f"{side}_sigma1")
            k = int(np.argmax(s))
            out[f"{side}_sigma1_Pa"] = float(s[k])
            out[f"{side}_sigma1_time_s"] = float(time[k])
            out[f"{side}_sigma1_at_normal_force_N"] = float(self.normal_force[k])
            out[f"{side}_effective_area_m2"] = float(getattr(self, f"{side}_effective_area")[k])
        return out


@dataclass(frozen=True)
class ClusterSubmodel:
    """:func:`evaluate_submodel`'s result: ``time`` (s) and ``histories`` keyed "1-2_bottom",
    "1-2_top", "1-3_bottom", "1-3_top"."""

    time: np.ndarray
    histories: dict[str, PairHistory]

    def csv_text(self) -> str:
        """The histories as CSV: ``time_s`` then, per pair-region, the quantities of
        :data:`CSV_QUANTITIES` (columns ``<quantity>_<pair-region>_<unit>``), every value
        written with Python's shortest round-trip repr (reads back to the same float)."""
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        keys = list(self.histories)
        w.writerow(["time_s"] + [f"{q}_{k}_{u}" for k in keys for q, u in CSV_QUANTITIES])
        cols = [self.time] + [getattr(self.histories[k], q) for k in keys
                              for q, _ in CSV_QUANTITIES]
        for row in zip(*cols):
            w.writerow([repr(float(v)) for v in row])
        return buf.getvalue()

    def summary(self) -> dict[str, Any]:
        """The summary entry: per pair-region the contact model and the peaks, and the
        largest outer and inner σ1 over all (plain values, strict-JSON safe)."""
        pairs: dict[str, Any] = {}
        for key, h in self.histories.items():
            c = h.contact
            pairs[key] = {
                "geometry": c.geometry, "crossing_angle_deg": c.crossing_angle_deg,
                "contact_length_m": c.contact_length_m, "contact_z_m": c.z_m,
                "location": c.location, "model_location": h.model_location,
                "in_model_range": h.in_model_range, "why": c.why,
                "clipped_tangential": h.clipped_tangential,
                "max_friction_ratio": h.max_friction_ratio,
                **h.peaks(self.time)}
        outer = max(pairs.items(), key=lambda kv: kv[1]["outer_sigma1_Pa"])
        inner = max(pairs.items(), key=lambda kv: kv[1]["inner_sigma1_Pa"])
        return {"pairs": pairs,
                "outer_sigma1_max_Pa": outer[1]["outer_sigma1_Pa"], "outer_sigma1_max_at": outer[0],
                "inner_sigma1_max_Pa": inner[1]["inner_sigma1_Pa"], "inner_sigma1_max_at": inner[0],
                "smoothing_s": SMOOTH_S, "csv": SUBMODEL_CSV,
                "model": "demfem.stress.contact_stresses on the smoothed force histories "
                         "(demfem.fem.cluster_submodel)"}


def _location(cluster: CartridgeCluster, z: float) -> str:
    from demfem.stress.shell import characteristic_length

    c = cluster.cartridge
    ell = characteristic_length(c.body_mid_radius, c.wall_thickness, c.material.nu)
    if z < END_BAND_ELL * ell:
        return "rim"
    if z > c.body_length - END_BAND_ELL * ell:
        return "shoulder"
    return "body"


def contact_geometry(cluster: CartridgeCluster) -> dict[str, PairContact]:
    """The contact model of each pair and half of 1 (module text), keyed "1-2_bottom" …"""
    c = cluster.cartridge
    half = 0.5 * c.length
    bl = c.body_length
    first = cluster.first_contact()
    out: dict[str, PairContact] = {}
    for k, pair in ((1, "2"), (2, "3")):
        tilt = float(getattr(cluster, f"tilt_{pair}_deg"))
        offset = float(getattr(cluster, f"offset_{pair}_z"))
        for r, rname in REGIONS:
            lo, hi = (0.0, half) if r == 0 else (half, c.length)
            a, b = max(0.0, offset, lo), min(bl, offset + bl, hi)
            key = f"1-{pair}_{rname}"
            if tilt == 0 and b > a:
                out[key] = PairContact(
                    pair, rname, "parallel", None, b - a, 0.5 * (a + b), "body",
                    f"{pair} upright: the bodies face each other over {(b - a) * 1e3:.4g} mm "
                    f"of 1's {rname} half (z {a * 1e3:.4g}-{b * 1e3:.4g} mm), a line contact")
                continue
            z_first = first[pair]["z_m"]
            lead = 0 if z_first < half else 1
            if r == lead:
                z = z_first
                what = "its leading end (first contact)" if tilt != 0 else "its open end's edge"
            elif r == 0:  # the hitter's open end, below its first contact
                z = offset
                what = "its trailing open end (if it touches)"
            else:  # the hitter's shoulder edge, above its first contact
                z = min(bl, offset + bl * math.cos(math.radians(tilt)))
                what = "its trailing shoulder edge (if it touches)"
            out[key] = PairContact(
                pair, rname, "crossed", 90.0, None, float(z), _location(cluster, float(z)),
                f"{pair} tilted {tilt:g} deg, lifted {offset * 1e3:g} mm: {what} on 1's body "
                f"at z = {z * 1e3:.3g} mm, a point contact (the end ring on the body: crossed "
                "at 90 deg, both radii the body's)")
    return out


def smooth_history(time: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``x`` averaged over :data:`SMOOTH_S` (a centred moving average of as many output steps),
    as the run's summary smooths its force peaks."""
    if len(time) < 3:
        return np.asarray(x, float)
    w = max(1, int(round(SMOOTH_S / float(np.median(np.diff(time))))))
    return moving_average(x, w)


def _stresses(contact: PairContact, f: np.ndarray, q: np.ndarray, mu: float,
              cluster: CartridgeCluster) -> tuple[Any, str, bool]:
    from demfem.stress import contact_stresses

    kw: dict[str, Any] = {"geometry": contact.geometry, "cartridge": cluster.cartridge,
                          "friction_coefficient": mu if mu > 0 else None}
    if contact.geometry == "parallel":
        kw.update(contact_length=contact.contact_length_m, ring_support="opposite")
    else:
        kw.update(crossing_angle_deg=contact.crossing_angle_deg)
    if contact.location != "body":
        try:
            return contact_stresses(f, q, location=contact.location, **kw), contact.location, True
        except InvalidParameterError as exc:
            if "location" not in str(exc):
                raise
    return (contact_stresses(f, q, location="body", **kw), "body",
            contact.location == "body")


def evaluate_submodel(cluster: CartridgeCluster, data: dict) -> ClusterSubmodel:
    """The submodel of a cluster run (module text): ``data`` holds ``time`` (s) and
    ``fn_1<pair>_<region>``, ``ft_1<pair>_<region>`` (N), as ``run.npz`` does."""
    if not isinstance(cluster, CartridgeCluster):
        raise InvalidParameterError(f"invalid cluster = {cluster!r}: must be a CartridgeCluster")
    try:
        time = np.asarray(data["time"], float)
    except KeyError:
        raise InvalidParameterError("invalid data: no 'time' (a cluster run's run.npz)") from None
    geo = contact_geometry(cluster)
    mu = float(cluster.friction)
    histories: dict[str, PairHistory] = {}
    for pair in PAIRS:
        for _, rname in REGIONS:
            key = f"1-{pair}_{rname}"
            try:
                fn, ft = data[f"fn_1{pair}_{rname}"], data[f"ft_1{pair}_{rname}"]
            except KeyError as exc:
                raise InvalidParameterError(f"invalid data: no {exc} (a cluster run's "
                                            "run.npz)") from None
            f = np.maximum(smooth_history(time, np.asarray(fn, float)), 0.0)
            q = np.maximum(smooth_history(time, np.asarray(ft, float)), 0.0)
            on = f > 0
            ratio = np.zeros_like(f)
            ratio[on] = q[on] / f[on]
            over = on & (q > mu * f * (1.0 + 1e-9))  # counted: beyond roundoff
            q = np.minimum(q, mu * f)
            q[~on] = 0.0
            zeros = [np.zeros_like(f) for _ in range(4)]
            model_loc, in_range = "body", geo[key].location == "body"
            if np.any(on):
                s, model_loc, in_range = _stresses(geo[key], f[on], q[on], mu, cluster)
                for arr, val in zip(zeros, (s.outer_sigma1_max, s.inner_sigma1_max,
                                            s.outer_effective_area, s.inner_effective_area)):
                    arr[on] = val
            histories[key] = PairHistory(
                geo[key], f, q, outer_sigma1=zeros[0], inner_sigma1=zeros[1],
                outer_effective_area=zeros[2], inner_effective_area=zeros[3],
                model_location=model_loc, in_model_range=in_range,
                clipped_tangential=int(np.count_nonzero(over)),
                max_friction_ratio=float(ratio.max(initial=0.0)))
    return ClusterSubmodel(time, histories)


def submodel_from_folder(out: Union[str, Path]) -> ClusterSubmodel:
    """:func:`evaluate_submodel` of the finished cluster run in folder ``out`` (its
    ``settings.json`` record and ``run.npz``; read only, nothing written)."""
    import json

    out = Path(out)
    record, run = out / "settings.json", out / "run.npz"
    if not record.is_file() or not run.is_file():
        raise DemfemIOError(f"invalid cluster folder {out}: needs settings.json and run.npz "
                            "(a finished demfem cluster run)")
    doc = json.loads(record.read_text(encoding="utf-8"))
    settings = doc.get("settings", doc)
    if "cluster" not in settings:
        raise DemfemIOError(f"invalid cluster folder {out}: {record.name} has no cluster settings")
    cluster = CartridgeCluster.from_dict(settings["cluster"], source=str(record))
    with np.load(run, allow_pickle=False) as z:
        data = {k: z[k] for k in z.files if k == "time" or k.startswith(("fn_", "ft_"))}
    return evaluate_submodel(cluster, data)
