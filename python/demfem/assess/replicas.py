"""`demfem assess --replicas N`: N independent copies of the table in operation on Dask, merged
into one hourly number with a confidence interval from their scatter.

Each replica is an ordinary :func:`demfem.assess.assess` in ``out/replica_<k>`` started from
its own perturbed start (``seed + k``, :mod:`demfem.scenes.perturb`), so each is resumable on
its own through its own stage record, and an interrupted or killed replica costs only its
own unfinished part. They run on a :class:`distributed.LocalCluster` (one single-threaded
worker process per core) or on an existing scheduler (``scheduler="tcp://host:8786"``; the
workers need demfem installed and ``out`` on a file system they share), or in this process
(``scheduler="serial"``). ``out/replicas.json`` records the settings, every replica's seed,
numbers and state, and the merged result (:mod:`demfem.assess.replica_stats`):

    broken per hour = Σ_r Y_r / Σ_r H_r

(Y_r the replica's expected broken cartridges over its window, H_r the hours that window
stands for) with the Student-t interval on the log scale over the replicas. With
``precision``, replicas are added in batches of the worker count until the interval's
half-width is at most that fraction of the number, or ``max_replicas`` is reached.

Faults: a replica that fails (a numerical failure, a killed worker after Dask's retries, a
damaged folder) is recorded with its error while the others go on; the call then raises
:class:`ReplicaFailedError` naming it, and the same call again resumes only what is
missing, ending with the numbers of an uninterrupted run. Bad arguments and folders with
other settings are refused before anything runs, or, found by a replica, stop the whole
set naming the replica. SI units: s, m; rates per hour.
"""
from __future__ import annotations

import dataclasses
import logging
import os
import socket
import time
from pathlib import Path
from typing import Any, Callable, Optional

from demfem.assess.replica_stats import (PRECISION_MIN_REPLICAS,
                                         PRECISION_SPREAD_CONFIDENCE)
from demfem.errors import (DemfemError, InvalidParameterError, OtherJobError,
                           SettingsMismatchError, check_count, check_positive, check_range)

__all__ = ["assess_replicas", "run_replica", "ReplicaFailedError", "SchedulerError",
           "COMMAND", "REPLICAS_FILE", "DEFAULT_MAX_REPLICAS", "replica_name"]

#: The job's name in ``replicas.json`` and in its folder's lock.
COMMAND = "demfem assess --replicas"
#: The record of a set of replicas, in its output folder.
REPLICAS_FILE = "replicas.json"
#: Most replicas ``precision`` adds up to, by default.
DEFAULT_MAX_REPLICAS = 64
#: Arguments of :func:`demfem.assess.assess` that the replicas set themselves.
_OWN = ("scene", "out", "seed", "fresh", "log", "progress", "stop_after")
#: Errors that a replica finds for every replica alike: they stop the whole set.
_FATAL = (InvalidParameterError, SettingsMismatchError)


class ReplicaFailedError(DemfemError):
    """One or more replicas failed while the others finished; the message names each with
    its error. The same call again resumes them."""


class SchedulerError(DemfemError):
    """The Dask scheduler named could not be reached (or the cluster not started)."""


def replica_name(k: int) -> str:
    """The folder name of replica ``k``: ``replica_<k>``."""
    return f"replica_{k}"


