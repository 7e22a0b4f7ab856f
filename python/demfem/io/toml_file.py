"""Reading scene files: the TOML document at a path, with errors that name the file."""
from __future__ import annotations

from pathlib import Path
from typing import Any

try:  # Python >= 3.11
    import tomllib
except ModuleNotFoundError:  # pragma: no cover - Python < 3.11
    import tomli as tomllib  # type: ignore[no-redef]

from demfem.errors import DemfemIOError, InvalidParameterError


def read_toml(path: str | Path) -> dict[str, Any]:
    """The TOML document at ``path`` as a dict; an unreadable file raises
    :class:`DemfemIOError`, invalid TOML :class:`InvalidParameterError`, both naming it."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise DemfemIOError(f"i/o error on {path}: {exc.strerror or exc}") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InvalidParameterError(f"invalid TOML in {path}: {exc}") from None
