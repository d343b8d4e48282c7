"""Reading the files a user names: train files, measurement and tolerance files, torque profiles.

Every failure is a :class:`~gearcheck.shared.errors.GearcheckError` naming the file and what is wrong:
missing, a directory, unreadable, larger than ``MAX_BYTES`` (no train or data file is), not UTF-8 (with
the byte offset), not TOML, or nested deeper than Python's parser recurses.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

from gearcheck.shared.errors import GearcheckError, TrainFileError

MAX_BYTES = 16 * 1024 * 1024


def read_text(path: str | Path, what: str = "file") -> str:
    """The UTF-8 text of ``path``; ``what`` names it in messages ("train file", "measurements file")."""
    path = Path(path)
    try:
        if path.is_dir():
            raise GearcheckError(f"{path}: is a directory, not a {what}")
        size = path.stat().st_size
        if size > MAX_BYTES:
            raise GearcheckError(f"{path}: {size / 2**20:.1f} MiB is too large for a {what} "
                                 f"(at most {MAX_BYTES // 2**20} MiB)")
        data = path.read_bytes()
    except FileNotFoundError:
        raise GearcheckError(f"{path}: no such {what}") from None
    except OSError as exc:
        raise GearcheckError(f"{path}: cannot read the {what}: {exc.strerror or exc}") from None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        byte = data[exc.start:exc.start + 1]
        raise GearcheckError(f"{path}: the {what} is not UTF-8 text (byte {exc.start}: {byte!r})") from None


def parse_toml(text: str, source: str) -> dict:
    """The TOML document of ``text``; errors name ``source``."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise TrainFileError(source, "", f"not valid TOML: {exc}") from None
    except RecursionError:
        raise TrainFileError(source, "", "not valid TOML: nested too deeply") from None


def read_toml(path: str | Path, what: str = "file") -> dict:
    return parse_toml(read_text(path, what), str(path))
