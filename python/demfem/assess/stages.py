"""Resumable stages: ``stages.json`` in the output folder records the settings of the job and,
for each completed stage, the files it wrote with their SHA-256.

A job started again in the same folder with the same settings skips every completed stage
whose files are intact and reruns from the first one that is not (a stage that is rerun
invalidates the stages after it). Other settings are refused with
:class:`~demfem.errors.SettingsMismatchError` naming each difference, unless ``fresh``: then
the previous outputs are removed first. Every file, ``stages.json`` included, is written
atomically (:mod:`demfem.io`), so an interruption leaves either the old or the new version.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Iterable, Mapping

from demfem.errors import SettingsMismatchError
from demfem.io.strict_json import read_record

__all__ = ["STAGES", "StageBook"]

#: The stages of ``demfem assess``, in order.
STAGES = ("calibration", "dem", "events", "stress", "risk", "report")

_FILE = "stages.json"


class StageBook:
    """The record of one output folder (see the module docstring)."""

    def __init__(self, out: Path, settings: Mapping[str, Any], fresh: bool,
                 outputs: Iterable[str]) -> None:
        from demfem.io.atomic import clean_stale_temporaries
        from demfem.studies.table_run import settings_differences

        self.out = Path(out)
        self.out.mkdir(parents=True, exist_ok=True)
        clean_stale_temporaries(self.out)
        self.path = self.out / _FILE
        self.settings = json.loads(_dumps(settings))
        self.completed: dict[str, dict[str, str]] = {}
        previous = read_record(self.path, ("settings", "completed"), fresh, "stage record",
                               "demfem assess")
        if previous is not None and not fresh:
            diff = settings_differences(previous["settings"], self.settings)
            if diff:
                raise SettingsMismatchError(
                    f"the output folder {self.out} holds an assessment with other settings ("
                    + "; ".join(diff) + "): use the same settings to resume it, another "
                    "output folder, or replace it (fresh=True, demfem assess --fresh)")
            self.completed = {k: dict(v) for k, v in previous["completed"].items()}
        elif fresh:
            for name in (*outputs, _FILE):
                (self.out / name).unlink(missing_ok=True)
        self._write()

    def _write(self) -> None:
        from demfem.io.strict_json import write_json_atomic

        write_json_atomic(self.path, {"format": 1, "settings": self.settings,
                                      "completed": self.completed,
                                      "order": list(STAGES)})

    def is_done(self, stage: str) -> bool:
        """True if ``stage`` and every stage before it completed and their files are intact."""
        from demfem.studies.table_run import sha256_file

        for name in STAGES[:STAGES.index(stage) + 1]:
            files = self.completed.get(name)
            if files is None:
                return False
            for rel, digest in files.items():
                p = self.out / rel
                if not p.exists() or sha256_file(p) != digest:
                    return False
        return True

    def complete(self, stage: str, files: Iterable[Path]) -> None:
        """Record ``stage`` as complete with ``files`` (their SHA-256); the stages after it
        are forgotten (their inputs changed)."""
        from demfem.studies.table_run import sha256_file

        for later in STAGES[STAGES.index(stage):]:
            self.completed.pop(later, None)
        self.completed[stage] = {str(Path(f).relative_to(self.out)): sha256_file(Path(f))
                                 for f in files}
        self._write()


def _dumps(obj: Any) -> str:
    from demfem.io.strict_json import dumps

    return dumps(obj)
