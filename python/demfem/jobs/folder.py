"""The output folder of one job: who made it, with which settings, and which files it holds.

Every job (``demfem run``, ``demfem assess``, ``demfem cluster``, a mesh-table run) writes into
an :class:`OutputFolder`. Opening one:

1. creates the folder and takes its lock (:class:`~demfem.jobs.lock.FolderLock`: a second
   process is refused at once, naming the PID that holds it);
2. removes the temporary files a killed process left (:func:`demfem.io.atomic.
   clean_stale_temporaries`: safe, since no other process can be writing);
3. reads the folder's **record** (``run.json``, ``stages.json`` or ``settings.json``, the
   names earlier versions wrote): the command that made the folder, its settings (with the
   SHA-256 of its input files), the output patterns it writes, and the SHA-256 of each output
   file it finished, the whole protected by a checksum of its own. A record that does not
   parse, lacks a field or fails its checksum (damaged, edited by hand) raises
   :class:`~demfem.errors.CheckpointError` naming the file and ``--fresh``;
4. refuses a folder that holds another command's job (:class:`~demfem.errors.OtherJobError`
   naming that command), the same command's job with other settings
   (:class:`~demfem.errors.SettingsMismatchError` naming each difference), or files this job
   writes without any record — unless ``fresh``, which removes the previous job's outputs
   (only those) first. The same command with the same settings resumes: :attr:`previous`
   holds the record, and :meth:`verify` refuses any recorded file whose bytes changed.

Records are written atomically (:mod:`demfem.io`), as strict JSON.
"""
from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any, Callable, Iterable, Mapping, Optional

from demfem.errors import (CheckpointError, DemfemIOError, OtherJobError,
                           SettingsMismatchError)
from demfem.jobs.lock import LOCK_FILE, FolderLock

__all__ = ["OutputFolder", "settings_differences", "sha256_file", "RECORD_FILES",
           "FORMAT"]

#: The record file names and the command whose records carried that name before records
#: named their command (format 1, or none).
RECORD_FILES = {"run.json": "demfem run", "stages.json": "demfem assess",
                "settings.json": "demfem cluster"}

#: The record format this version writes.
FORMAT = 2

Compare = Callable[[Mapping[str, Any], Mapping[str, Any]], list]


def settings_differences(recorded: Mapping[str, Any], now: Mapping[str, Any],
                         prefix: str = "") -> list[str]:
    """``"name: <recorded> -> <now>"`` for each setting that differs (nested dicts by
    dotted name)."""
    out = []
    for key in sorted(set(recorded) | set(now)):
        a, b = recorded.get(key), now.get(key)
        name = f"{prefix}{key}"
        if isinstance(a, Mapping) and isinstance(b, Mapping):
            out += settings_differences(a, b, name + ".")
        elif a != b:
            out.append(f"{name}: {a!r} -> {b!r}")
    return out


def sha256_file(path: str | Path) -> str:
    """Hex SHA-256 of a file's bytes."""
    h = hashlib.sha256()
    try:
        with open(path, "rb") as fh:
            for block in iter(lambda: fh.read(1 << 20), b""):
                h.update(block)
    except OSError as exc:
        raise DemfemIOError(f"i/o error on {path}: {exc.strerror or exc}") from None
    return h.hexdigest()


def _canonical(obj: Any) -> Any:
    """``obj`` as strict JSON would read it back (tuples as lists, numpy as plain numbers,
    NaN as null)."""
    from demfem.io.strict_json import dumps

    return json.loads(dumps(obj))


def _checksum(body: Mapping[str, Any]) -> str:
    from demfem.io.strict_json import dumps

    return hashlib.sha256(dumps(body, sort_keys=True).encode("utf-8")).hexdigest()


