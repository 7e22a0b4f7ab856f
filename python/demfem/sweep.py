"""Parameter sweeps on Dask: one run per task, one table of results, finished runs skipped.

A sweep is a grid of parameters (the Cartesian product of named value lists) and a *runner*,
a plain function ``runner(params: dict) -> dict`` named by ``"package.module:function"`` so
that any Dask worker can import it. Each finished run is written atomically as
``<out>/runs/<key>.json`` (its parameters and results), so a sweep that is stopped and
launched again only runs what is missing. The gathered table is ``<out>/results.csv``.

By default the runs go to a :class:`distributed.LocalCluster` on this machine; pass
``scheduler="tcp://host:8786"`` to use a real cluster (the workers need demfem installed).
``scheduler="serial"`` runs in this process without Dask, which is handy for debugging.
"""
from __future__ import annotations

import hashlib
import importlib
import itertools
import json
import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Mapping, Optional, Sequence

from demfem.errors import InvalidParameterError
from demfem.io import write_json_atomic, write_text_atomic

__all__ = ["grid_points", "run_key", "resolve_runner", "sweep", "SweepResult", "parse_grid_option"]


def grid_points(grid: Mapping[str, Sequence[Any]]) -> list[dict[str, Any]]:
    """The Cartesian product of ``grid`` as a list of parameter dicts (keys in given order)."""
    if not grid:
        raise InvalidParameterError("invalid grid = {}: name at least one parameter")
    for name, values in grid.items():
        if isinstance(values, (str, bytes)) or len(values) == 0:
            raise InvalidParameterError(f"invalid grid[{name!r}] = {values!r}: must be a non-empty list")
    names = list(grid)
    return [dict(zip(names, combo)) for combo in itertools.product(*(grid[n] for n in names))]


def run_key(params: Mapping[str, Any]) -> str:
    """A stable, readable file key for one parameter set: ``A=0.02_T=2_<hash8>``."""
    canon = json.dumps({k: params[k] for k in sorted(params)}, sort_keys=True, default=str)
    digest = hashlib.sha256(canon.encode()).hexdigest()[:8]
    readable = "_".join(f"{k}={params[k]}" for k in sorted(params))
    safe = "".join(c if c.isalnum() or c in "=._-" else "-" for c in readable)[:80]
    return f"{safe}_{digest}"


def resolve_runner(spec: "str | Callable[[dict], dict]") -> Callable[[dict], dict]:
    """A runner from ``"module:function"`` (or a callable, returned as is)."""
    if callable(spec):
        return spec
    if not isinstance(spec, str) or ":" not in spec:
        raise InvalidParameterError(f"invalid runner = {spec!r}: must be 'package.module:function'")
    mod_name, func_name = spec.split(":", 1)
    try:
        func = getattr(importlib.import_module(mod_name), func_name)
    except (ImportError, AttributeError) as exc:
        raise InvalidParameterError(f"invalid runner = {spec!r}: {exc}") from None
    if not callable(func):
        raise InvalidParameterError(f"invalid runner = {spec!r}: not callable")
    return func


def _run_one(runner_spec: "str | Callable[[dict], dict]", params: dict, path: str) -> dict:
    """Run one point and write its record atomically (executed on a worker)."""
    runner = resolve_runner(runner_spec)
    t0 = time.perf_counter()
    result = runner(dict(params))
    if not isinstance(result, Mapping):
        raise InvalidParameterError(f"invalid runner result = {result!r}: must be a dict")
    record = {"params": params, "result": dict(result), "wall_time_s": time.perf_counter() - t0}
    write_json_atomic(path, record, default=str)
    return record


@dataclass(frozen=True)
class SweepResult:
    """Records of every point (``params``, ``result``, ``wall_time_s``), how many ran now and
    how many were found finished, and the path of the gathered CSV table."""

    records: list[dict]
    ran: int
    skipped: int
    table_path: Path


