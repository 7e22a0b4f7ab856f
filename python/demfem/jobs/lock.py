"""An exclusive lock on an output folder for the life of one job.

Two processes started into one folder would overwrite each other's files (and the second
one's start-up would delete the first one's temporary files under it). The job holds
``fcntl.flock`` on the folder's lock file ``.demfem.lock`` from its start to its end; the
kernel releases it when the process ends in any way (return, exception, Ctrl-C, kill -9,
power loss), so a killed job never leaves its folder locked. A second process that finds
the folder locked is refused at once with :class:`~demfem.errors.FolderLockedError`, naming
the folder and the PID, command and start time of the process that holds it (the holder
writes them into the lock file).

Inside one process, a job started again in the same thread takes the lock over from an
earlier job of that thread that has ended without releasing it (e.g. one kept alive by a
traceback); a job of another live thread in the same folder is refused like another
process. Where the file system cannot lock (some network file systems) or the platform has
no ``fcntl``, the job runs unlocked with a :class:`RuntimeWarning` that says so.
"""
from __future__ import annotations

import datetime
import errno
import json
import os
import socket
import threading
import time
import warnings
from pathlib import Path
from typing import Any, Optional

from demfem.errors import DemfemIOError, FolderLockedError

try:
    import fcntl
except ImportError:  # pragma: no cover - Windows
    fcntl = None  # type: ignore[assignment]

__all__ = ["FolderLock", "LOCK_FILE"]

#: Name of the lock file in a job's output folder.
LOCK_FILE = ".demfem.lock"

#: The locks this process holds, by the folder's real path.
_HELD: dict[str, "FolderLock"] = {}
_HELD_GUARD = threading.RLock()  # re-entrant: a finaliser may release inside acquire

#: errno values of "held by another open file" (flock with LOCK_NB).
_BUSY = {errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES}


class FolderLock:
    """The lock of ``folder`` for a job of ``command`` (e.g. ``"demfem run"``).

    :meth:`acquire` takes it or raises :class:`~demfem.errors.FolderLockedError`;
    :meth:`release` (or the end of a ``with`` block, or the end of the process) gives it
    back. ``locked`` tells whether it is held; an object that is garbage collected releases
    its lock."""

    def __init__(self, folder: str | Path, command: str) -> None:
        self.folder = Path(folder)
        self.path = self.folder / LOCK_FILE
        self.command = str(command)
        self._fd: Optional[int] = None
        self._thread: Optional[threading.Thread] = None

    @property
    def locked(self) -> bool:
        """True while this object holds the folder's lock."""
        return self._fd is not None

    def acquire(self) -> "FolderLock":
        """Take the lock; returns ``self``. Raises :class:`FolderLockedError` naming the
        holder when another process (or another live thread of this one) holds it."""
        if self.locked:
            return self
        key = os.path.realpath(self.folder)
        with _HELD_GUARD:
            held = _HELD.get(key)
            if held is not None and held.locked:
                thread = held._thread
                if thread is threading.current_thread() or thread is None \
                        or not thread.is_alive():
                    held.release()
                else:
                    raise FolderLockedError(
                        f"the output folder {self.folder} is in use by another job of this "
                        f"process (PID {os.getpid()}, thread {thread.name!r}, "
                        f"{held.command}): wait for it to end, or choose another output folder")
            fd = self._open()
            if fd is None:
                return self
            try:
                _flock(fd)
            except BlockingIOError:
                holder = _holder(fd)
                os.close(fd)
                raise FolderLockedError(
                    f"the output folder {self.folder} is in use by another demfem process: "
                    f"{_describe(holder)}; two jobs cannot write one folder at once: wait for "
                    "it to end (or stop it), or choose another output folder (--out)") from None
            except OSError as exc:
                os.close(fd)
                if exc.errno in _BUSY:
                    raise FolderLockedError(
                        f"the output folder {self.folder} is in use by another demfem "
                        f"process; choose another output folder (--out)") from None
                warnings.warn(f"cannot lock the output folder {self.folder} "
                              f"({exc.strerror or exc}): the job runs unlocked, so a second "
                              "job started into the same folder would not be refused",
                              RuntimeWarning, stacklevel=3)
                return self
            self._fd = fd
            self._thread = threading.current_thread()
            _HELD[key] = self
            self._write_holder()
        return self

    def release(self) -> None:
        """Give the lock back (nothing if not held)."""
        fd, self._fd = self._fd, None
        if fd is None:
            return
        try:
            if fcntl is not None:
                fcntl.flock(fd, fcntl.LOCK_UN)
        except OSError:
            pass  # closing the descriptor releases it anyway
        finally:
            os.close(fd)
        with _HELD_GUARD:
            key = os.path.realpath(self.folder)
            if _HELD.get(key) is self:
                del _HELD[key]

    def __enter__(self) -> "FolderLock":
        return self.acquire()

    def __exit__(self, *exc: Any) -> None:
        self.release()

    def __del__(self) -> None:
        try:
            self.release()
        except Exception:  # noqa: BLE001 - never raise from a finaliser
            pass

    # ---- internals ---------------------------------------------------------------------------

    def _open(self) -> Optional[int]:
        """The lock file's descriptor, or None (with a warning) where locking is impossible."""
        if fcntl is None:  # pragma: no cover - Windows
            warnings.warn(f"no fcntl on this platform: the output folder {self.folder} is not "
                          "locked, so a second job started into it would not be refused",
                          RuntimeWarning, stacklevel=4)
            return None
        try:
            return os.open(self.path, os.O_RDWR | os.O_CREAT, 0o666)
        except OSError as exc:
            raise DemfemIOError(f"i/o error on {self.path}: cannot open the folder's lock "
                                f"file: {exc.strerror or exc}") from None

    def _write_holder(self) -> None:
        """Who holds the lock, for the message a second process prints."""
        assert self._fd is not None
        info = {"pid": os.getpid(), "host": socket.gethostname(), "command": self.command,
                "started": datetime.datetime.now().astimezone().isoformat(timespec="seconds")}
        data = (json.dumps(info) + "\n").encode("utf-8")
        try:
            os.ftruncate(self._fd, 0)
            os.pwrite(self._fd, data, 0)
        except OSError:
            pass  # the lock holds without its description


def _flock(fd: int) -> None:
    assert fcntl is not None
    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)


def _holder(fd: int) -> dict[str, Any]:
    """The holder's description from the lock file (it writes it just after locking: wait
    up to 0.5 s for it)."""
    deadline = time.monotonic() + 0.5
    while True:
        try:
            text = os.pread(fd, 4096, 0).decode("utf-8", "replace")
            info = json.loads(text)
            if isinstance(info, dict) and "pid" in info:
                return info
        except (OSError, ValueError):
            pass
        if time.monotonic() > deadline:
            return {}
        time.sleep(0.02)


def _describe(holder: dict[str, Any]) -> str:
    if not holder:
        return "its PID is unknown (it has not written it yet)"
    where = "" if holder.get("host") in (None, socket.gethostname()) else \
        f" on {holder['host']}"
    return (f"PID {holder.get('pid')}{where} ({holder.get('command', 'a demfem job')}, "
            f"started {holder.get('started', '?')})")