class OutputFolder:
    """The output folder ``path`` of a job of ``command`` with ``settings`` (see the module
    text).

    Args:
        path: the folder (created).
        command: what makes the folder, as the user knows it: ``"demfem run"``,
            ``"demfem assess"``, ``"demfem cluster"``, ``"demfem run (mesh table)"``.
        settings: what makes the job's result (strict-JSON values); a resume with other
            settings is refused naming each difference.
        fresh: replace a previous job (its outputs are removed) instead of refusing it.
        outputs: glob patterns (relative to the folder) of every file the job may write,
            checkpoints included: removed by a fresh start, and by a later fresh job of
            another command.
        record: the record's file name (one of :data:`RECORD_FILES`).
        inputs: input files whose content makes the result ({name: path}); their SHA-256
            join the settings as ``inputs.<name>``.
        compare: ``compare(recorded, now)`` -> the differences that refuse a resume
            (default :func:`settings_differences`).

    The folder is locked until :meth:`close` (or the end of a ``with`` block, or the end of
    the process). :attr:`previous` is the record of the same job found there (None for a
    new job); :attr:`files` the SHA-256 of the output files recorded so far; :attr:`fields`
    the job's own entries of the record (e.g. ``status``)."""

    def __init__(self, path: str | Path, command: str, settings: Mapping[str, Any], *,
                 fresh: bool = False, outputs: Iterable[str] = (), record: str = "run.json",
                 inputs: Optional[Mapping[str, str | Path]] = None,
                 compare: Optional[Compare] = None) -> None:
        from demfem.io.atomic import clean_stale_temporaries

        if record not in RECORD_FILES:
            raise ValueError(f"record must be one of {sorted(RECORD_FILES)}, not {record!r}")
        self.path = Path(path)
        self.command = str(command)
        self.record_path = self.path / record
        self.outputs = tuple(outputs)
        self.fresh = bool(fresh)
        settings = dict(settings)
        if inputs:
            settings["inputs"] = {str(k): sha256_file(Path(p)) for k, p in inputs.items()}
        self.settings = _canonical(settings)
        self.previous: Optional[dict[str, Any]] = None
        self.files: dict[str, str] = {}
        self.fields: dict[str, Any] = {}
        try:
            self.path.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise DemfemIOError(f"i/o error on {self.path}: cannot create the output folder: "
                                f"{exc.strerror or exc}") from None
        self.lock = FolderLock(self.path, self.command).acquire()
        try:
            clean_stale_temporaries(self.path)
            self._open(compare or settings_differences)
        except BaseException:
            self.lock.release()
            raise

    # ---- the public interface ----------------------------------------------------------------

    @property
    def fresh_hint(self) -> str:
        """How to start afresh, for messages: ``fresh=True, demfem run --fresh``."""
        return f"fresh=True, {self.command.split(' (')[0]} --fresh"

    def close(self) -> None:
        """Release the folder's lock (the record stays)."""
        self.lock.release()

    def __enter__(self) -> "OutputFolder":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def update(self, **fields: Any) -> None:
        """Set the job's own entries of the record (e.g. ``status="complete"``) and write
        it."""
        self.fields.update(_canonical(fields))
        self.write()

    def add_files(self, paths: Iterable[str | Path]) -> dict[str, str]:
        """Record the SHA-256 of finished output files (paths in the folder) and write the
        record; returns {relative name: SHA-256}."""
        added = {}
        for p in paths:
            p = Path(p)
            added[self.relative(p)] = sha256_file(p)
        self.files.update(added)
        self.write()
        return added

    def forget_files(self, names: Iterable[str]) -> None:
        """Drop recorded files (relative names) whose content is about to be replaced."""
        for name in names:
            self.files.pop(str(name), None)
        self.write()

    def intact(self, name: str | Path) -> bool:
        """True if the file (relative name or path) is recorded and its bytes are the ones
        recorded."""
        rel = self.relative(name)
        digest = self.files.get(rel)
        p = self.path / rel
        return digest is not None and p.is_file() and sha256_file(p) == digest

    def verify(self, name: str | Path) -> Path:
        """The path of a recorded output file, after checking its SHA-256 against the
        record; a missing, changed or unrecorded one raises
        :class:`~demfem.errors.CheckpointError` naming it and ``--fresh``."""
        rel = self.relative(name)
        p = self.path / rel
        digest = self.files.get(rel)
        if digest is None:
            why = f"it is not recorded in {self.record_path.name} as finished"
        elif not p.is_file():
            why = "it is missing"
        elif sha256_file(p) != digest:
            why = (f"its SHA-256 differs from the one recorded in {self.record_path.name} "
                   "when it was written (damaged or altered)")
        else:
            return p
        raise CheckpointError(f"damaged output folder: {p} cannot be reused: {why}; start "
                              f"afresh ({self.fresh_hint})")

    def relative(self, name: str | Path) -> str:
        """``name`` (a path in the folder, or a name relative to it) as the record names it."""
        p = Path(name)
        n = len(self.path.parts)
        if not p.is_absolute() and (n == 0 or p.parts[:n] != self.path.parts):
            return p.as_posix()
        try:
            return p.relative_to(self.path).as_posix()
        except ValueError:
            return p.resolve().relative_to(self.path.resolve()).as_posix()

    def write(self) -> None:
        """Write the record atomically (with its checksum)."""
        from demfem.io.strict_json import write_json_atomic

        body = {"format": FORMAT, "command": self.command, **self.fields,
                "settings": self.settings, "outputs": list(self.outputs),
                "files": dict(self.files)}
        body["format"], body["command"] = FORMAT, self.command
        body = _canonical(body)
        write_json_atomic(self.record_path, {**body, "checksum": _checksum(body)})

    def remove_outputs(self, patterns: Iterable[str]) -> list[Path]:
        """Remove the files matching ``patterns`` (globs relative to the folder; never the
        lock file), then the sub-folders that this left empty; returns the files removed."""
        removed: list[Path] = []
        root = self.path.resolve()
        for pattern in patterns:
            for p in sorted(self.path.glob(pattern)):
                if not p.is_file() or p.name == LOCK_FILE or \
                        root not in p.resolve().parents:
                    continue
                try:
                    p.unlink()
                except OSError as exc:
                    raise DemfemIOError(f"i/o error on {p}: cannot remove it: "
                                        f"{exc.strerror or exc}") from None
                removed.append(p)
        for d in sorted({p.parent for p in removed}, key=lambda q: -len(q.parts)):
            while d.resolve() != root and d.is_dir() and not any(d.iterdir()):
                d.rmdir()
                d = d.parent
        return removed

    # ---- opening -----------------------------------------------------------------------------

    def _open(self, compare: Compare) -> None:
        found = {name: self._read(self.path / name) for name in RECORD_FILES
                 if (self.path / name).exists()}
        mine: Optional[dict[str, Any]] = None
        for name, doc in found.items():
            if doc is None:  # damaged, and fresh: replaced below
                (self.path / name).unlink(missing_ok=True)
            elif doc["command"] != self.command:
                if not self.fresh:
                    raise OtherJobError(
                        f"the output folder {self.path} holds the output of another job, "
                        f"{doc['command']!r} (its record {name}); this is {self.command!r}, "
                        "which would overwrite or mix with its files: choose another output "
                        f"folder (--out), or replace that job ({self.fresh_hint})")
                self.remove_outputs([*doc["outputs"], *doc["files"], name])
            elif self.path / name == self.record_path:
                mine = doc
            else:  # the same command under another record name: an older layout
                self.remove_outputs([*doc["outputs"], *doc["files"], name])
        if mine is not None and not self.fresh:
            diff = compare(mine["settings"], self.settings)
            if diff:
                raise SettingsMismatchError(
                    f"the output folder {self.path} holds a job of {self.command!r} with "
                    f"other settings (" + "; ".join(diff) + "): use the same settings to "
                    f"resume it, another output folder, or replace it ({self.fresh_hint})")
            self.previous = mine
            self.files = dict(mine["files"])
            self.fields = {k: v for k, v in mine.items()
                           if k not in ("format", "command", "settings", "outputs", "files",
                                        "checksum")}
            return
        if mine is None and not self.fresh:
            present = [pattern for pattern in self.outputs if any(self.path.glob(pattern))]
            if present:
                raise OtherJobError(
                    f"the output folder {self.path} holds files that {self.command!r} writes "
                    f"({', '.join(present[:4])}) but no record of the job that made them "
                    f"({self.record_path.name}; another job, or an earlier demfem version): "
                    f"choose another output folder (--out), or replace them ({self.fresh_hint})")
        if mine is not None:
            self.remove_outputs([*mine["outputs"], *mine["files"]])
        self.remove_outputs(self.outputs)
        self.write()

    def _read(self, path: Path) -> Optional[dict[str, Any]]:
        """A record, checked and brought to the current layout; None when it is damaged and
        ``fresh`` (it is replaced), else a damaged one raises CheckpointError."""
        try:
            try:
                doc = json.loads(path.read_text(encoding="utf-8"))
            except UnicodeDecodeError:
                raise ValueError("it is not UTF-8 text") from None
            return _layout(doc, path.name)
        except OSError as exc:
            raise DemfemIOError(f"i/o error on {path}: {exc.strerror or exc}") from None
        except (ValueError, TypeError, KeyError) as exc:
            if self.fresh:
                return None
            raise CheckpointError(
                f"damaged job record {path}: {exc}; it cannot be trusted to resume or reuse "
                f"the job: start afresh ({self.fresh_hint}), which replaces the folder's "
                "outputs") from None


