"""Strength data in and strength files out: the CSV of a user's strength tests, the JSON
strength file that ``demfem assess --strength FILE`` reads, and ``demfem strength-fit``.

CSV (:func:`read_strength_csv`): a header row, one specimen per row, ``strength_Pa`` (Pa) or
``failure_stress_MPa`` (MPa), optional ``censored`` (0/1), other columns ignored, ``#``
comments. Strength file (:func:`write_strength_file`, :func:`load_strength_file`): strict JSON
with the :class:`~demfem.risk.surface.SurfaceStrength` of each measured surface and the
:class:`~demfem.risk.strength_fit.StrengthFit` behind it. See ``docs/strength.md``.
"""
from __future__ import annotations

import csv
import json
import math
from pathlib import Path
from typing import Any, Dict, Sequence, Tuple, Union

import numpy as np
from numpy.typing import NDArray

from demfem.errors import DemfemIOError, InvalidParameterError
from demfem.risk.defaults import REFERENCE_AREA
from demfem.risk.specimen_area import SURFACES
from demfem.risk.strength_fit import StrengthFit, fit_strength
from demfem.risk.surface import SurfaceStrength

__all__ = [
    "FILE_FORMAT",
    "FILE_VERSION",
    "load_strength_file",
    "read_strength_csv",
    "strength_document",
    "strength_fit_command",
    "write_strength_file",
]

#: ``format`` tag and version of a strength file.
FILE_FORMAT = "demfem-strength"
FILE_VERSION = 1

PathLike = Union[str, Path]


def read_strength_csv(path: PathLike) -> Tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Strengths (Pa) and censoring flags of a strength-data CSV file.

    Format: a header row, then one specimen per row; lines starting with ``#`` and blank lines
    are skipped. Columns: ``strength_Pa`` (Pa) or ``failure_stress_MPa`` (MPa), exactly one of
    them; optional ``censored`` (0 or 1; 1 = did not fail from the fitted flaw population);
    other columns (specimen id, notes) are ignored. Errors name the file, the line and the
    column: :class:`~demfem.errors.DemfemIOError` if unreadable,
    :class:`~demfem.errors.InvalidParameterError` for invalid content.
    """
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError) as exc:
        raise DemfemIOError(f"cannot read strength data {p}: {exc}") from None
    rows = [(i + 1, line) for i, line in enumerate(text.splitlines())
            if line.strip() and not line.lstrip().startswith("#")]
    if not rows:
        raise InvalidParameterError(f"invalid strength data {p}: no header row")
    header = [h.strip() for h in next(csv.reader([rows[0][1]]))]
    cols = [k for k in ("strength_Pa", "failure_stress_MPa") if k in header]
    if len(cols) != 1:
        raise InvalidParameterError(
            f"invalid strength data {p}: the header (line {rows[0][0]}) must have exactly one "
            f"of the columns strength_Pa, failure_stress_MPa; it has {', '.join(header)}")
    col, scale = cols[0], (1.0 if cols[0] == "strength_Pa" else 1e6)
    i_s = header.index(col)
    i_c = header.index("censored") if "censored" in header else None
    strength, cens = [], []
    for lineno, line in rows[1:]:
        cells = [x.strip() for x in next(csv.reader([line]))]
        if len(cells) != len(header):
            raise InvalidParameterError(f"invalid strength data {p}, line {lineno}: "
                                        f"{len(cells)} fields, the header has {len(header)}")
        try:
            value = float(cells[i_s])
        except ValueError:
            value = math.nan
        if not (math.isfinite(value) and value > 0.0):
            raise InvalidParameterError(f"invalid strength data {p}, line {lineno}: {col} = "
                                        f"{cells[i_s]!r}: must be a finite number > 0")
        strength.append(value * scale)
        flag = cells[i_c] if i_c is not None else "0"
        if flag not in ("0", "1"):
            raise InvalidParameterError(f"invalid strength data {p}, line {lineno}: censored = "
                                        f"{flag!r}: must be 0 or 1")
        cens.append(flag == "1")
    s, c = np.array(strength, dtype=np.float64), np.array(cens, dtype=bool)
    if int((~c).sum()) < 2:
        raise InvalidParameterError(f"invalid strength data {p}: {int((~c).sum())} failed "
                                    "(uncensored) specimen(s), at least 2 are needed")
    return s, c


def strength_document(fits: Union[StrengthFit, Sequence[StrengthFit]],
                      reference_area: float = REFERENCE_AREA) -> Dict[str, Any]:
    """The strength file's content (a JSON-ready dict, see :func:`load_strength_file`) with the
    SurfaceStrength of each fit's surface on ``reference_area`` (m²); one fit per surface."""
    items = [fits] if isinstance(fits, StrengthFit) else list(fits)
    if not items or len({f.surface for f in items}) != len(items):
        raise InvalidParameterError("invalid fits: give one StrengthFit per surface (inner, "
                                    "outer), at least one")
    surfaces = {}
    for f in items:
        ss = f.to_surface_strength(reference_area)
        surfaces[f.surface] = {"weibull_modulus": ss.weibull_modulus,
                               "characteristic_strength_Pa": ss.characteristic_strength,
                               "reference_area_m2": ss.reference_area, "source": ss.source,
                               "time_to_failure_s": f.time_to_failure_s}
    return {"format": FILE_FORMAT, "version": FILE_VERSION, "surfaces": surfaces,
            "fits": {f.surface: f.to_dict() for f in items}}


