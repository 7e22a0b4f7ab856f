"""Where on the cartridge an event lands: the place weights of the sphere table's events.

The DEM of ``demfem assess`` runs equivalent spheres, which touch at a point with no height
and no angle. The full-shape table (the same default table with exact cartridges, bodies of
revolution: ``benches/full_shape_table.py``, docs/cartridge-places.md) logged, for every
contact onset, the place on each cartridge it landed on. Its counts give, per partner, the
probability that a contact lands at the **rim** (the open bottom end, the paper's Fig. 1b
"fire polish area"), on the **body** or at the **shoulder** (the body–shoulder junction);
no onset touched the neck or the flange. An event of the sphere table gets those
probabilities as weights (:func:`event_place_weights`), and the risk takes the expectation
over them: P_k = Σ_p w_p P_k(σ at p) (:func:`demfem.assess.risk_stage.event_probabilities`).
The expectation, not a sampled place per event: the answer carries no sampling noise, and
the hazard splits exactly by place.

The weights are conditioned on the partner only (another cartridge; each wall by its name),
not on the force: the full-shape run recorded the place per partner, over 0.7–1.4 s of the
default table (50 909 onsets between cartridges). For a pair, each of the two cartridges is
counted at its own place (the pair "body–shoulder" puts one cartridge's contact on its body
and the other's at its shoulder).

:data:`PLACE_WEIGHTS` is the shipped table (``place_weights.json`` beside this module, made
by :func:`weights_from_full_shape` from ``docs/data/full_shape_table.json``; a test checks
that the two agree). Places are in the order of :data:`demfem.stress.model.LOCATIONS`.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Mapping, Optional, Sequence

import numpy as np

from demfem.errors import InvalidParameterError

__all__ = ["PLACES", "PLACE_MODES", "PLACE_WEIGHTS", "PLACE_WEIGHTS_FILE",
           "weights_from_full_shape", "event_place_weights", "pair_place_weights",
           "load_place_weights"]

#: The places on the cartridge the stress model knows, in :data:`demfem.stress.model.LOCATIONS`
#: order (the neck and the flange were never touched on the full-shape table).
PLACES = ("body", "rim", "shoulder")
#: ``demfem assess --place``: ``"mix"`` (the full-shape table's weights), or every event at
#: one place.
PLACE_MODES = ("mix",) + PLACES
#: The shipped weights.
PLACE_WEIGHTS_FILE = Path(__file__).with_name("place_weights.json")
#: Partner key of contacts between two cartridges.
PAIR = "cartridge"
#: Partner key of walls the full-shape table did not log (all walls pooled).
OTHER_WALL = "wall"


def _normalised(counts: Mapping[str, float]) -> list[float]:
    w = np.array([float(counts.get(p, 0.0)) for p in PLACES])
    if not np.all(np.isfinite(w)) or np.any(w < 0) or w.sum() <= 0:
        raise InvalidParameterError(f"invalid place counts {dict(counts)!r}: must be finite, "
                                    f">= 0 and not all 0 over {PLACES}")
    return [float(x) for x in w / w.sum()]


def weights_from_full_shape(doc: Mapping[str, Any]) -> dict[str, Any]:
    """The place weights from a full-shape table's document (``benches/full_shape_table.py``'s
    JSON): per partner, the fraction of contact onsets at each of :data:`PLACES`; pairs from
    ``pair_place_pairs`` (both cartridges of each pair counted at their own place), walls from
    ``place_by_partner`` by name, and ``wall`` for the walls pooled. The belt is not an event
    partner (a cartridge stands on it) and is left out."""
    try:
        rev = doc["revolution"]
        pairs = rev["pair_place_pairs"]
        by_partner = rev["place_by_partner"]
    except (KeyError, TypeError):
        raise InvalidParameterError("invalid full-shape document: needs revolution."
                                    "pair_place_pairs and revolution.place_by_partner") from None
    known = set(PLACES) | {"neck", "flange"}
    per_cartridge: dict[str, float] = {}
    for key, n in pairs.items():
        parts = str(key).split("-")
        if len(parts) != 2 or not set(parts) <= known:
            raise InvalidParameterError(f"invalid pair of places {key!r}: must be 'a-b' with "
                                        f"a, b among {sorted(known)}")
        for p in parts:
            per_cartridge[p] = per_cartridge.get(p, 0.0) + float(n)
    untouched = sum(per_cartridge.get(p, 0.0) for p in ("neck", "flange"))
    weights: dict[str, Any] = {PAIR: _normalised(per_cartridge)}
    counts: dict[str, Any] = {PAIR: {p: per_cartridge.get(p, 0.0) for p in sorted(known)}}
    pooled: dict[str, float] = {}
    for name, c in by_partner.items():
        if name in (PAIR, "belt"):
            continue
        untouched += sum(float(c.get(p, 0)) for p in ("neck", "flange"))
        weights[name] = _normalised(c)
        counts[name] = {p: float(c.get(p, 0)) for p in sorted(known)}
        for p in PLACES:
            pooled[p] = pooled.get(p, 0.0) + float(c.get(p, 0))
    weights[OTHER_WALL] = _normalised(pooled)
    return {"places": list(PLACES), "weights": weights, "counts": counts,
            "neck_or_flange_onsets": untouched,
            "source": doc.get("command", "full-shape table"),
            "note": "fraction of contact onsets (>= the assess filter's speed) at each place "
                    "on the cartridge, per partner, from the full-shape default table "
                    "(docs/cartridge-places.md)"}


def load_place_weights(path: Path | str = PLACE_WEIGHTS_FILE) -> dict[str, Any]:
    """The place-weights document at ``path`` (checked: rows of :data:`PLACES` fractions that
    sum to 1, a ``cartridge`` and a ``wall`` row)."""
    try:
        doc = json.loads(Path(path).read_text())
        w = doc["weights"]
        places = tuple(doc["places"])
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise InvalidParameterError(f"invalid place weights file {str(path)!r}: {exc}") from None
    if places != PLACES:
        raise InvalidParameterError(f"invalid place weights file {str(path)!r}: places "
                                    f"{places} must be {PLACES}")
    for key in (PAIR, OTHER_WALL):
        if key not in w:
            raise InvalidParameterError(f"invalid place weights file {str(path)!r}: no "
                                        f"{key!r} row")
    for key, row in w.items():
        r = np.asarray(row, float)
        if r.shape != (len(PLACES),) or np.any(~np.isfinite(r)) or np.any(r < 0) \
                or abs(r.sum() - 1.0) > 1e-9:
            raise InvalidParameterError(f"invalid place weights file {str(path)!r}: row "
                                        f"{key!r} = {row!r} must be {len(PLACES)} fractions "
                                        "summing to 1")
    return doc


#: The shipped place weights (:func:`load_place_weights` of :data:`PLACE_WEIGHTS_FILE`).
PLACE_WEIGHTS: dict[str, Any] = load_place_weights()


def _mode_row(mode: str) -> Optional[np.ndarray]:
    if mode not in PLACE_MODES:
        raise InvalidParameterError(f"invalid place = {mode!r}: must be one of "
                                    f"{', '.join(map(repr, PLACE_MODES))}")
    if mode == "mix":
        return None
    row = np.zeros(len(PLACES))
    row[PLACES.index(mode)] = 1.0
    return row


def pair_place_weights(n: int, mode: str = "mix",
                       weights: Optional[Mapping[str, Any]] = None) -> np.ndarray:
    """(n, 3) weights of ``n`` contacts between two cartridges (:data:`PLACES` order)."""
    row = _mode_row(mode)
    if row is None:
        row = np.asarray((weights or PLACE_WEIGHTS)["weights"][PAIR], float)
    return np.tile(row, (int(n), 1))


def event_place_weights(events: np.ndarray, wall_names: Sequence[str], mode: str = "mix",
                        weights: Optional[Mapping[str, Any]] = None) -> np.ndarray:
    """(n, 3) place weights of the events (:data:`demfem.assess.events.EVENT_DTYPE`): pairs
    (``partner`` 0) the ``cartridge`` row, walls (1) their name's row (``wall_names`` by index)
    or the pooled ``wall`` row; ``mode`` one place puts every event there."""
    n = len(events)
    row = _mode_row(mode)
    if row is not None:
        return np.tile(row, (n, 1))
    table = (weights or PLACE_WEIGHTS)["weights"]
    out = np.empty((n, len(PLACES)))
    partner = np.asarray(events["partner"], np.int64)
    wall = np.asarray(events["wall"], np.int64)
    out[partner == 0] = np.asarray(table[PAIR], float)
    rest = partner != 0
    for k in np.unique(wall[rest]):
        name = wall_names[int(k)] if 0 <= int(k) < len(wall_names) else OTHER_WALL
        out[rest & (wall == k)] = np.asarray(table.get(name, table[OTHER_WALL]), float)
    return out
