"""Do the intervals of a short assessment hold what a long run then observes? Issue 41's check
on held-back periods of one long run of the table in operation.

A long assessment (``demfem assess --duration 62 --out RUN``: 30 gate periods after the 2-s
warm-up) is cut into non-overlapping short windows of ``k`` whole gate periods (k = 4 and 7 by
default: the default job's steady rule needs at least 4, and reaches 7 on the default table).
On each window, with that window's events only:

* **the hourly number's interval**, as ``demfem assess`` makes it (per-event hazard
  h = −ln(1 − P) times the cartridges it loads, block totals over whole gate periods,
  Student-t on the log scale: :func:`demfem.risk.interval.rate_interval`), is compared with
  the hourly number of the **held-back periods** (every other whole period of the run). The
  window's interval *covers* when the held-back number lies inside it.
* **the rare-period check** (:func:`demfem.risk.rare_periods.period_dominance`, what
  ``risk.json``'s ``period_check`` and the report say): whether one period of the window
  dominates its hazard (a jam), and otherwise how rare such periods must be for the window
  to have missed them.
* **the tail model** (:func:`demfem.risk.tail.fit_tail` on the window's cartridge–cartridge
  peak forces, threshold by the documented diagnostic) predicts how often an impact harder
  than the hardest of the window happens (:func:`~demfem.risk.tail.expected_beyond` with a
  unit hazard, its interval over parameter draws); the held-back periods then count such
  impacts. The prediction *covers* when the count lies in the Poisson predictive interval
  of the predicted rate's interval over the held-back time.

Held-back numbers are themselves estimates (about 23–26 periods); their own interval is
given beside them. The result goes to ``docs/data/interval_coverage.json`` and a table to
stdout.

    demfem assess --duration 62 --out demfem_out/long --no-reports   # (about 50 min, 2 cores)
    python benches/interval_coverage.py demfem_out/long
"""
from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any

import numpy as np
from scipy import stats

from demfem.assess.tables import load_assessment
from demfem.errors import InvalidParameterError
from demfem.io.strict_json import write_json_atomic
from demfem.risk.interval import rate_interval
from demfem.risk.rare_periods import period_dominance
from demfem.risk.tail import expected_beyond, fit_tail

OUT = Path(__file__).resolve().parent.parent / "docs" / "data" / "interval_coverage.json"


def _poisson_covers(count: int, lo_rate: float, hi_rate: float, seconds: float,
                    confidence: float = 0.95) -> bool:
    """Does ``count`` lie in the Poisson predictive interval of a rate in [lo, hi] over
    ``seconds``?"""
    a = (1.0 - confidence) / 2.0
    lo = stats.poisson.ppf(a, lo_rate * seconds) if lo_rate > 0 else 0.0
    hi = stats.poisson.ppf(1.0 - a, hi_rate * seconds) if math.isfinite(hi_rate) else math.inf
    return bool(lo <= count <= hi)


