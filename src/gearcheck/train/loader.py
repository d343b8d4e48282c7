"""Reading train files and shipped presets.

``TRAIN`` arguments are a preset name (``demo-3p``) or a path to a TOML file.  Presets are package
data: they install with gearcheck.
"""

from __future__ import annotations

import hashlib
from importlib import resources
from pathlib import Path

from gearcheck.train import schema
from gearcheck.train.files import parse_toml, read_text
from gearcheck.train.kinematics import kinematics
from gearcheck.train.spec import TrainSpec, build_spec
from gearcheck.shared.errors import GearcheckError, TrainFileError, did_you_mean
from gearcheck.shared.units import checked_rpm, rpm_to_rad_s

PRESET_PACKAGE = "gearcheck.train.presets"


def preset_names() -> list[str]:
    files = resources.files(PRESET_PACKAGE)
    return sorted(p.name[:-5] for p in files.iterdir() if p.name.endswith(".toml"))


def preset_text(name: str) -> str:
    return resources.files(PRESET_PACKAGE).joinpath(f"{name}.toml").read_text(encoding="utf-8")


def load_text(text: str, source: str) -> TrainSpec:
    """Parse and validate TOML text; ``source`` names it in error messages.  The train must also be a
    mechanism that turns at a speed gears survive (:func:`gearcheck.train.kinematics.kinematics`)."""
    data = schema.parse(parse_toml(text, source), source)
    spec = build_spec(data, source, hashlib.sha256(text.encode("utf-8")).hexdigest())
    kin = kinematics(spec)
    if spec.operating.input_torque is not None:  # the load that balances it: T_out = T_in |w_in / w_out|
        spec = spec.with_operating(output_torque=spec.operating.input_torque * abs(kin.ratio))
    return spec


def load_train(train: str | Path | TrainSpec, speed: float | None = None) -> TrainSpec:
    """A preset by name, a train file by path, or a TrainSpec as it is, validated; ``speed`` (rpm)
    replaces the train's input speed."""
    spec = train if isinstance(train, TrainSpec) else load_text(*read_train_text(train))
    if speed is None:
        return spec
    spec = spec.with_operating(input_speed=rpm_to_rad_s(checked_rpm(speed)))
    try:
        kinematics(spec)
    except TrainFileError as exc:
        raise GearcheckError(f"speed {speed:g} rpm for {spec.name}: {exc.reason}") from None
    return spec


def read_train_text(train: str | Path) -> tuple[str, str]:
    """(TOML text, source label) of a preset name or a file path."""
    name = str(train)
    if name in preset_names():
        return preset_text(name), f"preset:{name}"
    path = Path(name)
    if not path.exists():
        raise GearcheckError(f"{name}: no such train file or preset"
                             + did_you_mean(name, preset_names(), "presets", cutoff=0.7))
    return read_text(path, "train file"), str(path)