def run_replica(table: Any, folder: str, seed: int, assess_kwargs: dict[str, Any],
                fresh: bool = False, report: bool = True) -> dict[str, Any]:
    """One replica (runs on a Dask worker): :func:`demfem.assess.assess` of ``table`` in
    ``folder`` with ``seed`` (up to its risk stage without ``report``), its log appended to
    ``<folder>.log``; returns its numbers
    (:func:`demfem.assess.replica_stats.replica_numbers`) with ``seed``, ``folder``,
    ``wall_s`` and ``cpu_s`` (this call's wall and CPU time, s; far apart on a machine that
    other jobs load) and ``reused`` (nothing was left to run). An error is raised
    again with the replica's name and seed in front of its message."""
    from demfem.assess import run as assess_run
    from demfem.assess.replica_stats import replica_numbers

    path = Path(folder)
    name = path.name
    risk_file = path / "risk.json"
    before = risk_file.stat().st_mtime_ns if risk_file.exists() else None
    path.parent.mkdir(parents=True, exist_ok=True)
    t0, c0 = time.perf_counter(), time.process_time()
    with open(f"{folder}.log", "a", encoding="utf-8") as log_file:
        def log(line: str) -> None:
            log_file.write(line + "\n")
            log_file.flush()

        log(f"== {name}: seed {seed} ({time.strftime('%Y-%m-%d %H:%M:%S')}, process "
            f"{os.getpid()} on {socket.gethostname()})")
        try:
            kwargs = dict(assess_kwargs, seed=int(seed), fresh=fresh, log=log,
                          stop_after=None if report else "risk")
            risk = assess_run.assess(table, out=path, **kwargs)
        except DemfemError as exc:
            log(f"failed: {type(exc).__name__}: {exc}")
            message = f"{name} (seed {seed}, {folder}): {exc}"
            try:
                again = type(exc)(message)
            except Exception:  # noqa: BLE001 - a class with another signature
                again = ReplicaFailedError(message)
            raise again from None
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    numbers = replica_numbers(risk)
    numbers.update(name=name, seed=int(seed), folder=str(folder), wall_s=wall, cpu_s=cpu,
                   reused=before is not None and risk_file.stat().st_mtime_ns == before)
    return numbers


def _check_arguments(replicas: Any, precision: Any, max_replicas: Any, seed: Any,
                     n_workers: Any, confidence: Any, connect_timeout: Any,
                     assess_kwargs: dict[str, Any]) -> tuple[int, Optional[float], int]:
    n = check_count("replicas", replicas, 1)
    p = None if precision is None else check_positive("precision", precision)
    m = check_count("max_replicas", max_replicas, 1)
    if p is not None and m < max(n, 2):
        raise InvalidParameterError(f"invalid max_replicas = {m}: must be at least replicas "
                                    f"= {n} and at least 2 (an interval needs two)")
    check_count("seed", seed, 0)
    if n_workers is not None:
        check_count("n_workers", n_workers, 1)
    check_range("confidence", confidence, 0.0, 1.0)
    check_positive("connect_timeout", connect_timeout)
    own = sorted(set(assess_kwargs) & set(_OWN))
    if own:
        raise InvalidParameterError(
            f"invalid assess argument(s) {own}: the replicas set {', '.join(_OWN)} "
            "themselves (the folder is out/replica_<k>, the seed seed + k)")
    return n, p, m


def _plain(value: Any) -> Any:
    """A setting as strict-JSON data (a stress model by its dict, a path as text)."""
    if hasattr(value, "to_dict"):
        return value.to_dict()
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return dataclasses.asdict(value)
    if isinstance(value, Path):
        return str(value)
    return value


def _read_record(out: Path) -> Optional[dict[str, Any]]:
    import json

    from demfem.errors import CheckpointError

    path = out / REPLICAS_FILE
    if not path.exists():
        return None
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
        if doc.get("command") != COMMAND or not isinstance(doc.get("settings"), dict):
            raise ValueError("not a record of demfem assess --replicas")
        return doc
    except (ValueError, UnicodeDecodeError, AttributeError) as exc:
        raise CheckpointError(f"damaged replica record {path}: {exc}; start afresh "
                              "(fresh=True, demfem assess --replicas N --fresh)") from None