def windows_check(times: np.ndarray, h: np.ndarray, force: np.ndarray, pair: np.ndarray,
                  start: float, period: float, n_periods: int, k: int) -> list[dict[str, Any]]:
    """The rows of the check for windows of ``k`` periods (module docstring)."""
    end = start + n_periods * period
    run_check = period_dominance(times, h, (start, end), period)
    jam = np.zeros(times.shape, bool)         # the whole run's dominant periods
    for d in run_check.dominant:
        jam |= (times >= start + d * period) & (times < start + (d + 1) * period)
    out: list[dict[str, Any]] = []
    for i in range(n_periods // k):
        a, b = start + i * k * period, start + (i + 1) * k * period
        inside = (times >= a) & (times < b)
        held = (times >= start) & (times < end) & ~inside
        w_held = (n_periods - k) * period
        ci = rate_interval(times[inside], h[inside], (a, b), period, scale=3600.0)
        truth = 3600.0 * float(h[held].sum()) / w_held
        # the held-back periods' own interval (their blocks, the window's gap closed)
        t_held = np.where(times[held] >= b, times[held] - k * period, times[held])
        ci_held = rate_interval(t_held, h[held], (start, start + w_held), period, scale=3600.0)
        row: dict[str, Any] = {
            "window_s": [a, b], "estimate_per_h": ci.estimate, "lower_per_h": ci.lower,
            "upper_per_h": ci.upper, "factor": ci.factor, "held_back_per_h": truth,
            "held_back_lower_per_h": ci_held.lower, "held_back_upper_per_h": ci_held.upper,
            "covers": bool(ci.lower <= truth <= ci.upper)}
        dom = period_dominance(times[inside], h[inside], (a, b), period)
        # the held-back ordinary periods: without the run's dominant ones
        held_o = held & ~jam
        w_o = w_held - period * sum(1 for d in run_check.dominant
                                    if not a <= start + d * period < b)
        truth_o = 3600.0 * float(h[held_o].sum()) / w_o
        row["held_back_ordinary_per_h"] = truth_o
        row["covers_ordinary"] = bool(ci.lower <= truth_o <= ci.upper)
        row["period_check"] = {"dominated": dom.dominated,
                               "largest_over_median": dom.largest_over_median,
                               "largest_share": dom.largest_share,
                               "unseen_bound": dom.unseen_bound}
        f_win = force[inside & pair]
        try:
            model = fit_tail(f_win, b - a)
            beyond = expected_beyond(model, lambda f: np.ones_like(np.asarray(f, float)))
            n_obs = int(np.count_nonzero(held & pair & (force > model.max_value)))
            row["tail"] = {
                "threshold_N": model.threshold, "shape": model.shape, "shape_se": model.shape_se,
                "n_exceedances": model.n_exceedances, "largest_N": model.max_value,
                "predicted_per_s": beyond.estimate, "predicted_lower_per_s": beyond.lower,
                "predicted_upper_per_s": beyond.upper, "held_back_count": n_obs,
                "held_back_per_s": n_obs / w_held,
                "covers": _poisson_covers(n_obs, beyond.lower, beyond.upper, w_held)}
        except InvalidParameterError as exc:
            row["tail"] = {"status": f"no fit: {exc}"}
        out.append(row)
    return out


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("run", help="a finished demfem assess folder of a long run")
    p.add_argument("--warmup", type=float, default=2.0, help="start of the periods, s (2)")
    p.add_argument("--period", type=float, default=None,
                   help="gate period, s (default: the run's scene)")
    p.add_argument("--periods", type=int, nargs="+", default=[4, 7],
                   help="window lengths in gate periods (4 7)")
    p.add_argument("--out", default=str(OUT), help="result file")
    a = p.parse_args()
    run = load_assessment(a.run)
    ev = run.events
    period = a.period
    if period is None:
        period = float(run.risk["settings"]["scene"]["gate_period"])
    times = ev["time_s"].to_numpy(float)
    loads = np.where(ev["j"].to_numpy() >= 0, 2.0, 1.0)
    h = -np.log1p(-ev["p_event"].to_numpy(float)) * loads
    force = ev["force_N"].to_numpy(float)
    pair = (ev["partner"] == "sphere").to_numpy()
    end = float(run.risk["window_s"][1])
    n_periods = int(math.floor((end - a.warmup) / period + 1e-9))
    doc: dict[str, Any] = {"run": str(a.run), "period_s": period, "warmup_s": a.warmup,
                           "n_periods": n_periods, "windows": {}}
    whole = rate_interval(times, h, (a.warmup, a.warmup + n_periods * period), period,
                          scale=3600.0)
    doc["whole_run_per_h"] = [whole.estimate, whole.lower, whole.upper]
    print(f"{n_periods} periods of {period:g} s after {a.warmup:g} s: {whole.estimate:.3g} "
          f"per hour [{whole.lower:.3g}, {whole.upper:.3g}] (log-t over the periods)")
    for k in a.periods:
        rows = windows_check(times, h, force, pair, a.warmup, period, n_periods, k)
        covered = sum(r["covers"] for r in rows)
        tails = [r["tail"] for r in rows if "covers" in r["tail"]]
        flagged = sum(r["period_check"]["dominated"] for r in rows)
        quiet = [r for r in rows if not r["period_check"]["dominated"]]
        cov_o = sum(r["covers_ordinary"] for r in quiet)
        doc["windows"][str(k)] = {"rows": rows, "covered": covered, "n": len(rows),
                                  "flagged_dominated": flagged,
                                  "unflagged_covering_ordinary": cov_o,
                                  "unflagged": len(quiet),
                                  "tail_covered": sum(t["covers"] for t in tails),
                                  "tail_n": len(tails)}
        print(f"\nwindows of {k} periods: the interval holds the held-back number in "
              f"{covered} of {len(rows)}; the tail model's prediction in "
              f"{sum(t['covers'] for t in tails)} of {len(tails)}; {flagged} window(s) "
              "flagged as dominated by one period; the unflagged windows' intervals hold the "
              f"held-back ordinary periods' number (the run's dominant periods left out) in "
              f"{cov_o} of {len(quiet)}")
        print("  window s      estimate  95 % interval          factor  held back [its 95 %]"
              "            tail: beyond largest, predicted /s [95 %]  held back count")
        for r in rows:
            t = r["tail"]
            tail = (f"{t['predicted_per_s']:.3g} [{t['predicted_lower_per_s']:.3g}, "
                    f"{t['predicted_upper_per_s']:.3g}]  {t['held_back_count']} in "
                    f"{(n_periods - k) * period:g} s" if "covers" in t else t["status"])
            print(f"  {r['window_s'][0]:5.1f}-{r['window_s'][1]:5.1f}  {r['estimate_per_h']:.3g}"
                  f"  [{r['lower_per_h']:.3g}, {r['upper_per_h']:.3g}]  x{r['factor']:.1f}  "
                  f"{r['held_back_per_h']:.3g} [{r['held_back_lower_per_h']:.3g}, "
                  f"{r['held_back_upper_per_h']:.3g}]  {'in ' if r['covers'] else 'OUT'}  {tail}"
                  f"  largest period x{r['period_check']['largest_over_median']:.3g} the median"
                  + ("  DOMINATED" if r["period_check"]["dominated"] else ""))
    Path(a.out).parent.mkdir(parents=True, exist_ok=True)
    write_json_atomic(a.out, doc)
    print(f"\n-> {a.out}")


if __name__ == "__main__":
    main()
