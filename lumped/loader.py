"""Reading train files and shipped presets.

``TRAIN`` arguments are a preset name (``demo-3p``) or a path to a TOML file.
"""

from __future__ import annotations

import hashlib
import tomllib
from importlib import resources
from pathlib import Path

from . import schema
from .errors import GearcheckError, TrainFileError
from .spec import TrainSpec, build_spec

PRESET_PACKAGE = "lumped.presets"


def preset_names() -> list[str]:
    files = resources.files(PRESET_PACKAGE)
    return sorted(p.name[:-5] for p in files.iterdir() if p.name.endswith(".toml"))


def preset_text(name: str) -> str:
    return resources.files(PRESET_PACKAGE).joinpath(f"{name}.toml").read_text(encoding="utf-8")


def load_text(text: str, source: str) -> TrainSpec:
    """Parse and validate TOML text; ``source`` names it in error messages."""
    try:
        document = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise TrainFileError(source, "", f"not valid TOML: {exc}") from None
    data = schema.parse(document, source)
    return build_spec(data, source, hashlib.sha256(text.encode("utf-8")).hexdigest())


def load_train(train: str | Path) -> TrainSpec:
    """A preset by name or a train file by path, validated."""
    text, source = read_train_text(train)
    return load_text(text, source)


def read_train_text(train: str | Path) -> tuple[str, str]:
    """(TOML text, source label) of a preset name or a file path."""
    name = str(train)
    if name in preset_names():
        return preset_text(name), f"preset:{name}"
    path = Path(name)
    if not path.exists():
        known = ", ".join(preset_names())
        raise GearcheckError(f"{name}: no such train file or preset (presets: {known})")
    try:
        return path.read_text(encoding="utf-8"), str(path)
    except (OSError, UnicodeDecodeError) as exc:
        raise GearcheckError(f"{name}: cannot read: {exc}") from None