class _Runner:
    """Where the replicas run: this process, a LocalCluster or a scheduler's cluster."""

    def __init__(self, scheduler: Optional[str], n_workers: Optional[int], wanted: int,
                 timeout: float) -> None:
        self.client = self.cluster = None
        self.workers = 1
        if scheduler == "serial":
            return
        try:
            from distributed import Client, LocalCluster
        except ImportError as exc:  # pragma: no cover - a dependency of demfem
            raise SchedulerError(f"dask.distributed is not installed ({exc}); use "
                                 "scheduler='serial'") from None
        if scheduler is None:
            self.workers = n_workers or max(1, min(wanted, os.cpu_count() or 1))
            try:
                self.cluster = LocalCluster(n_workers=self.workers, threads_per_worker=1,
                                            processes=True, dashboard_address=None,
                                            silence_logs=logging.ERROR)
                self.client = Client(self.cluster, timeout=timeout)
            except Exception as exc:  # noqa: BLE001 - any failure to start is one error
                self.close()
                raise SchedulerError(f"could not start a Dask LocalCluster of {self.workers} "
                                     f"workers: {exc}") from None
            return
        if not isinstance(scheduler, str) or not scheduler.strip():
            raise InvalidParameterError(f"invalid scheduler = {scheduler!r}: must be None (a "
                                        "LocalCluster), 'serial' or an address such as "
                                        "'tcp://10.0.0.5:8786'")
        try:
            self.client = Client(scheduler, timeout=timeout)
        except Exception as exc:  # noqa: BLE001 - OSError, TimeoutError, ValueError
            raise SchedulerError(
                f"cannot reach the Dask scheduler {scheduler!r} within {timeout:g} s ({exc}); "
                "check the address and that the scheduler runs (dask scheduler), or run on "
                "this machine (no scheduler: a LocalCluster)") from None
        self.workers = max(1, len(self.client.scheduler_info().get("workers", {})))

    def run(self, jobs: list[tuple[int, tuple]], done: Callable[[int, Any], None],
            failed: Callable[[int, BaseException], None]) -> None:
        """Run ``run_replica(*args)`` for every (k, args); ``done(k, record)`` or
        ``failed(k, error)`` as each ends. A fatal error cancels the rest and is raised."""
        if self.client is None:
            for k, args in jobs:
                try:
                    done(k, run_replica(*args))
                except _FATAL:
                    raise
                except Exception as exc:  # noqa: BLE001 - recorded, the others go on
                    failed(k, exc)
            return
        from distributed import as_completed

        futures = {self.client.submit(run_replica, *args, pure=False,
                                      key=f"{replica_name(k)}-{time.time_ns()}"): k
                   for k, args in jobs}
        try:
            for fut in as_completed(list(futures)):
                k = futures[fut]
                try:
                    done(k, fut.result())
                except _FATAL:
                    raise
                except Exception as exc:  # noqa: BLE001 - KilledWorker, NumericalError, ...
                    failed(k, exc)
        except BaseException:
            self.client.cancel(list(futures))
            raise

    def close(self) -> None:
        for thing in (self.client, self.cluster):
            if thing is not None:
                try:
                    thing.close()
                except Exception:  # noqa: BLE001 - closing is best effort
                    pass


