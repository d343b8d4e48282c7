"""The published JSON Schemas (schemas/): current with the code, every shipped train file valid against the train
schema and known-bad ones not, and report.json of a real run valid against the report schema."""

from __future__ import annotations

import copy
import json
import tomllib
from pathlib import Path

import pytest
from jsonschema import Draft202012Validator

import gearcheck
from gearcheck.compare.engine.diagnosis import Evidence, diagnose
from gearcheck.compare.presentation.schemas import SCHEMA_FILES, write_schemas
from gearcheck.lumped.assembly import build_model
from gearcheck.train.loader import load_text, preset_names, preset_text
from gearcheck.shared.errors import GearcheckError

ROOT = Path(__file__).resolve().parents[1]
SHIPPED = ROOT / "schemas"
DATA = Path(__file__).parent / "data"
# tests/data/invalid files whose mistake is a single field's (the rest need the loader's cross-field checks)
FIELD_ERRORS = ["inf_bearing", "missing_input_speed", "missing_operating", "negative_mass", "negative_support",
                "speed_negative", "stiffness_extra_param", "teeth_not_integer", "tolerance_negative",
                "unknown_key", "unknown_stiffness_model", "unknown_table", "wrong_type"]


def validator(name: str) -> Draft202012Validator:
    schema = json.loads((SHIPPED / name).read_text(encoding="utf-8"))
    Draft202012Validator.check_schema(schema)
    return Draft202012Validator(schema)


@pytest.fixture(scope="module")
def train_validator():
    return validator("train.schema.json")


def test_the_shipped_schemas_are_current(tmp_path):
    """Regenerate them (``python -m gearcheck.compare.presentation.schemas schemas/``) and compare byte for byte."""
    assert sorted(p.name for p in SHIPPED.iterdir()) == sorted(SCHEMA_FILES)
    for path in write_schemas(tmp_path):
        assert path.read_bytes() == (SHIPPED / path.name).read_bytes(), f"{path.name} is stale: regenerate it"


@pytest.mark.parametrize("source", [f"preset:{name}" for name in preset_names()] + [
    "tests/data/stepped-planet.toml", "docs/hub-drive-calibration/fit/hub-drive-calibrated.toml"])
def test_every_shipped_train_file_is_valid(source, train_validator):
    text = preset_text(source[7:]) if source.startswith("preset:") else (ROOT / source).read_text(encoding="utf-8")
    errors = [e.message for e in train_validator.iter_errors(tomllib.loads(text))]
    assert not errors, errors


@pytest.mark.parametrize("name", FIELD_ERRORS)
def test_known_bad_train_files_fail(name, train_validator):
    text = (DATA / "invalid" / f"{name}.toml").read_text(encoding="utf-8")
    with pytest.raises(GearcheckError):  # the loader refuses it too
        load_text(text, name)
    assert not train_validator.is_valid(tomllib.loads(text))


def demo() -> dict:
    return tomllib.loads(preset_text("demo-3p"))


@pytest.mark.parametrize("what, edit", [
    ("a key of another stiffness model",
     lambda d: d["stages"][0]["mesh"]["stiffness"].update(model="energy", mean=1e9)),
    ("a stiffness model's parameter out of bounds",
     lambda d: d["stages"][0]["mesh"].update(stiffness={"model": "energy", "poisson_ratio": 0.6})),
    ("the default model without its mean", lambda d: d["stages"][0]["mesh"].update(stiffness={})),
    ("a tolerance without a metric", lambda d: d.update(tolerances={"mesh_force": 0.01})),
    ("a tolerance of zero", lambda d: d.update(tolerances={"mesh_force": {"nrmse": 0}})),
    ("a name the pattern refuses", lambda d: d["train"].update(name="demo 3p")),
    ("an unknown reference key", lambda d: d["train"].update(references=["nobody-2030"])),
    ("a band of one frequency", lambda d: d.update(measurements=[
        {"quantity": "stage1.ring.ay.world", "metric": "rms", "value": 1.0, "sensor_band_hz": [5.0]}])),
    ("a measurement's unknown metric", lambda d: d.update(measurements=[
        {"quantity": "stage1.ring.ay.world", "metric": "mean", "value": 1.0}])),
    ("a bad compound planet gear", lambda d: d["stages"][0]["planet"].update(gears={"f": {"teeth": 0}})),
])
def test_bad_fields_fail_the_schema_as_the_loader(what, edit, train_validator):
    doc = demo()
    assert train_validator.is_valid(doc)
    edit(doc)
    assert not train_validator.is_valid(doc), what


def test_good_variants_pass():
    """Dotted tolerance keys arrive nested; a quantity's key is quoted; the default stiffness model needs no name."""
    schema = validator("train.schema.json")
    doc = demo()
    doc["tolerances"] = {"mesh_force": {"nrmse": 0.02}, "stage1.planet1.sun.force.nrmse": 0.5}
    doc["stages"][0]["mesh"]["stiffness"] = {"mean": 5e8}
    assert schema.is_valid(doc), [e.message for e in schema.iter_errors(doc)]


def test_report_json_of_a_real_run_is_valid(tmp_path, demo_check):
    schema = validator("report.schema.json")
    demo_check.write(tmp_path)
    data = json.loads((tmp_path / "report.json").read_text(encoding="utf-8"))
    errors = [f"{list(e.absolute_path)}: {e.message}" for e in schema.iter_errors(data)]
    assert not errors, errors
    # a user's model adds a diagnosis
    model = build_model(gearcheck.load("demo-3p"))
    with_diagnosis = copy.deepcopy(data)
    with_diagnosis["diagnosis"] = json.loads(json.dumps(diagnose(model, Evidence.of_model(model)).to_dict()))
    assert schema.is_valid(with_diagnosis)
    for drift in ({"unknown_field": 1}, {"verdict": {**data["verdict"], "verdict": "MAYBE"}}, {"solvers": None}):
        assert not schema.is_valid({**data, **drift}), drift