def write_strength_file(path: PathLike, fits: Union[StrengthFit, Sequence[StrengthFit]],
                        reference_area: float = REFERENCE_AREA) -> Path:
    """Write :func:`strength_document` to ``path`` (strict JSON, atomically); returns it."""
    from demfem.io.strict_json import write_json_atomic

    return write_json_atomic(path, strength_document(fits, reference_area))


def _field(path: Path, name: str, value: Any) -> float:
    """A positive finite number of the strength file, else an error naming file and field."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not (
            math.isfinite(value) and value > 0):
        raise InvalidParameterError(f"invalid strength file {path}: field {name} = {value!r}: "
                                    "must be a finite number > 0")
    return float(value)


def load_strength_file(path: PathLike) -> Dict[str, Any]:
    """Read a strength file (``demfem strength-fit --out``, or written by hand) for ``demfem
    assess --strength FILE``.

    Returns a dict:

    * ``"inner"``, ``"outer"``: :class:`SurfaceStrength` of each surface — the file's for the
      surfaces it holds, :data:`demfem.risk.defaults.INNER_SURFACE` / ``OUTER_SURFACE`` (planning
      assumptions) for the others;
    * ``"measured"``: tuple of the surfaces the file holds;
    * ``"source"``: one text naming the file and, per surface, where its numbers come from;
    * ``"time_to_failure_s"``: {surface: s} of the measured surfaces that state their test
      duration (for the slow-crack-growth reference time t_f/(n+1)); may be empty.

    The file: ``{"format": "demfem-strength", "version": 1, "surfaces": {"outer":
    {"weibull_modulus": m, "characteristic_strength_Pa": σ_0, "reference_area_m2": A_0,
    "source": "..."}}}`` (``"fits"`` optional, informative). A damaged file raises
    :class:`~demfem.errors.DemfemIOError`, invalid content
    :class:`~demfem.errors.InvalidParameterError`, each naming the file and the field.
    """
    from demfem.risk.defaults import INNER_SURFACE, OUTER_SURFACE

    p = Path(path)
    try:
        doc = json.loads(p.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise DemfemIOError(f"damaged or unreadable strength file {p}: {exc}") from None
    if not isinstance(doc, dict) or doc.get("format") != FILE_FORMAT:
        raise InvalidParameterError(f"invalid strength file {p}: field format must be "
                                    f"{FILE_FORMAT!r}")
    if doc.get("version") != FILE_VERSION:
        raise InvalidParameterError(f"invalid strength file {p}: field version = "
                                    f"{doc.get('version')!r}: must be {FILE_VERSION}")
    surfaces = doc.get("surfaces")
    if not isinstance(surfaces, dict) or not surfaces or not set(surfaces) <= set(SURFACES):
        raise InvalidParameterError(f"invalid strength file {p}: field surfaces must map "
                                    "'inner' and/or 'outer' to their Weibull parameters")
    out: Dict[str, Any] = {"inner": INNER_SURFACE, "outer": OUTER_SURFACE,
                           "measured": tuple(k for k in SURFACES if k in surfaces),
                           "time_to_failure_s": {}}
    parts = []
    for name in SURFACES:
        entry = surfaces.get(name)
        if entry is None:
            parts.append(f"{name}: default ({out[name].source})")
            continue
        if not isinstance(entry, dict):
            raise InvalidParameterError(f"invalid strength file {p}: field surfaces.{name} must "
                                        "be an object")
        vals = [_field(p, f"surfaces.{name}.{k}", entry.get(k)) for k in
                ("weibull_modulus", "characteristic_strength_Pa", "reference_area_m2")]
        src = entry.get("source")
        if not isinstance(src, str) or not src.strip():
            raise InvalidParameterError(f"invalid strength file {p}: field surfaces.{name}."
                                        "source must be a non-empty text")
        if entry.get("time_to_failure_s") is not None:
            out["time_to_failure_s"][name] = _field(p, f"surfaces.{name}.time_to_failure_s",
                                                    entry["time_to_failure_s"])
        out[name] = SurfaceStrength(weibull_modulus=vals[0], characteristic_strength=vals[1],
                                    reference_area=vals[2], source=src)
        parts.append(f"{name}: {src}")
    out["source"] = f"strength file {p}: " + "; ".join(parts)
    return out


def strength_fit_command(args: Any) -> int:
    """``demfem strength-fit``: the arguments parsed by :mod:`demfem.cli`; fits, writes the
    strength file, prints a summary; returns the exit code."""
    strength, cens = read_strength_csv(args.data)
    geometry: Dict[str, Any] = {}
    if args.test == "ring-on-ring":
        geometry = {"load_ring_diameter_m": args.load_ring_diameter,
                    "support_ring_diameter_m": args.support_ring_diameter,
                    "specimen_diameter_m": args.specimen_diameter,
                    "poisson_ratio": args.poisson_ratio}
    elif args.test in ("side-compression", "burst"):
        geometry = {"outer_diameter_m": args.outer_diameter,
                    "wall_thickness_m": args.wall_thickness, "length_m": args.length}
        if args.test == "burst":
            geometry["closed_ends"] = bool(args.closed_ends)
    else:  # "none": strengths already refer to an area; by default the reference area
        geometry = {"effective_area_m2": (args.reference_area if args.effective_area is None
                                          else args.effective_area)}
    missing = ["--" + k[:-2].replace("_", "-") for k, v in geometry.items() if v is None]
    if missing:
        raise InvalidParameterError(f"invalid geometry: --test {args.test} needs "
                                    f"{', '.join(missing)} (m)")
    fit = fit_strength(strength, cens, test=args.test, geometry=geometry, surface=args.surface,
                       criterion=args.criterion, scaling_modulus=args.modulus,
                       confidence=args.confidence, source=Path(args.data).name,
                       time_to_failure_s=args.time_to_failure, n_simulations=args.simulations,
                       seed=args.seed)
    out = Path(args.out)
    doc = strength_document(fit, args.reference_area)
    kept = []
    if args.merge and out.exists():
        from demfem.io.strict_json import write_json_atomic

        old = load_strength_file(out)           # refuses a damaged or invalid file
        raw = json.loads(out.read_text(encoding="utf-8"))
        for name in old["measured"]:
            if name != fit.surface:
                kept.append(name)
                doc["surfaces"][name] = raw["surfaces"][name]
                if isinstance(raw.get("fits"), dict) and name in raw["fits"]:
                    doc["fits"][name] = raw["fits"][name]
        write_json_atomic(out, doc)
    else:
        write_strength_file(out, fit, args.reference_area)
    ss = fit.to_surface_strength(args.reference_area)
    pct = f"{fit.confidence:.0%}"
    print(f"{fit.n} specimens from {args.data} ({fit.n_censored} censored), {fit.test} test, "
          f"{fit.surface} surface")
    print(f"  Weibull modulus m: {fit.m_unbiased:.3g} unbiased (ML {fit.m:.3g}, b = "
          f"{fit.unbiasing_factor:.3f}); {pct} bounds {fit.bounds['m'][0]:.3g} - "
          f"{fit.bounds['m'][1]:.3g}")
    lo, hi = fit.bounds["sigma_theta_Pa"]
    print(f"  characteristic strength of the specimens: {fit.sigma_theta_Pa / 1e6:.1f} MPa; "
          f"{pct} bounds {lo / 1e6:.1f} - {hi / 1e6:.1f} MPa")
    print(f"  effective area: {fit.effective_area_m2:.4g} m^2 ({fit.criterion}, m = "
          f"{fit.weibull_modulus:.3g})")
    print(f"  {fit.surface} surface: m = {ss.weibull_modulus:.3g}, sigma_0 = "
          f"{ss.characteristic_strength / 1e6:.1f} MPa on A_0 = {ss.reference_area:g} m^2")
    print(f"written: {out}" + (f" (kept the {kept[0]} surface already there)" if kept else ""))
    return 0