def assess_replicas(scene: Any = None, out: str | Path = "demfem_out/replicas",
                    replicas: int = 4, *, precision: Optional[float] = None,
                    max_replicas: int = DEFAULT_MAX_REPLICAS, scheduler: Optional[str] = None,
                    n_workers: Optional[int] = None, seed: int = 0, confidence: float = 0.95,
                    fresh: bool = False, reports: bool = True,
                    connect_timeout: float = 10.0, log: Callable[[str], None] = print,
                    **assess_kwargs: Any) -> dict[str, Any]:
    """Run (or resume) ``replicas`` independent assessments and merge them (module text).

    Args:
        scene: the table: None (built-in default), an AccumulationTable or a TOML file.
        out: the set's folder: ``replica_<k>/`` (each an assess folder), ``replica_<k>.log``
            and ``replicas.json``.
        replicas: how many, ≥ 1 (a set started before with more resumes all of them).
        precision: add replicas until the interval's half-width of the hourly number is at
            most this fraction of it (> 0, e.g. 0.2), or ``max_replicas`` is reached.
        max_replicas: most replicas ``precision`` runs.
        scheduler: None (a LocalCluster on this machine), ``"tcp://host:port"`` (a running
            cluster) or ``"serial"`` (this process, one after another).
        n_workers: LocalCluster worker processes (default: the cores, at most the replicas
            of the first batch); one thread each.
        seed: replica k starts from the perturbed start of seed ``seed + k`` (≥ 0).
        confidence: the interval's nominal coverage, in (0, 1).
        fresh: start every replica afresh (their outputs are removed) instead of resuming.
        reports: write each replica's ``report.html`` (False: stop each after its risk
            stage, which is all the merge needs; a later call with True adds the reports).
        connect_timeout: how long to try to reach a scheduler, s.
        log: where the progress and the summary go.
        **assess_kwargs: the settings of every replica, as :func:`demfem.assess.assess`
            takes them (``duration``, ``quick``, ``full``, ``throughput``, ``threads`` ...).

    Returns:
        The ``replicas.json`` document: ``settings``, ``replicas`` (each one's seed, window,
        expected broken cartridges Y, hours H, hourly number, wall time, state),
        ``merged`` (the pooled numbers and the interval, :class:`RatioInterval` fields) and
        ``precision``.

    Raises:
        InvalidParameterError: a bad argument (``replicas = 0``, a negative precision ...).
        SettingsMismatchError: the folder holds replicas of other settings (each difference
            named, with the replica where a replica found it).
        SchedulerError: the scheduler is unreachable (after ``connect_timeout`` s).
        ReplicaFailedError: replicas failed while the others finished (the record is
            written; run the same call again to resume them).
    """
    from demfem.io.strict_json import finite_or_none, write_json_atomic
    from demfem.jobs import RECORD_FILES, settings_differences
    from demfem.jobs.lock import FolderLock
    from demfem.pipeline import load_scene

    n, prec, most = _check_arguments(replicas, precision, max_replicas, seed, n_workers,
                                     confidence, connect_timeout, assess_kwargs)
    for name, flag in (("fresh", fresh), ("reports", reports)):
        if not isinstance(flag, bool):
            raise InvalidParameterError(f"invalid {name} = {flag!r}: must be True or False")
    table = load_scene(scene)
    settings = finite_or_none({"scene": dataclasses.asdict(table), "seed": int(seed),
                               "assess": {k: _plain(v) for k, v in sorted(
                                   assess_kwargs.items())}}, default=str)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    lock = FolderLock(out, COMMAND).acquire()
    runner = None
    try:
        other = [name for name in RECORD_FILES if (out / name).exists()]
        if other:
            raise OtherJobError(f"the output folder {out} holds another job's record "
                                f"({other[0]}); replicas go in a folder of their own, each in "
                                "its replica_<k> sub-folder: choose another output folder")
        record = None if fresh else _read_record(out)
        if record is not None:
            diff = settings_differences(record["settings"], settings)
            if diff:
                raise SettingsMismatchError(
                    f"the output folder {out} holds replicas of other settings ("
                    + "; ".join(diff) + "): use the same settings to resume or add "
                    "replicas, another output folder, or start afresh (fresh=True, "
                    "--fresh)")
            n = max(n, len(record.get("replicas", [])))
        if prec is not None:
            n = max(n, 2)
        kwargs = dict(assess_kwargs)
        kwargs.setdefault("threads", 1)
        runner = _Runner(scheduler, n_workers, n if prec is None else max(n, os.cpu_count()
                                                                          or 1),
                         float(connect_timeout))
        results: dict[int, dict[str, Any]] = {}
        errors: dict[int, str] = {}

        def job(k: int) -> tuple[int, tuple]:
            return k, (table, str(out / replica_name(k)), int(seed) + k, kwargs, fresh,
                       reports)

        def done(k: int, rec: dict[str, Any]) -> None:
            results[k] = rec
            errors.pop(k, None)
            log(f"  {rec['name']} (seed {rec['seed']}): {rec['broken_per_hour']:.4g} broken "
                f"per hour over {rec['window_s'][1] - rec['window_s'][0]:.4g} s"
                + (" (done before: reused)" if rec["reused"] else
                   f", {rec['wall_s']:.1f} s wall"))

        def failed(k: int, exc: BaseException) -> None:
            errors[k] = f"{type(exc).__name__}: {exc}"
            log(f"  {replica_name(k)} (seed {int(seed) + k}) FAILED: {errors[k]}")

        log(f"== {n} replica(s) of the assessment in {out}, "
            + ("in this process" if scheduler == "serial" else
               f"on {runner.workers} Dask worker(s)"
               + ("" if scheduler is None else f" of {scheduler}")) + " ==")
        pending = list(range(n))
        started = time.perf_counter()
        while True:
            runner.run([job(k) for k in pending], done, failed)
            doc = _document(settings, n, results, errors, confidence, prec, most,
                            time.perf_counter() - started)
            write_json_atomic(out / REPLICAS_FILE, doc)
            if errors or prec is None or n >= most or doc["precision"]["stopped"]:
                break
            judged = doc["precision"]["judged_half_width"]
            add = min(runner.workers, most - n)
            log(f"  the half-width judged by the precision rule is "
                + ("not defined yet" if judged is None else f"{judged:.0%} of the number")
                + f" with {n} replicas, the target {prec:.0%} (and at least "
                f"{PRECISION_MIN_REPLICAS} replicas): {add} more replica(s)")
            pending = list(range(n, n + add))
            n += add
    finally:
        if runner is not None:
            runner.close()
        lock.release()
    for line in summary_lines(doc):
        log(line)
    if errors:
        raise ReplicaFailedError(
            f"{len(errors)} of {n} replicas failed (" + "; ".join(
                f"{replica_name(k)}: {e}" for k, e in sorted(errors.items()))
            + f"); the others finished and are recorded in {out / REPLICAS_FILE}: run the "
            "same command again to resume the failed ones")
    return doc