def _layout(doc: Any, name: str) -> dict[str, Any]:
    """A parsed record as {format, command, settings, outputs, files, ...}; raises
    ValueError naming what is wrong."""
    if not isinstance(doc, dict):
        raise ValueError(f"a JSON object is expected, not {type(doc).__name__}")
    if doc.get("format") == FORMAT or "checksum" in doc:
        for key, kind in (("command", str), ("settings", dict), ("outputs", list),
                          ("files", dict), ("checksum", str)):
            if not isinstance(doc.get(key), kind):
                raise ValueError(f"its field {key!r} is missing or not a {kind.__name__}")
        body = {k: v for k, v in doc.items() if k != "checksum"}
        if _checksum(body) != doc["checksum"]:
            raise ValueError("its checksum does not match its content (damaged or edited "
                             "by hand)")
        if doc["format"] != FORMAT:
            raise ValueError(f"format {doc['format']!r}; this version reads {FORMAT}")
        if not all(isinstance(p, str) for p in doc["outputs"]) or not all(
                isinstance(k, str) and isinstance(v, str) for k, v in doc["files"].items()):
            raise ValueError("its outputs or files are not names")
        return doc
    # format 1 (or none): written before records named their command; no checksum
    command = RECORD_FILES[name]
    if name == "settings.json":  # the cluster's bare settings
        if "cluster" not in doc:
            raise ValueError("neither a job record nor a cluster run's settings")
        return {"format": 1, "command": command, "settings": doc, "outputs": [], "files": {}}
    settings = doc.get("settings")
    if not isinstance(settings, dict):
        raise ValueError("its field 'settings' is missing or not an object")
    legacy = {k: v for k, v in doc.items() if k not in ("format", "settings")}
    if name == "stages.json":
        completed = doc.get("completed")
        if not isinstance(completed, dict) or not all(
                isinstance(v, dict) and all(isinstance(h, str) for h in v.values())
                for v in completed.values()):
            raise ValueError("its field 'completed' is missing or not {stage: {file: "
                             "SHA-256}}")
    return {"format": 1, "command": command, "settings": settings, "outputs": [],
            "files": {}, **legacy}