def _write_table(records: list[dict], path: Path) -> Path:
    pkeys: list[str] = []
    rkeys: list[str] = []
    for r in records:
        pkeys += [k for k in r["params"] if k not in pkeys]
        rkeys += [k for k, v in r["result"].items()
                  if k not in rkeys and isinstance(v, (int, float, str, bool))]
    lines = [",".join(pkeys + rkeys + ["wall_time_s"])]
    for r in records:
        row = [str(r["params"].get(k, "")) for k in pkeys]
        row += [str(r["result"].get(k, "")) for k in rkeys]
        row.append(f"{r['wall_time_s']:.3f}")
        lines.append(",".join(row))
    return write_text_atomic(path, "\n".join(lines) + "\n")


def sweep(
    grid: Mapping[str, Sequence[Any]],
    runner: "str | Callable[[dict], dict]",
    out_dir: "str | Path",
    scheduler: Optional[str] = None,
    n_workers: Optional[int] = None,
    fixed: Optional[Mapping[str, Any]] = None,
    progress: Optional[Callable[[int, int], None]] = None,
) -> SweepResult:
    """Run ``runner`` on every point of ``grid`` (merged with ``fixed`` parameters).

    ``scheduler``: ``None`` for a LocalCluster (``n_workers`` processes, one thread each;
    default: the number of cores), an address such as ``"tcp://10.0.0.5:8786"`` for a running
    cluster, or ``"serial"`` for no Dask at all. Points whose record file exists are skipped.
    ``progress(done, total)`` is called as runs finish.
    """
    out = Path(out_dir)
    runs_dir = out / "runs"
    runs_dir.mkdir(parents=True, exist_ok=True)
    resolve_runner(runner)  # fail early, here, not on a worker
    points = [{**(fixed or {}), **p} for p in grid_points(grid)]
    paths = [runs_dir / f"{run_key(p)}.json" for p in points]
    todo = [(p, str(path)) for p, path in zip(points, paths) if not path.exists()]
    skipped = len(points) - len(todo)
    done = skipped
    if progress:
        progress(done, len(points))
    if todo:
        if scheduler == "serial":
            for p, path in todo:
                _run_one(runner, p, path)
                done += 1
                if progress:
                    progress(done, len(points))
        else:
            from distributed import Client, LocalCluster, as_completed

            cluster = None
            if scheduler is None:
                import os

                workers = n_workers or max(1, min(len(todo), os.cpu_count() or 1))
                cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                       dashboard_address=None)
                client = Client(cluster)
            else:
                client = Client(scheduler)
            try:
                futures = [client.submit(_run_one, runner, p, path, pure=False) for p, path in todo]
                for fut in as_completed(futures):
                    fut.result()  # re-raises a worker's exception here
                    done += 1
                    if progress:
                        progress(done, len(points))
            finally:
                client.close()
                if cluster is not None:
                    cluster.close()
    records = [json.loads(path.read_text()) for path in paths]
    table = _write_table(records, out / "results.csv")
    return SweepResult(records=records, ran=len(todo), skipped=skipped, table_path=table)


def parse_grid_option(items: Sequence[str]) -> dict[str, list[Any]]:
    """Parse CLI grid options ``NAME=v1,v2,...`` (numbers where they parse, else strings)."""
    grid: dict[str, list[Any]] = {}
    for item in items:
        if "=" not in item:
            raise InvalidParameterError(f"invalid --grid {item!r}: must be NAME=v1,v2,...")
        name, vals = item.split("=", 1)
        values: list[Any] = []
        for v in vals.split(","):
            v = v.strip()
            try:
                x = float(v)
                values.append(int(x) if x.is_integer() and "." not in v and "e" not in v.lower() else x)
            except ValueError:
                values.append(v)
        if not name.strip() or not values or any(
                isinstance(x, float) and not math.isfinite(x) for x in values):
            raise InvalidParameterError(f"invalid --grid {item!r}: name and finite values needed")
        grid[name.strip()] = values
    return grid