def _document(settings: dict[str, Any], n: int, results: dict[int, dict[str, Any]],
              errors: dict[int, str], confidence: float, precision: Optional[float],
              most: int, wall: float) -> dict[str, Any]:
    """The ``replicas.json`` document of the replicas so far (merge over those done)."""
    from demfem.assess.replica_stats import merge_replicas
    from demfem.io.strict_json import finite_or_none

    order = sorted(results)
    merged: dict[str, Any] = (merge_replicas([results[k] for k in order], confidence)
                              if order else {"status": "no replica finished",
                                             "relative_half_width": None})
    rows = []
    for k in range(n):
        if k in results:
            rows.append({key: v for key, v in results[k].items() if key != "settings"}
                        | {"state": "done"})
        else:
            rows.append({"name": replica_name(k), "state": "failed" if k in errors else
                         "missing", "error": errors.get(k)})
    rhw = merged.get("relative_half_width")
    judged = merged.get("judged_half_width")
    reached = None if precision is None else bool(judged is not None and judged <= precision)
    stopped = bool(reached) and len(order) >= PRECISION_MIN_REPLICAS
    return finite_or_none({
        "format": 1, "command": COMMAND, "settings": settings,
        "seeds": [settings["seed"] + k for k in range(n)], "replicas": rows,
        "merged": merged, "wall_time_s": wall,
        "precision": {"target": precision, "max_replicas": most, "reached": reached,
                      "stopped": stopped, "judged_half_width": judged,
                      "min_replicas": PRECISION_MIN_REPLICAS,
                      "spread_confidence": PRECISION_SPREAD_CONFIDENCE,
                      "note": None if precision is None else (
                          f"half-width {rhw:.1%} (judged {judged:.1%} with the spread's "
                          f"{PRECISION_SPREAD_CONFIDENCE:.0%} upper bound) <= target "
                          f"{precision:.0%} with {n} replicas" if reached else
                          f"target {precision:.0%} NOT reached: max_replicas = {most} "
                          f"replicas give a half-width of "
                          + ("(undefined)" if rhw is None else f"{rhw:.1%}")
                          + ("" if judged is None else f" (judged {judged:.1%})"))},
        "failed": {replica_name(k): e for k, e in sorted(errors.items())}})


def summary_lines(doc: dict[str, Any]) -> list[str]:
    """The console summary of a ``replicas.json`` document."""
    m = doc["merged"]
    lines = [f"== merged over {m.get('n', 0)} replica(s) =="]
    if m.get("estimate") is None and m.get("status") != "ok":
        lines.append(f"  {m.get('status')}")
    else:
        conf = m.get("confidence", 0.95)
        iv = (f"{conf:.0%} interval {m['lower']:.3g} - {m['upper']:.3g} (x{m['factor']:.2f} "
              f"either way, half-width {m['relative_half_width']:.0%})"
              if m.get("status") == "ok" and m.get("factor") is not None else
              f"no interval: {m.get('status')}")
        lines.append(f"  expected broken per hour: {m['estimate']:.3g}, {iv}")
        lines.append(f"  {m['n_events_window']} events over {m['window_total_s']:.4g} s of "
                     f"statistics windows; replicas' hourly numbers "
                     + ", ".join(f"{x:.3g}" for x in m["per_replica"]))
    dp = m.get("dominant_periods") or {}
    if dp.get("periods"):
        lo, hi = dp["ci"]
        lines.append(f"  gate periods dominated by one event (jams): {dp['dominant']} of "
                     f"{dp['periods']} ({dp['fraction']:.1%}, {dp['confidence']:.0%}: "
                     f"{lo:.1%} - {hi:.1%})"
                     + (f" in {', '.join(dp['replicas'])}" if dp["replicas"] else ""))
    note = doc["precision"].get("note")
    if note:
        lines.append(f"  precision: {note}")
    return lines
