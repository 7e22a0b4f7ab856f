"""Resumable stages of ``demfem assess`` on its output folder (:class:`demfem.jobs.OutputFolder`):
``stages.json``, the folder's record, holds the job's settings and, for each completed stage,
the files it wrote with their SHA-256, under a checksum of its own; once the job has finished
(:meth:`StageBook.finish`), also the intermediates it removed (``dropped``) and the stages'
digests (``digests``: what their console lines need), with ``finished`` true.

A job started again in the same folder with the same settings skips every completed stage
whose files are intact and reruns from the first one that is not (a stage that is rerun
invalidates the stages after it). In a finished folder a stage whose intermediates were
removed counts as completed only while every product of the job is intact: a damaged or
missing product makes the job rerun from the first such stage. Other settings are refused with
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
from typing import Any, Iterable, Mapping, Optional

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
        self.finished, self.dropped, self.digests = self._finish_fields(self.folder.fields)
        self._intact: dict[str, bool] = {}
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

    def _finish_fields(self, fields: Mapping[str, Any]
                       ) -> tuple[bool, dict[str, list[str]], dict[str, dict[str, Any]]]:
        """The record's ``finished``, ``dropped`` ({stage: [file]}) and ``digests``
        ({stage: {...}}), checked (absent in an unfinished job's record)."""
        finished = fields.get("finished", False)
        dropped = fields.get("dropped", {})
        digests = fields.get("digests", {})
        if not (isinstance(finished, bool) and isinstance(dropped, dict)
                and all(k in STAGES and isinstance(v, list) and all(isinstance(f, str) for f in v)
                        for k, v in dropped.items())
                and isinstance(digests, dict)
                and all(k in STAGES and isinstance(v, dict) for k, v in digests.items())):
            self.close()
            raise CheckpointError(
                f"damaged job record {self.path}: its 'finished', 'dropped' or 'digests' "
                f"entry is not a flag, {{stage: [file]}} and {{stage: {{...}}}} over the "
                f"stages {', '.join(STAGES)}; start afresh ({self.folder.fresh_hint})")
        return finished, {k: list(v) for k, v in dropped.items()}, dict(digests)

    def _files(self) -> dict[str, str]:
        return {f: h for files in self.completed.values() for f, h in files.items()}

    def _write(self) -> None:
        self.folder.files = self._files()
        fields: dict[str, Any] = {"completed": self.completed, "order": list(STAGES)}
        if self.finished:
            fields.update(finished=True, dropped=self.dropped, digests=self.digests)
        else:
            for key in ("finished", "dropped", "digests"):
                self.folder.fields.pop(key, None)
        self.folder.update(**fields)

    def _stage_intact(self, name: str) -> bool:
        """Whether ``name`` completed and its recorded files are intact (each file's SHA-256
        computed once per book)."""
        files = self.completed.get(name)
        if files is None:
            return False
        for rel in files:
            if rel not in self._intact:
                self._intact[rel] = self.folder.intact(rel)
            if not self._intact[rel]:
                return False
        return True

    def is_done(self, stage: str) -> bool:
        """True if ``stage`` and every stage before it completed and their files are intact;
        in a finished folder, a stage whose intermediates were removed also needs every
        stage's products intact (module docstring)."""
        whole: Optional[bool] = None
        for name in STAGES[:STAGES.index(stage) + 1]:
            if not self._stage_intact(name):
                return False
            if self.finished and self.dropped.get(name):
                if whole is None:
                    whole = all(self._stage_intact(n) for n in STAGES)
                if not whole:
                    return False
        return True

    def complete(self, stage: str, files: Iterable[Path]) -> None:
        """Record ``stage`` as complete with ``files`` (their SHA-256); the stages after it
        are forgotten (their inputs changed), and the folder is no longer finished."""
        from demfem.jobs import sha256_file

        for later in STAGES[STAGES.index(stage):]:
            self.completed.pop(later, None)
        self.completed[stage] = {self.folder.relative(f): sha256_file(Path(f)) for f in files}
        self.finished, self.dropped, self.digests = False, {}, {}
        self._intact = {}
        self._write()

    def digest(self, stage: str) -> Optional[dict[str, Any]]:
        """The digest recorded for ``stage`` when the job finished (None if it has none)."""
        return self.digests.get(stage)

    def finish(self, intermediates: Mapping[str, Iterable[str]],
               digests: Mapping[str, dict[str, Any]]) -> None:
        """Mark the job finished: record the stages' ``digests`` and remove their
        ``intermediates`` ({stage: file names}). The record is written first, so an
        interruption leaves at most unrecorded intermediates, which the next call (the
        folder is finished: nothing else runs) removes. A finished folder's leftover
        intermediates are removed the same way."""
        if not self.finished:
            dropped = {name: [f for f in map(self.folder.relative, names)
                              if f in self.completed.get(name, {})]
                       for name, names in intermediates.items()}
            for name, files in dropped.items():
                for f in files:
                    self.completed[name].pop(f, None)
            self.finished = True
            self.dropped = {name: files for name, files in dropped.items() if files}
            self.digests = {k: dict(v) for k, v in digests.items()}
            self._write()
            self.digests = dict(self.folder.fields["digests"])  # as the record holds them
        for names in intermediates.values():
            self.folder.remove_outputs(names)

    def close(self) -> None:
        """Release the folder's lock (the record stays)."""
        self.folder.close()

    def __enter__(self) -> "StageBook":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()
