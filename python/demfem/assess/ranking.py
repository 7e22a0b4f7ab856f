"""Set-ups ranked by breakage risk with intervals and tests that say whether a difference is
real: `demfem sweep ... --rank-by broken_per_hour --replicas R`.

Every set-up of the sweep's grid (e.g. belt speed 0.1, 0.2, 0.3 m/s) runs R replicas with
the seeds s, s + 1, … s + R − 1 (:mod:`demfem.scenes.perturb`): replica r of every set-up
starts from the same perturbation of its spheres (common random starts), so the replicas
pair up across set-ups. Each set-up's hourly number is pooled over its replicas with its
Student-t interval on the log scale (:func:`demfem.assess.replica_stats.ratio_interval`).

**Is a difference real?** For two set-ups A and B the statistic is the log ratio of their
pooled numbers, D = ln(Σ Y_A/Σ H_A) − ln(Σ Y_B/Σ H_B). The default test (``"log-t"``)
linearises D per pair, as the intervals do, u_r = (Y_A,r − R_A H_A,r)/(R_A H̄_A) −
(Y_B,r − R_B H_B,r)/(R_B H̄_B), and takes t = D / (sd(u)/√R) with R − 1 degrees of freedom
(two-sided), which also gives the ratio's interval. The sign-flip permutation test
(``"sign-flip"``) takes the same |D| and its distribution from swapping A and B within
every pair (all 2^R swaps for R ≤ 16, else 20 000 drawn): exact under the null of
exchangeable pairs whatever the distribution, but its smallest p is 2/2^R, so it needs
R ≥ 6 for one comparison at 5 % and more after a correction; it is used where a set-up has
no hazard at all (no log). On synthetic heavy-tailed replicas (a period's hazard with a CV
of 2, three set-ups, 400 sweeps each) the log-t's family-wise error was 0.04–0.065 for
R = 4–16 and it found a 3× difference in 8, 26, 52, 73, 91 % of sweeps at R = 4, 6, 8, 10,
16, the sign-flip in 0, 0, 38, 62, 90 %, a paired t on the replicas' log rates (the
geometric mean) in 6–58 % (its error 0.02: conservative). Pairing is valid whether or not
the common starts make the pairs correlated (the DEM is chaotic: after the warm-up they
hardly are); it gains power only where they are, and each test reports the correlation of
the paired log rates.

All k(k − 1)/2 pairs of set-ups are tested and the p-values Holm-corrected together, so the
family-wise error over every statement is at most ``alpha`` even though the best set-up is
picked from the same data; each set-up's row then says whether its difference to the best
is significant. ``tests/python/test_ranking.py`` checks the error rate and the power on
synthetic heavy-tailed replicas. SI units; rates per hour.
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Mapping, Optional, Sequence

import numpy as np
from scipy import stats

from demfem.errors import InvalidParameterError, check_count, check_range

__all__ = ["TESTS", "paired_test", "holm", "rank_setups", "Ranking", "replica_point",
           "ranked_sweep", "RISK_RUNNER", "REPLICA_RUNNER"]

#: Paired tests: the default first.
TESTS = ("log-t", "sign-flip")
#: The plain risk runner of ``demfem sweep``, and the one that takes a seed.
RISK_RUNNER = "demfem.assess.sweep_runner:risk_point"
REPLICA_RUNNER = "demfem.assess.ranking:replica_point"
_EXACT_MAX = 16
_DRAWS = 20_000


def _as_pairs(name: str, a: Any, b: Any) -> tuple[np.ndarray, np.ndarray]:
    x, y = np.asarray(a, float), np.asarray(b, float)
    if x.ndim != 1 or x.shape != y.shape or len(x) < 2:
        raise InvalidParameterError(f"invalid {name}: two equally long lists of at least 2 "
                                    f"paired replicas are needed (got {x.shape}, {y.shape})")
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(y))):
        raise InvalidParameterError(f"invalid {name}: every value must be finite")
    return x, y


def paired_test(y_a: Sequence[float] | np.ndarray, h_a: Sequence[float] | np.ndarray,
                y_b: Sequence[float] | np.ndarray, h_b: Sequence[float] | np.ndarray,
                method: Optional[str] = None,
                seed: int = 0) -> dict[str, Any]:
    """Two-sided test of "set-ups A and B break as often" from R paired replicas.

    Args:
        y_a, h_a, y_b, h_b: (R,) each replica's expected breakages Y ≥ 0 and hours H > 0
            (rate = Y / H), replica r of A paired with replica r of B.
        method: ``"log-t"`` (the pooled log ratio's paired t) or ``"sign-flip"``
            (permutation), see the module text; None: ``"log-t"`` unless a set-up's pooled
            rate is 0.
        seed: for the drawn sign flips (R > 16).

    Returns:
        ``p_value``, ``method``, ``n_pairs``, ``log_ratio`` (ln of the pooled rates' ratio
        A/B), ``ratio`` (A/B pooled), ``correlation`` (of the pairs' log rates; NaN when a
        rate is 0 or R < 3); with ``"log-t"`` also ``t``, ``dof`` and the ratio's 95 %
        interval ``ratio_lower``, ``ratio_upper``; with ``"sign-flip"`` ``smallest_p``.
    """
    ya, yb = _as_pairs("numerators", y_a, y_b)
    ha, hb = _as_pairs("denominators", h_a, h_b)
    if ya.shape != ha.shape or np.any(ya < 0) or np.any(yb < 0) or np.any(ha <= 0) \
            or np.any(hb <= 0):
        raise InvalidParameterError("invalid replicas: expected breakages must be >= 0 and "
                                    "hours > 0, one of each per replica of each set-up")
    n = len(ya)
    pa, pb = ya.sum() / ha.sum(), yb.sum() / hb.sum()
    if method is None:
        method = "log-t" if pa > 0 and pb > 0 else "sign-flip"
    if method not in TESTS:
        raise InvalidParameterError(f"invalid method = {method!r}: must be one of {TESTS}")
    if method == "log-t" and not (ya.sum() > 0 and yb.sum() > 0):
        raise InvalidParameterError("invalid method = 'log-t': a set-up without any "
                                    "breakage hazard has no log rate; use 'sign-flip'")
    with np.errstate(divide="ignore"):
        log_ratio = float(np.log(pa) - np.log(pb)) if pa > 0 or pb > 0 else 0.0
    ra, rb = ya / ha, yb / hb
    corr = math.nan
    if n > 2 and np.all(ra > 0) and np.all(rb > 0):
        la, lb = np.log(ra), np.log(rb)
        if np.std(la) > 0 and np.std(lb) > 0:
            corr = float(np.corrcoef(la, lb)[0, 1])
    out: dict[str, Any] = {"method": method, "n_pairs": n, "log_ratio": log_ratio,
                           "ratio": float(pa / pb) if pb > 0 else math.inf,
                           "correlation": corr}
    if method == "log-t":
        # the pooled rates' log ratio, linearised per pair (the intervals' delta method)
        ua = (ya - pa * ha) / (pa * ha.mean())
        ub = (yb - pb * hb) / (pb * hb.mean())
        sd = float(np.std(ua - ub, ddof=1))
        tq = float(stats.t.ppf(0.975, n - 1))
        if sd > 0:
            t = log_ratio / (sd / math.sqrt(n))
            p = float(2.0 * stats.t.sf(abs(t), n - 1))
        else:
            t, p = (0.0, 1.0) if log_ratio == 0 else (math.copysign(math.inf, log_ratio), 0.0)
        half = tq * sd / math.sqrt(n)
        out.update(p_value=p, t=t, dof=n - 1, ratio_lower=math.exp(log_ratio - half),
                   ratio_upper=math.exp(log_ratio + half))
        return out
    # sign flips: swap A and B within a pair (mask 1 = swapped)
    if n <= _EXACT_MAX:
        masks = ((np.arange(2 ** n)[:, None] >> np.arange(n)) & 1).astype(bool)
    else:
        masks = np.random.default_rng(seed).random((_DRAWS, n)) < 0.5
    sa = np.where(masks, yb, ya).sum(axis=1) / np.where(masks, hb, ha).sum(axis=1)
    sb = np.where(masks, ya, yb).sum(axis=1) / np.where(masks, ha, hb).sum(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        stat = np.abs(np.log(sa) - np.log(sb))
    stat = np.where(np.isnan(stat), 0.0, stat)           # both 0: no difference
    observed = abs(log_ratio)
    extreme = int(np.sum(stat >= observed * (1.0 - 1e-12)))
    p = extreme / len(masks) if n <= _EXACT_MAX else (extreme + 1) / (len(masks) + 1)
    out.update(p_value=float(min(1.0, p)), smallest_p=2.0 / 2 ** n if n <= _EXACT_MAX
               else 1.0 / (_DRAWS + 1))
    return out


def holm(p_values: Sequence[float]) -> np.ndarray:
    """Holm's step-down adjusted p-values (family-wise error control), in the input order."""
    p = np.asarray(p_values, float)
    if p.ndim != 1 or np.any(~np.isfinite(p)) or np.any((p < 0) | (p > 1)):
        raise InvalidParameterError("invalid p_values: a list of numbers in [0, 1]")
    m = len(p)
    order = np.argsort(p, kind="stable")
    adj = np.minimum(1.0, (m - np.arange(m)) * p[order])
    adj = np.maximum.accumulate(adj)
    out = np.empty(m)
    out[order] = adj
    return out


@dataclass(frozen=True)
class Ranking:
    """Set-ups ranked lowest first: ``rows`` (each set-up's label, parameters, pooled
    number, interval, ratio to the best, Holm-adjusted p of that difference and
    ``significant``), ``pairs`` (every pairwise test), ``alpha``, ``by``."""

    rows: list[dict[str, Any]]
    pairs: list[dict[str, Any]]
    alpha: float
    by: str
    notes: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        """Strict-JSON data (``ranking.json``)."""
        from demfem.io.strict_json import finite_or_none

        return finite_or_none({"by": self.by, "alpha": self.alpha, "rows": self.rows,
                               "pairs": self.pairs, "notes": self.notes}, default=str)

    def text(self) -> str:
        """The ranking as the console shows it."""
        conf = self.rows[0]["interval"]["confidence"] if self.rows else 0.95
        lines = [f"ranked by {self.by} (lowest first), {conf:.0%} intervals over the "
                 f"replicas; difference to the best: paired test, Holm-corrected over all "
                 f"{len(self.pairs)} pairs, alpha = {self.alpha:g}:"]
        for k, r in enumerate(self.rows, 1):
            iv = r["interval"]
            lo, hi = iv.get("lower"), iv.get("upper")
            span = (f"[{lo:.3g}, {hi:.3g}]" if lo is not None and hi is not None
                    and math.isfinite(lo) and math.isfinite(hi) else f"[{iv['status']}]")
            verdict = ("best" if k == 1 else
                       f"x{r['ratio_to_best']:.3g} the best, p = {r['p_vs_best']:.3g}: "
                       + ("REAL difference" if r["significant"] else "not significant"))
            lines.append(f"  {k:3d}  {r['label']}  {self.by} = {r['estimate']:.4g} {span} "
                         f"({r['n_replicas']} replicas)  {verdict}")
        lines += [f"  note: {n}" for n in self.notes]
        return "\n".join(lines)


def rank_setups(setups: Mapping[str, Sequence[Mapping[str, Any]]], *, by: str = "broken_per_hour",
                alpha: float = 0.05, confidence: float = 0.95, method: Optional[str] = None,
                params: Optional[Mapping[str, Mapping[str, Any]]] = None) -> Ranking:
    """Rank set-ups by their pooled number over paired replicas (module text).

    Args:
        setups: label → its replicas' records, each with ``seed`` and either
            ``expected_broken`` and ``hours`` (:func:`demfem.assess.replica_stats.
            replica_numbers`; rate = Y/H, pooled Σ Y/Σ H) or the value ``by`` (pooled: the
            mean). Replicas pair by seed; seeds missing from a set-up leave its tests.
        by: the number ranked (lowest first).
        alpha: family-wise error of the significance statements, in (0, 1).
        confidence: the intervals' coverage, in (0, 1).
        method: the paired test (:data:`TESTS`), or None to choose per pair.
        params: label → the set-up's parameters, for the rows.
    """
    from demfem.assess.replica_stats import ratio_interval

    a = check_range("alpha", alpha, 0.0, 1.0)
    if method is not None and method not in TESTS:
        raise InvalidParameterError(f"invalid method = {method!r}: must be one of {TESTS}")
    if len(setups) < 2:
        raise InvalidParameterError(f"invalid setups: {len(setups)} set-up(s); a ranking "
                                    "needs at least 2")
    use_ratio = by == "broken_per_hour" and all(
        "expected_broken" in r and "hours" in r for recs in setups.values() for r in recs)
    series: dict[str, dict[int, tuple[float, float]]] = {}
    for label, recs in setups.items():
        got: dict[int, tuple[float, float]] = {}
        for r in recs:
            if use_ratio:
                got[int(r["seed"])] = (float(r["expected_broken"]), float(r["hours"]))
            elif by in r:
                got[int(r["seed"])] = (float(r[by]), 1.0)
            else:
                raise InvalidParameterError(f"invalid by = {by!r}: not a result of set-up "
                                            f"{label} (results: {sorted(r)})")
        if not got:
            raise InvalidParameterError(f"invalid setups: set-up {label} has no replica")
        series[label] = got
    rows: list[dict[str, Any]] = []
    for label, got in series.items():
        y, h = (np.array([got[s][i] for s in sorted(got)]) for i in (0, 1))
        iv = ratio_interval(y, h, confidence)
        rows.append({"label": label, "params": dict((params or {}).get(label, {})),
                     "estimate": iv.estimate, "interval": iv.to_dict(),
                     "n_replicas": len(got), "seeds": sorted(got)})
    rows.sort(key=lambda r: r["estimate"])
    notes: list[str] = []
    pairs: list[dict[str, Any]] = []
    for x, z in itertools.combinations(range(len(rows)), 2):
        la, lb = rows[x]["label"], rows[z]["label"]
        common = sorted(set(series[la]) & set(series[lb]))
        entry: dict[str, Any] = {"a": la, "b": lb, "n_pairs": len(common)}
        if len(common) < 2:
            entry.update(p_value=1.0, method=None, note="fewer than 2 paired replicas")
        else:
            ya, ha = (np.array([series[la][s][i] for s in common]) for i in (0, 1))
            yb, hb = (np.array([series[lb][s][i] for s in common]) for i in (0, 1))
            entry.update(paired_test(ya, ha, yb, hb, method))
        pairs.append(entry)
    adj = holm([p["p_value"] for p in pairs]) if pairs else np.zeros(0)
    for p, q in zip(pairs, adj):
        p["p_holm"] = float(q)
        p["significant"] = bool(q < a)
    best = rows[0]["label"]
    for r in rows:
        if r["label"] == best:
            r.update(ratio_to_best=1.0, p_vs_best=None, significant=None)
            continue
        pair = next(p for p in pairs if {p["a"], p["b"]} == {best, r["label"]})
        r.update(ratio_to_best=(r["estimate"] / rows[0]["estimate"]
                                if rows[0]["estimate"] > 0 else math.inf),
                 p_vs_best=pair["p_holm"], significant=pair["significant"])
    if any(p.get("method") == "sign-flip" and p.get("smallest_p", 0) * len(pairs) >= a
           for p in pairs):
        notes.append("some pairs were tested by sign flips, which with this few replicas "
                     "cannot reach significance after the Holm correction: add replicas")
    if min(r["n_replicas"] for r in rows) < 5:
        notes.append("fewer than 5 replicas per set-up: wide intervals and little power "
                     "(docs/replicas.md)")
    return Ranking(rows, pairs, a, by, notes)


def replica_point(params: dict) -> dict:
    """Sweep runner: :func:`demfem.assess.sweep_runner.risk_point` with a ``seed`` (the
    replica's perturbed start); returns its numbers with ``expected_broken``, ``hours``,
    ``window_s`` and ``seed`` (:func:`demfem.assess.replica_stats.replica_numbers`)."""
    from demfem.assess import run as assess_run
    from demfem.assess.replica_stats import replica_numbers
    from demfem.assess.sweep_runner import SweepPoint, sweep_point

    point = sweep_point(params, ("seed",), prefix="demfem_replica_")
    try:
        seed = check_count("seed", point.extra.get("seed", 0), 0)
        risk = assess_run.assess(point.table, out=point.out, stop_after="risk",
                                 log=lambda line: None, seed=seed, duration=point.duration,
                                 throughput=point.throughput)
    finally:
        point.remove_temporary()
    res = SweepPoint.numbers(risk)
    nums = replica_numbers(risk)
    res.update(seed=seed, expected_broken=nums["expected_broken"], hours=nums["hours"],
               window_s=nums["window_s"])
    return res


def ranked_sweep(grid: Mapping[str, Sequence[Any]], runner: str | Callable[[dict], dict],
                 out: str | Path, replicas: int, *, rank_by: str = "broken_per_hour",
                 seed: int = 0, scheduler: Optional[str] = None,
                 n_workers: Optional[int] = None, alpha: float = 0.05,
                 confidence: float = 0.95, method: Optional[str] = None,
                 keep_runs: bool = True,
                 progress: Optional[Callable[[int, int], None]] = None) -> Ranking:
    """A sweep over ``grid`` with ``replicas`` paired replicas per set-up (seeds ``seed`` …
    ``seed + replicas − 1``) through :func:`demfem.sweep.sweep` (Dask; finished points are
    reused), ranked by :func:`rank_setups`; writes ``out/ranking.json``.

    ``runner``: :data:`RISK_RUNNER` is run as :data:`REPLICA_RUNNER` (which takes the seed);
    any other runner must accept a ``seed`` parameter. With ``keep_runs`` every point's
    assessment stays in ``out/points/<key>`` (resumable mid-run); else in a temporary
    folder.
    """
    from demfem.io.strict_json import write_json_atomic
    from demfem.sweep import sweep

    r = check_count("replicas", replicas, 1)
    s0 = check_count("seed", seed, 0)
    if "seed" in grid:
        raise InvalidParameterError("invalid grid: 'seed' is set by --replicas (the replicas' "
                                    "seeds are seed ... seed + replicas - 1); remove it")
    names = list(grid)
    # the set-ups are labelled by what varies (every parameter stays in the rows' params)
    varying = [n for n in names if len(grid[n]) > 1] or names
    full = {**grid, "seed": list(range(s0, s0 + r))}
    spec = REPLICA_RUNNER if runner == RISK_RUNNER else runner
    fixed = {"run_dir": str(Path(out) / "points")} if keep_runs and spec == REPLICA_RUNNER \
        else None
    res = sweep(full, spec, out, scheduler=scheduler, n_workers=n_workers, fixed=fixed,
                progress=progress)
    setups: dict[str, list[dict[str, Any]]] = {}
    params: dict[str, dict[str, Any]] = {}
    for rec in res.records:
        label = ", ".join(f"{n}={rec['params'][n]}" for n in varying)
        setups.setdefault(label, []).append({**rec["result"], "seed": rec["params"]["seed"]})
        params[label] = {n: rec["params"][n] for n in names}
    ranking = rank_setups(setups, by=rank_by, alpha=alpha, confidence=confidence,
                          method=method, params=params)
    write_json_atomic(Path(out) / "ranking.json", ranking.to_dict())
    return ranking
