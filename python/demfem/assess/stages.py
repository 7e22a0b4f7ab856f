"""Resumable stages of ``demfem assess`` on its output folder (:class:`demfem.jobs.OutputFolder`):
``stages.json``, the folder's record, holds the job's settings and, for each completed stage,
the files it wrote with their SHA-256, under a checksum of its own.

A job started again in the same folder with the same settings skips every completed stage
whose files are intact and reruns from the first one that is not (a stage that is rerun
invalidates the stages after it). Other settings are refused with
:class:`~demfem.errors.SettingsMismatchError` naming each difference, another command's
folder (e.g. a ``demfem run`` one) with :class:`~demfem.errors.OtherJobError`, a damaged or
hand-edited ``stages.json`` with :class:`~demfem.errors.CheckpointError` naming it, unless
``fresh``: then the previous outputs are removed first. The folder is locked from the
book's creation until :meth:`StageBook.close` (or the end of a ``with`` block, or the
book's garbage collection, or the process's end). Every file, ``stages.json`` included, is
written atomically (:mod:`demfem.io`), so an interruption leaves either the old or the new
version.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any, Iterable, Mapping

from demfem.errors import CheckpointError

__all__ = ["STAGES", "StageBook", "COMMAND"]

#: The stages of ``demfem assess``, in order.
STAGES = ("calibration", "dem", "events", "stress", "risk", "report")

#: The job's name in its folder's record.
COMMAND = "demfem assess"

_FILE = "stages.json"

#: Files of the job besides those the caller names: the DEM checkpoint.
_ALSO_WRITTEN = ("table.ck*",)


class StageBook:
    """The record of one assessment's output folder (see the module docstring): ``out``,
    the job's ``settings``, ``fresh`` to replace a previous job, ``outputs`` the files
    (glob patterns) the job writes."""

    def __init__(self, out: Path, settings: Mapping[str, Any], fresh: bool,
                 outputs: Iterable[str]) -> None:
        from demfem.assess.figures import FIGURES
        from demfem.jobs import OutputFolder

        self.folder = OutputFolder(out, COMMAND, settings, fresh=fresh,
                                   outputs=(*outputs, *FIGURES, *_ALSO_WRITTEN), record=_FILE)
        self.out = self.folder.path
        self.path = self.folder.record_path
        self.settings = self.folder.settings
        self.completed = self._completed(self.folder.fields.get("completed", {}))
        if self.folder.previous is None or self.folder.previous.get("format") != 2:
            self._write()  # a new job, or a record of an earlier version: in today's layout
        else:
            self.folder.files = self._files()

    def _completed(self, value: Any) -> dict[str, dict[str, str]]:
        """The record's completed stages, checked ({stage: {file: SHA-256}})."""
        if not isinstance(value, dict) or not all(
                k in STAGES and isinstance(v, dict)
                and all(isinstance(f, str) and isinstance(h, str) for f, h in v.items())
                for k, v in value.items()):
            self.close()
            raise CheckpointError(
                f"damaged job record {self.path}: its 'completed' entry is not {{stage: "
                f"{{file: SHA-256}}}} over the stages {', '.join(STAGES)}; start afresh "
                f"({self.folder.fresh_hint})")
        return {k: dict(v) for k, v in value.items()}

    def _files(self) -> dict[str, str]:
        return {f: h for files in self.completed.values() for f, h in files.items()}

    def _write(self) -> None:
        self.folder.files = self._files()
        self.folder.update(completed=self.completed, order=list(STAGES))

    def is_done(self, stage: str) -> bool:
        """True if ``stage`` and every stage before it completed and their files are intact."""
        for name in STAGES[:STAGES.index(stage) + 1]:
            files = self.completed.get(name)
            if files is None:
                return False
            for rel in files:
                if not self.folder.intact(rel):
                    return False
        return True

    def complete(self, stage: str, files: Iterable[Path]) -> None:
        """Record ``stage`` as complete with ``files`` (their SHA-256); the stages after it
        are forgotten (their inputs changed)."""
        from demfem.jobs import sha256_file

        for later in STAGES[STAGES.index(stage):]:
            self.completed.pop(later, None)
        self.completed[stage] = {self.folder.relative(f): sha256_file(Path(f)) for f in files}
        self._write()

    def close(self) -> None:
        """Release the folder's lock (the record stays)."""
        self.folder.close()

    def __enter__(self) -> "StageBook":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()
