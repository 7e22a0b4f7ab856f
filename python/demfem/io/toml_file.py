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
        data = path.read_bytes()
    except OSError as exc:
        raise DemfemIOError(f"i/o error on {path}: {exc.strerror or exc}") from None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise InvalidParameterError(
            f"invalid scene file {path}: not UTF-8 text (byte 0x{data[exc.start]:02x} at "
            f"position {exc.start}); a scene file is TOML text — is it the right file?") from None
    if "\x00" in text:
        raise InvalidParameterError(
            f"invalid scene file {path}: it holds a NUL byte (position {text.index(chr(0))}): "
            "a binary file, not TOML text — is it the right file?")
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InvalidParameterError(f"invalid TOML in {path}: {exc}") from None
    except RecursionError:
        raise InvalidParameterError(f"invalid TOML in {path}: nested too deeply") from None
