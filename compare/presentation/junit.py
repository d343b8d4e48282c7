"""What a CI system reads: cross-checks as JUnit XML.

:func:`write_junit` writes one ``<testsuite>`` per cross-check (named by its train) and in it one
``<testcase>`` per compared quantity, per mode, for the steady state and, when a baseline was checked, for
the baseline.  Statuses map onto JUnit as follows:

* ``pass`` -- a passed testcase;
* ``fail`` -- a ``<failure>`` whose message is the NRMSE (a mode: the relative frequency difference) against
  the tolerance;
* ``negligible`` -- a passed testcase with the property ``status = negligible``: the quantity was compared and
  is below the negligibility floor in both solvers, which is a result, not a test that did not run;
* ``unresolved`` -- an ``<error>``: the integration error estimates reach the tolerance, so the check could not
  decide; like the verdict INCONCLUSIVE (exit 3) it must not read as a pass, which a skip would in most CI
  tools.  A run without a steady state gives its ``steady state`` testcase an ``<error>`` for the same reason;
* metrics moved from the baseline -- a ``<failure>`` of the ``baseline`` testcase listing them.

Nothing is skipped.  Every testcase carries its status and numbers as properties.  The file is the same byte
for byte for the same reports, except the ``time`` attributes: a suite's is the wall time of its runs (the
report's volatile part), a testcase's 0 (every quantity comes from the same runs).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

from gearcheck.compare.presentation.report import solver_names, to_dict
from gearcheck.shared.outputs import write_file


def _number(x) -> str:
    return "" if x is None else f"{x:.6g}"


def _properties(parent: ET.Element, values: dict) -> None:
    props = ET.SubElement(parent, "properties")
    for name, value in values.items():
        ET.SubElement(props, "property", name=name, value=str(value))


def _case(suite: ET.Element, classname: str, name: str, properties: dict) -> ET.Element:
    case = ET.SubElement(suite, "testcase", classname=classname, name=name, time="0")
    _properties(case, properties)
    return case


def _quantity_case(suite, data, q) -> None:
    A, B = solver_names(data)
    nrmse, tol = q["errors"]["nrmse"], q["tolerance_nrmse"]
    nrmse, tol = nrmse and nrmse["value"], tol and tol["value"]
    case = _case(suite, f"gearcheck.{data['train']['name']}.{q['kind']}", q["name"],
                 {"status": q["status"], "nrmse": _number(nrmse), "tolerance_nrmse": _number(tol), "unit": q["unit"]})
    if q["status"] == "fail":
        lines = [s for s in q["spectrum"] if s["status"] == "fail"]
        detail = [f"RMS {A} {_number(q['reference']['rms']['value'])} {q['unit']}, {B} "
                  f"{_number(q['test']['rms']['value'])} {q['unit']}; correlation "
                  f"{_number(q['errors']['correlation'] and q['errors']['correlation']['value'])}; lag "
                  f"{_number(q['errors']['lag']['value'])} s"]
        detail += [f"spectral line {s['line']} ({_number(s['frequency']['value'])} Hz): relative error "
                   f"{_number(s['rel_error']['value'])} (advisory)" for s in lines]
        ET.SubElement(case, "failure", message=f"NRMSE {_number(nrmse)} > tolerance {_number(tol)}",
                      type="ToleranceExceeded").text = "\n".join(detail)
    elif q["status"] == "unresolved":
        errors = q["integration_error"]
        bounds = " + ".join(_number(e and e["value"]) for e in (errors["reference"], errors["test"]))
        ET.SubElement(case, "error", type="Unresolved",
                      message=f"integration error estimates {bounds} reach the tolerance {_number(tol)}: the "
                              f"comparison cannot decide (NRMSE {_number(nrmse)})")


def _mode_case(suite, data, m) -> None:
    A, B = solver_names(data)
    tol, rel = data["modes_tolerance"]["value"], m["rel_error"]["value"]
    case = _case(suite, f"gearcheck.{data['train']['name']}.modes", f"mode {m['mode']}",
                 {"status": m["status"], "type": m["type"], "frequency_hz": _number(m["reference"]["value"]),
                  "rel_error": _number(rel), "tolerance": _number(tol)})
    if m["status"] == "fail":
        ET.SubElement(case, "failure", type="ToleranceExceeded",
                      message=f"relative frequency difference {_number(rel)} > tolerance {_number(tol)} ({A} "
                              f"{_number(m['reference']['value'])} Hz, {B} {_number(m['test']['value'])} Hz)")


def _suite(root: ET.Element, data: dict) -> ET.Element:
    train = data["train"]["name"]
    s, v = data["settings"], data["verdict"]
    wall = sum(t["value"] for t in data["volatile"]["wall_time"].values())
    suite = ET.SubElement(root, "testsuite", name=train, tests="0", failures="0", errors="0", skipped="0",
                          time=f"{wall:.3f}")
    _properties(suite, {"verdict": v["verdict"], "reference": data["solvers"]["reference"],
                        "test": data["solvers"]["test"], "input_speed_rpm": _number(s["input_speed"]["value"]),
                        "simulated_s": _number(s["simulated"]["value"]), "train_file": data["provenance"]["train_file"],
                        "train_sha256": data["provenance"]["train_sha256"]})
    for q in data["quantities"]:
        _quantity_case(suite, data, q)
    for m in data["modes"]:
        _mode_case(suite, data, m)
    steady = data["steady_state"]
    case = _case(suite, f"gearcheck.{train}.run", "steady state",
                 {"status": steady["how"] or "none", "start_s": _number(steady["start"]["value"])})
    if not steady["detected"]:
        ET.SubElement(case, "error", type="NoSteadyState",
                      message="no steady state in the run: the comparison cannot decide (run longer: --duration)")
    if v["moved_from_baseline"] is not None:
        moved = v["moved_from_baseline"]
        case = _case(suite, f"gearcheck.{train}.run", "baseline", {"moved": str(len(moved))})
        if moved:
            ET.SubElement(case, "failure", type="BaselineMoved",
                          message=f"{len(moved)} metrics moved from the baseline").text = "\n".join(moved)
    cases = suite.findall("testcase")
    suite.set("tests", str(len(cases)))
    suite.set("failures", str(sum(c.find("failure") is not None for c in cases)))
    suite.set("errors", str(sum(c.find("error") is not None for c in cases)))
    return suite


def junit_xml(results) -> str:
    """The JUnit XML text of cross-checks: ``results`` are CrosscheckResults or their report dicts
    (:func:`gearcheck.compare.presentation.report.to_dict`)."""
    root = ET.Element("testsuites", name="gearcheck crosscheck")
    suites = [_suite(root, r if isinstance(r, dict) else to_dict(r)) for r in results]
    for key in ("tests", "failures", "errors", "skipped"):
        root.set(key, str(sum(int(s.get(key)) for s in suites)))
    root.set("time", f"{sum(float(s.get('time')) for s in suites):.3f}")
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def write_junit(results, path) -> None:
    """Write :func:`junit_xml` of ``results`` to ``path``, whole or not at all."""
    write_file(path, junit_xml(results), "--junit")
