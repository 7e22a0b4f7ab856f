"""Atomic file writes: a reader (ParaView, a sweep that resumes, a second process) never sees a
half-written file, because the content goes to a temporary file in the same directory that is
then renamed over the target with :func:`os.replace` (atomic on POSIX and Windows)."""
from __future__ import annotations

import os
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator, Union

from demfem.errors import DemfemIOError

PathLike = Union[str, "os.PathLike[str]"]

__all__ = ["atomic_path", "write_bytes_atomic", "write_text_atomic", "savefig_atomic",
           "clean_stale_temporaries"]


@contextmanager
def atomic_path(path: PathLike, suffix: str = "") -> Iterator[Path]:
    """Yield a temporary path next to ``path``; on normal exit rename it onto ``path``.

    ``suffix`` is the temporary file's extension, for writers that infer the format from it
    (matplotlib, Pillow). On an exception the temporary file is removed and ``path`` is left
    untouched.
    """
    target = Path(path)
    directory = target.parent if str(target.parent) else Path(".")
    try:
        directory.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise DemfemIOError(f"i/o error on {target}: cannot create {directory}: {exc}") from None
    fd, tmp_name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp" + suffix,
                                    dir=directory)
    os.close(fd)
    tmp = Path(tmp_name)
    # mkstemp makes the file private (0600); give the result the usual permissions instead.
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)
    try:
        yield tmp
        # flush the content to disk before the rename makes it visible: after a crash the
        # target is either the old file or the complete new one
        with open(tmp, "rb") as fh:
            os.fsync(fh.fileno())
        os.replace(tmp, target)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def write_bytes_atomic(path: PathLike, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically; return the path."""
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)
    return Path(path)


def write_text_atomic(path: PathLike, text: str) -> Path:
    """Write UTF-8 ``text`` to ``path`` atomically; return the path."""
    return write_bytes_atomic(path, text.encode("utf-8"))


def savefig_atomic(fig, path: PathLike, **kwargs) -> Path:
    """Save a matplotlib figure to ``path`` atomically (format from the suffix)."""
    target = Path(path)
    with atomic_path(target, suffix=target.suffix) as tmp:
        fig.savefig(tmp, **kwargs)
    return target


def clean_stale_temporaries(folder: PathLike) -> list[Path]:
    """Remove the temporary files that :func:`atomic_path` left in ``folder`` (and its
    sub-folders) when a process died before renaming them (``.<name>.<random>.tmp*``);
    returns the paths removed. Call it at the start of a job that owns ``folder``."""
    root = Path(folder)
    removed: list[Path] = []
    if not root.is_dir():
        return removed
    for p in root.rglob(".*.tmp*"):
        if p.is_file() and ".tmp" in p.name:
            try:
                p.unlink()
            except OSError as exc:
                raise DemfemIOError(f"i/o error on {p}: cannot remove a stale temporary "
                                    f"file: {exc}") from None
            removed.append(p)
    return removed
