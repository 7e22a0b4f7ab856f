"""Factors that carry :func:`demfem.stress.contact_stresses` from mid-body to the open rim and
to the shoulder, from the resolved FEM of a contact on the whole cartridge.

Near the open end of the body and below the body–shoulder junction no closed form holds for
the wall's bending under a contact. :mod:`demfem.stress.place_fem` solves it (a half model of
the default cartridge's glass, the Hertz circle of crossed cartridges, free: inertia relief)
at the place and mid-body on the same grading; ``benches/stress_place_tables.py`` writes the
ratios k = FEM(place) / FEM(body) of the model's global terms to ``place_factors.json``
(shipped with the package):

* ``inner`` — the inner surface's bending tension under the load (``inner_bending_Pa``,
  the whole inner σ1) and ``inner_area`` its effective area;
* ``outer_bending`` — the wall's bending stress on the outer surface at the contact edge
  (``outer_bending_Pa``): the FEM's outer peak less the model's contact term (the Hertz /
  Hamilton edge tension, which the FEM reproduces on a half-space to 2–4 %) at the place,
  over the same at mid-body;
* ``ring`` and ``ring_area`` — the bending field's outer tension away from the contact
  (``outer_ring_Pa``; the FEM's largest outer σ1 farther than two wall thicknesses from the
  contact centre) and its effective area.

per normal force F (N) and friction coefficient μ. :func:`place_factors` interpolates them
linearly in log F and in μ, **clamped** at the table's ends (F below the smallest or above the
largest tabulated force takes the end value; μ above the largest tabulated coefficient the
last one): the factors change slowly with F (the global field is linear in F; only the
contact's size moves, c/t from 0.05 to 0.24 over 1–100 N).

Scope: point contacts (crossed cartridges, rail edges) on the default cartridge's proportions;
the rim contact's centre at s = max(t/2, 1.5 a) from the open end face (the fire-polished end
rounds the last ≈ t/2), the shoulder contact's s = max(t/2, 1.5 a) below the junction.

Units: SI (N; the factors are dimensionless).
"""
from __future__ import annotations

import json
from functools import lru_cache
from importlib import resources
from typing import Any

import numpy as np

from demfem.errors import InvalidParameterError

__all__ = ["PLACE_TERMS", "factor_table", "place_factors"]

#: The model terms that carry a factor (keys of :func:`place_factors`).
PLACE_TERMS = ("inner", "inner_area", "outer_bending", "ring", "ring_area")


@lru_cache(maxsize=1)
def factor_table() -> dict[str, Any]:
    """The factor tables (``place_factors.json``): per place ("rim", "shoulder") the grid
    ``force_N`` (N, ascending), ``mu`` (ascending) and per term of :data:`PLACE_TERMS` a
    (len(mu), len(force_N)) array; plus their provenance."""
    text = resources.files("demfem.stress").joinpath("place_factors.json").read_text()
    raw = json.loads(text)
    out: dict[str, Any] = {k: v for k, v in raw.items() if k != "places"}
    places: dict[str, Any] = {}
    for place, block in raw["places"].items():
        f = np.asarray(block["force_N"], float)
        mu = np.asarray(block["mu"], float)
        grids = {t: np.asarray(block[t], float) for t in PLACE_TERMS}
        if f.size == 0 or mu.size == 0 or np.any(np.diff(f) <= 0) or np.any(np.diff(mu) <= 0):
            raise InvalidParameterError(f"invalid place_factors.json: place {place!r} needs "
                                        "ascending force_N and mu")
        for t, g in grids.items():
            # the outer bending at the contact edge may change sign (compression at mid-body,
            # ≈ 0 or slightly tensile at the open end); every other factor is a ratio of peaks
            ok = np.isfinite(g) & ((g > 0) if t != "outer_bending" else True)
            if g.shape != (mu.size, f.size) or not np.all(ok):
                raise InvalidParameterError(f"invalid place_factors.json: {place!r} {t!r} must "
                                            f"be a ({mu.size}, {f.size}) grid of finite "
                                            "factors (> 0 but for outer_bending)")
        places[place] = {"force_N": f, "mu": mu, **grids}
    out["places"] = places
    return out


def _interp_log(x: np.ndarray, grid: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Linear in log x over ``grid`` (ascending, > 0), clamped at its ends."""
    if grid.size == 1:
        return np.full(x.shape, values[0])
    return np.interp(np.log(x), np.log(grid), values)


def place_factors(place: str, normal_force: Any, friction: Any = 0.0) -> dict[str, np.ndarray]:
    """The factors k of :data:`PLACE_TERMS` at ``place`` ("rim" or "shoulder") for contact
    forces ``normal_force`` (N, > 0; array allowed) and friction coefficients ``friction``
    (Q/F, ≥ 0; broadcast with it): bilinear in (log F, μ), clamped at the table's ends."""
    table = factor_table()["places"]
    if place not in table:
        raise InvalidParameterError(f"invalid location = {place!r}: place factors exist for "
                                    f"{', '.join(map(repr, sorted(table)))}")
    f, mu = np.broadcast_arrays(np.asarray(normal_force, float), np.asarray(friction, float))
    if not np.all(np.isfinite(f) & (f > 0)):
        raise InvalidParameterError(f"invalid normal_force = {normal_force!r}: must be finite "
                                    "and > 0 N")
    if not np.all(np.isfinite(mu) & (mu >= 0)):
        raise InvalidParameterError(f"invalid friction = {friction!r}: must be finite and >= 0")
    b = table[place]
    mus = b["mu"]
    out: dict[str, np.ndarray] = {}
    for t in PLACE_TERMS:
        rows = [_interp_log(f, b["force_N"], b[t][k]) for k in range(mus.size)]
        if mus.size == 1:
            out[t] = rows[0]
            continue
        m = np.clip(mu, mus[0], mus[-1])
        j = np.clip(np.searchsorted(mus, m) - 1, 0, mus.size - 2)
        w = (m - mus[j]) / (mus[j + 1] - mus[j])
        stack = np.stack(rows)  # (n_mu, ...)
        lo = np.take_along_axis(stack, j[None], 0)[0]
        hi = np.take_along_axis(stack, (j + 1)[None], 0)[0]
        out[t] = (1.0 - w) * lo + w * hi
    return out
