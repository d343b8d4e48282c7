"""Regression baselines: the metrics of a stored cross-check, and what moved since.

A baseline keeps, per quantity, the RMS and peak-to-peak of both solvers and the NRMSE,
and every natural frequency of both solvers, with the run settings (duration, speed).
A metric has moved when

* an RMS or peak-to-peak changed by more than the quantity's NRMSE tolerance, relatively;
* an NRMSE changed by more than half its tolerance, absolutely;
* a natural frequency changed by more than the frequency tolerance, relatively.

Baselines of the shipped presets live in ``compare/engine/baselines/PRESET.json``.
"""

from __future__ import annotations

import json
from pathlib import Path

from gearcheck.train.files import read_text
from gearcheck.shared.errors import GearcheckError
from gearcheck.shared.outputs import write_file

BASELINE_DIR = Path(__file__).parent / "baselines"
VERSION = 2  # 2: the sides' metrics keyed reference_* and test_* (1: lumped_* and mujoco_*, read as 2's)
RENAMED = (("lumped_", "reference_"), ("mujoco_", "test_"))


def snapshot(result) -> dict:
    quantities = {}
    for q in result.quantities:
        m = q.metrics
        quantities[q.name] = {
            "kind": q.kind, "status": q.status, "tolerance": q.tolerance, "nrmse": m["nrmse"],
            "reference_rms": m["reference"]["rms"], "test_rms": m["test"]["rms"],
            "reference_peak_to_peak": m["reference"]["peak_to_peak"], "test_peak_to_peak": m["test"]["peak_to_peak"],
        }
    return {
        "baseline_version": VERSION, "train": result.spec.name,
        "duration_s": result.settings["duration_s"], "input_speed_rpm": result.settings["input_speed_rpm"],
        "modes": [{"mode": r["mode"], "reference_hz": r["reference_hz"], "test_hz": r["test_hz"]}
                  for r in result.modal],
        "modes_tolerance": result.modal_tolerance, "quantities": quantities,
    }


def write_baseline(result, path: str | Path) -> None:
    write_file(path, json.dumps(snapshot(result), indent=2, sort_keys=True) + "\n", "baseline")


NUMBER = (int, float)
QUANTITY_KEYS = ("reference_rms", "test_rms", "reference_peak_to_peak", "test_peak_to_peak")


def read_baseline(path: str | Path) -> dict:
    """A stored baseline, its structure checked (every entry the comparison reads, with its type)."""
    try:
        data = json.loads(read_text(path, "baseline"))
    except json.JSONDecodeError as exc:
        raise GearcheckError(f"{path}: the baseline is not JSON: {exc}") from None
    if isinstance(data, dict) and data.get("baseline_version") == 1:
        data = _renamed(data)
    if not isinstance(data, dict) or data.get("baseline_version") != VERSION:
        found = data.get("baseline_version") if isinstance(data, dict) else type(data).__name__
        raise GearcheckError(f"{path}: not a gearcheck baseline of version {VERSION} or 1 (found {found!r})")

    def need(ok: bool, what: str):
        if not ok:
            raise GearcheckError(f"{path}: not a valid baseline: {what}")

    for key, kind in (("train", str), ("duration_s", NUMBER), ("input_speed_rpm", NUMBER),
                      ("modes_tolerance", NUMBER), ("modes", list), ("quantities", dict)):
        need(isinstance(data.get(key), kind), f"{key} missing or not a {getattr(kind, '__name__', 'number')}")
    for mode in data["modes"]:
        need(isinstance(mode, dict) and all(isinstance(mode.get(k), NUMBER) for k in ("mode", "reference_hz",
                                                                                       "test_hz")),
             f"modes entry {mode!r} needs numbers mode, reference_hz, test_hz")
    for name, q in data["quantities"].items():
        need(isinstance(q, dict) and all(isinstance(q.get(k), NUMBER) for k in QUANTITY_KEYS)
             and isinstance(q.get("status"), str) and isinstance(q.get("tolerance"), (*NUMBER, type(None)))
             and isinstance(q.get("nrmse"), (*NUMBER, type(None))),
             f"quantity {name!r} needs {', '.join(QUANTITY_KEYS)}, status, tolerance and nrmse")
    return data


def _renamed(data: dict) -> dict:
    """A version 1 baseline with version 2's keys (its entries' lumped_* and mujoco_* as reference_* and test_*)."""
    def keys(entry):
        if not isinstance(entry, dict):
            return entry
        for old, new in RENAMED:
            entry = {new + k[len(old):] if k.startswith(old) else k: v for k, v in entry.items()}
        return entry
    quantities = data.get("quantities")
    return {**data, "baseline_version": VERSION,
            "modes": [keys(m) for m in data["modes"]] if isinstance(data.get("modes"), list) else data.get("modes"),
            "quantities": {k: keys(q) for k, q in quantities.items()} if isinstance(quantities, dict) else quantities}


def _moved_rel(new, old, tol) -> bool:
    if new is None or old is None:
        return new is not old
    return abs(new - old) > tol * max(abs(old), 1e-300)


def baseline_path(baseline, name: str) -> Path | None:
    """Where the baseline ``baseline`` of the train ``name`` lies: None, "shipped" (the preset's own) or a path."""
    if baseline is None:
        return None
    return BASELINE_DIR / f"{name}.json" if str(baseline) == "shipped" else Path(baseline)


def check_settings(baseline: dict, duration: float, input_speed_rpm: float) -> None:
    """Refuse to compare runs made at another speed or over another duration than the baseline."""
    if abs(duration - baseline["duration_s"]) > 1e-12 or \
            abs(input_speed_rpm - baseline["input_speed_rpm"]) > 1e-9 * baseline["input_speed_rpm"]:
        raise GearcheckError(f"baseline of {baseline['train']} was taken at {baseline['input_speed_rpm']:.6g} rpm over "
                             f"{baseline['duration_s']:.6g} s; run with speed= and duration= to match")


def compare_to_baseline(result, baseline: dict) -> list[str]:
    """Descriptions of every metric that moved by more than its tolerance (empty: none did)."""
    now = snapshot(result)
    moved = []
    check_settings(baseline, now["duration_s"], now["input_speed_rpm"])
    tol_f = baseline["modes_tolerance"]
    for old, new in zip(baseline["modes"], now["modes"]):
        for key in ("reference_hz", "test_hz"):
            if _moved_rel(new[key], old[key], tol_f):
                moved.append(f"mode {old['mode']} {key}: {old[key]:.9g} -> {new[key]:.9g}")
    if len(baseline["modes"]) != len(now["modes"]):
        moved.append(f"number of modes: {len(baseline['modes'])} -> {len(now['modes'])}")
    for name, old in baseline["quantities"].items():
        new = now["quantities"].get(name)
        if new is None:
            moved.append(f"{name}: missing")
            continue
        tol = old["tolerance"] or 0.0
        for key in QUANTITY_KEYS:
            if old["status"] != "negligible" and _moved_rel(new[key], old[key], tol):
                moved.append(f"{name} {key}: {old[key]:.6g} -> {new[key]:.6g}")
        if old["status"] != "negligible" and old["nrmse"] is not None and new["nrmse"] is not None \
                and abs(new["nrmse"] - old["nrmse"]) > 0.5 * tol:
            moved.append(f"{name} nrmse: {old['nrmse']:.4g} -> {new['nrmse']:.4g}")
    return moved
