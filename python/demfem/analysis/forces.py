"""Forces on spheres and groups of spheres, and the choice of the gentlest set-up (paper Fig. 5).

The paper picks A = 2 cm, T = 2 s, V_belt = 0.2 m/s by eye from curves of the average force on
the first line: small A clogs (the force grows over time), large A gives high spikes. The score
here makes that choice explicit and repeatable (see :func:`gentleness_score`).
"""
from __future__ import annotations

from typing import Sequence

import numpy as np

from demfem.analysis._checks import as_fraction, as_pairs, as_vectors
from demfem.errors import InvalidParameterError, ShapeError
from demfem.scenes.table import Tag

__all__ = [
    "particle_contact_force",
    "mean_tagged_force",
    "first_line_force",
    "force_statistics",
    "gentleness_score",
    "rank_setups",
    "SETUP_RANKING_DTYPE",
]


def particle_contact_force(pairs: np.ndarray, pair_forces: np.ndarray, n_particles: int,
                           kind: str = "net") -> np.ndarray:
    """Contact force on each particle from a contact list (one frame).

    Args:
        pairs: (n_c, 2) particle indices (i, j) of each contact.
        pair_forces: (n_c, 3) force on particle i from particle j, N (j receives the opposite).
        n_particles: N.
        kind: "net" for the resultant of the listed contact forces (Yade's ``O.forces.f``
            is this resultant over all of a body's contacts, walls and belt included, when
            those are in the list), or "sum" for the sum of the magnitudes of the contact
            forces, which stays large in a jammed pack whose forces cancel.

    Returns:
        (N, 3) resultant forces in N for "net", (N,) sums of magnitudes in N for "sum".
    """
    pairs = as_pairs(pairs, n_particles)
    f = as_vectors(pair_forces, "pair_forces").reshape(-1, 3)
    if len(f) != len(pairs):
        raise ShapeError(f"shape mismatch for pair_forces: expected ({len(pairs)}, 3), got "
                         f"{np.shape(pair_forces)}")
    if kind == "net":
        total = np.zeros((n_particles, 3))
        np.add.at(total, pairs[:, 0], f)
        np.add.at(total, pairs[:, 1], -f)
        return total
    if kind == "sum":
        magnitude = np.linalg.norm(f, axis=1)
        return (np.bincount(pairs[:, 0], magnitude, minlength=n_particles)
                + np.bincount(pairs[:, 1], magnitude, minlength=n_particles))
    raise InvalidParameterError(f"invalid kind = {kind!r}: must be 'net' or 'sum'")


def mean_tagged_force(forces: np.ndarray, tags: np.ndarray, tag: int) -> np.ndarray:
    """Average force magnitude in N on the spheres carrying ``tag``, per frame.

    Args:
        forces: (n_frames, N, 3) force vectors or (n_frames, N) magnitudes, N; NaN marks
            spheres that have left the table and is left out.
        tags: (N,) tag codes.
        tag: the code to average over.

    Returns:
        (n_frames,) mean magnitude, N; NaN where none of them is on the table.
    """
    f = np.asarray(forces, float)
    tags = np.asarray(tags)
    if f.ndim == 3 and f.shape[2] == 3:
        f = np.linalg.norm(f, axis=2)
    if f.ndim != 2 or tags.shape != (f.shape[1],):
        raise ShapeError(f"shape mismatch for forces/tags: expected (n_frames, N[, 3]) and "
                         f"(N,), got {np.shape(forces)} and {tags.shape}")
    chosen = f[:, tags == tag]
    finite = np.isfinite(chosen)
    count = finite.sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(count > 0, np.where(finite, chosen, 0.0).sum(axis=1)
                        / np.maximum(count, 1), np.nan)


def first_line_force(forces: np.ndarray, tags: np.ndarray) -> np.ndarray:
    """Average force magnitude on the 'first line' spheres against time (paper Fig. 5), N;
    :func:`mean_tagged_force` with ``Tag.FIRST_LINE``."""
    return mean_tagged_force(forces, tags, Tag.FIRST_LINE)


def force_statistics(force: np.ndarray, quantile: float = 0.95) -> dict[str, float]:
    """Mean, peak and high quantile of a force history (N), ignoring NaN frames.

    Returns:
        {"mean", "peak", "quantile"} in N.
    """
    f = np.asarray(force, float).ravel()
    f = f[np.isfinite(f)]
    q = as_fraction("quantile", quantile, 1.0)
    if len(f) == 0:
        raise InvalidParameterError("invalid force: no finite value to take statistics of")
    return {"mean": float(f.mean()), "peak": float(f.max()),
            "quantile": float(np.quantile(f, q))}


