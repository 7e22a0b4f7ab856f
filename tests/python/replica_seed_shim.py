"""Test scaffolding for the replica tests: gives :func:`demfem.assess.run.assess` the ``seed``
argument (a perturbed start, :func:`demfem.scenes.perturb.perturbed_start`) while this
demfem's assess does not have it yet; inert once it does.

It is loaded in the test process (:func:`install`, undone by the fixture) and, as a Dask
worker preload (``distributed.worker.preload``), in every worker process a test's cluster
starts: ``import``-ing the file installs it. The seeded table is the same table whose
``build()`` perturbs the start, so the run's settings and numbers are those of the table,
started elsewhere."""
from __future__ import annotations

import inspect
import threading
from typing import Any, Callable

from demfem.assess import run as _assess_run
from demfem.scenes.perturb import perturbed_start
from demfem.scenes.table import AccumulationTable
from demfem.studies import table_run as _table_run

_STATE = threading.local()


class _SeededTable(AccumulationTable):
    """The table with a perturbed start (not a new dataclass: the same fields)."""

    def build(self):  # type: ignore[override]
        return perturbed_start(super().build(), self.__dict__["_start_seed"])


def _seeded(table: AccumulationTable, seed: int) -> AccumulationTable:
    import copy

    t = copy.copy(table)
    object.__setattr__(t, "__class__", _SeededTable)
    object.__setattr__(t, "_start_seed", int(seed))
    return t


def needed() -> bool:
    """True while demfem's assess has no ``seed`` argument."""
    return "seed" not in inspect.signature(_assess_run.assess).parameters


def install(setattr_: Callable[[Any, str, Any], None] = setattr) -> bool:
    """Patch assess and run_table (with ``setattr_``, e.g. pytest's monkeypatch.setattr);
    False when not needed."""
    if not needed():
        return False
    assess, run_table = _assess_run.assess, _table_run.run_table

    def seeded_assess(*args: Any, seed: Any = None, **kwargs: Any) -> Any:
        _STATE.seed = seed
        try:
            return assess(*args, **kwargs)
        finally:
            _STATE.seed = None

    def seeded_run_table(table: Any, *args: Any, **kwargs: Any) -> Any:
        seed = getattr(_STATE, "seed", None)
        return run_table(table if seed is None else _seeded(table, seed), *args, **kwargs)

    setattr_(_assess_run, "assess", seeded_assess)
    setattr_(_table_run, "run_table", seeded_run_table)
    return True


if __name__ == "replica_seed_shim" and needed():
    # imported under the file's own name (a Dask worker preload): install; the tests load
    # it under another name and install it themselves, undone after each test
    install()