#: Fields of the table returned by :func:`rank_setups` (forces in N, score dimensionless).
SETUP_RANKING_DTYPE = np.dtype([
    ("label", "U64"), ("mean", "f8"), ("peak", "f8"), ("quantile", "f8"),
    ("score", "f8"), ("rank", "i8"),
])


def gentleness_score(stats: np.ndarray, weights: Sequence[float] = (1.0, 1.0, 1.0)) -> np.ndarray:
    """Score of each run from its force statistics: lower is gentler.

    For runs k with mean force m_k, peak p_k and high quantile q_k (N), each statistic is
    divided by its median over the compared runs (so the three are dimensionless and weigh the
    same whatever their size), then combined:

        S_k = (w_m m_k / med(m) + w_p p_k / med(p) + w_q q_k / med(q)) / (w_m + w_p + w_q).

    The mean catches clogging (a force that keeps growing, paper A = 1 cm), the peak catches
    single violent events (A = 5 and 7.5 cm), the quantile catches frequent strong events that a
    single peak would not show. A run equal to the median run in all three scores 1.

    Args:
        stats: (n_runs, 3) columns mean, peak, quantile, N.
        weights: (w_m, w_p, w_q), non-negative, not all zero.

    Returns:
        (n_runs,) scores.
    """
    s = np.asarray(stats, float)
    w = np.asarray(weights, float)
    if s.ndim != 2 or s.shape[1] != 3 or len(s) == 0:
        raise ShapeError(f"shape mismatch for stats: expected (n_runs, 3), got {s.shape}")
    if w.shape != (3,) or not np.all(np.isfinite(w)) or np.any(w < 0) or w.sum() <= 0:
        raise InvalidParameterError(f"invalid weights = {tuple(weights)!r}: must be three "
                                    "finite values >= 0, not all zero")
    median = np.median(s, axis=0)
    if np.any(median <= 0):
        raise InvalidParameterError("invalid stats: the median mean, peak and quantile over "
                                    "the runs must be > 0 to normalise by them")
    return (s / median) @ w / w.sum()


def rank_setups(times: Sequence[np.ndarray], forces: Sequence[np.ndarray],
                labels: Sequence[str], quantile: float = 0.95, discard_before: float = 0.0,
                weights: Sequence[float] = (1.0, 1.0, 1.0)) -> np.ndarray:
    """Rank runs of a parameter sweep from the gentlest (rank 1) on.

    Args:
        times: one (n_frames_k,) array of times in s per run (runs may differ in length).
        forces: one (n_frames_k,) force history in N per run, e.g. :func:`first_line_force`.
        labels: one name per run, e.g. "A=0.02 T=2 V=0.2".
        quantile: the high quantile used, in [0, 1).
        discard_before: frames earlier than this (s) are left out, to skip the start-up
            transient common to all runs.
        weights: see :func:`gentleness_score`.

    Returns:
        Structured array of :data:`SETUP_RANKING_DTYPE`, sorted by score (gentlest first).
    """
    if not (len(times) == len(forces) == len(labels)) or len(labels) == 0:
        raise ShapeError(f"shape mismatch: {len(times)} times, {len(forces)} forces and "
                         f"{len(labels)} labels; expected the same number (> 0) of each")
    rows = []
    for k, (t, f, label) in enumerate(zip(times, forces, labels)):
        t, f = np.asarray(t, float), np.asarray(f, float)
        if t.shape != f.shape or t.ndim != 1:
            raise ShapeError(f"shape mismatch for run {label!r}: times {t.shape} and forces "
                             f"{f.shape} must be equal 1-D shapes")
        keep = t >= discard_before
        if not np.any(np.isfinite(f[keep])):
            raise InvalidParameterError(f"invalid forces[{k}] ({label!r}): no finite value "
                                        f"at t >= discard_before = {discard_before:g} s")
        st = force_statistics(f[keep], quantile)
        rows.append((st["mean"], st["peak"], st["quantile"]))
    stats = np.array(rows)
    score = gentleness_score(stats, weights)
    order = np.argsort(score, kind="stable")
    table = np.zeros(len(labels), SETUP_RANKING_DTYPE)
    table["label"] = np.asarray(labels, str)[order]
    table["mean"], table["peak"], table["quantile"] = stats[order].T
    table["score"] = score[order]
    table["rank"] = np.arange(1, len(labels) + 1)
    return table
