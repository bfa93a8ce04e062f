"""The gate's verdicts as files that CI systems read: JUnit XML (GitLab,
Jenkins and GitHub Actions show one test case per expectation and series,
failed with the reasons the table gives) and JSON (every number the row is
made of: each level's h and error, the fitted order with its interval, the
band, the bounds). Written by `mpmvv gate DIR --junit FILE --json FILE`
beside the table, with the same verdicts (reports/gate.py).

JSON: {"suite", "expectations", "holds", "verdicts": [{"number", "study",
"series", "norm", "time", "status", "observed": {"order", "ci_low", "ci_high",
"error_constant", "floor"}, "expected": {"order", "tolerance", "max_error",
"max_error_constant", "at_roundoff", "must_complete"}, "levels": [{"value", "h", "error",
"used", "reason", "case"}], "reasons", "notes", "warnings"}]}; a number
that is not finite (no fit, an unusable level) is null.
"""
import json
import math
import os
import stat
import xml.etree.ElementTree as ET
from pathlib import Path

from .gate import series_description, verdict_row


def _number(x):
    """x as JSON has it: a finite float, or None."""
    try:
        x = float(x)
    except (TypeError, ValueError):
        return None
    return x if math.isfinite(x) else None


def _observed(verdict):
    shown = "order" in verdict.expectation and not verdict.floor
    fit = verdict.fit
    return {"order": _number(fit.order) if shown else None,
            "ci_low": _number(fit.ci_low) if shown else None,
            "ci_high": _number(fit.ci_high) if shown else None,
            "error_constant": _number(verdict.error_constant),
            "floor": verdict.floor}


def _expected(expect):
    return {"order": _number(expect.get("order")), "tolerance": _number(expect.get("tolerance")),
            "max_error": _number(expect.get("max_error")),
            "max_error_constant": _number(expect.get("max_error_constant")),
            "at_roundoff": bool(expect.get("at_roundoff", False)),
            "must_complete": bool(expect.get("must_complete", True))}


def verdict_record(verdict):
    expect = verdict.expectation
    return {
        "number": verdict.number,
        "study": expect["study"],
        "series": series_description(expect.get("where", {}), verdict.series),
        "norm": expect["norm"],
        "time": _number(expect.get("time")) if "time" in expect else "end",
        "status": "pass" if verdict.passed else "fail",
        "observed": _observed(verdict),
        "expected": _expected(expect),
        "levels": [{"value": level.value, "h": _number(level.h), "error": _number(level.error),
                    "used": not level.reason, "reason": level.reason or None,
                    "case": level.case.id if level.case is not None else None}
                   for level in verdict.levels],
        "reasons": list(verdict.reasons),
        "notes": list(verdict.notes),
        "warnings": list(verdict.warnings),
    }


def gate_record(suite, verdicts):
    return {"suite": suite.name, "expectations": len(suite.expectations),
            "holds": all(v.passed for v in verdicts) and not suite.problems,
            "problems": list(suite.problems),
            "verdicts": [verdict_record(v) for v in verdicts]}


def write_atomically(path, text):
    """`text` under `path` whole or not at all (a full disk leaves no partial file under the name).
    A `path` that is not a regular file (a device as /dev/stdout or /dev/full, a
    FIFO) is written to, never replaced, and a failed write or flush raises OSError."""
    path = Path(path)
    try:
        existing = path.stat().st_mode
    except OSError:
        existing = None
    if existing is not None and not stat.S_ISREG(existing) and not stat.S_ISDIR(existing):
        with open(path, "w", encoding="utf-8") as stream:
            stream.write(text)
            stream.flush()
        return
    temporary = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        temporary.write_text(text, encoding="utf-8")
        os.replace(temporary, path)
    finally:
        temporary.unlink(missing_ok=True)


def write_json(path, suite, verdicts):
    write_atomically(path, json.dumps(gate_record(suite, verdicts), indent=1, allow_nan=False) + "\n")


def junit_tree(suite, verdicts):
    """<testsuites><testsuite name=SUITE> with one <testcase> per verdict; a
    failing one holds a <failure> with the reasons; the row's observed and
    expected values are the test case's properties and its system-out."""
    failures = sum(not v.passed for v in verdicts) + bool(suite.problems)
    tests = len(verdicts) + bool(suite.problems)
    root = ET.Element("testsuites", name="mpmvv gate", tests=str(tests), failures=str(failures))
    group = ET.SubElement(root, "testsuite", name=suite.name, tests=str(tests), failures=str(failures),
                          errors="0", skipped="0")
    if suite.problems:
        # Results not checked to be their cases' (reports/consistency.py): the gate's first failure.
        case = ET.SubElement(group, "testcase", classname=f"{suite.name}.results", name="results match their cases")
        failure = ET.SubElement(case, "failure", message=f"{len(suite.problems)} result problem(s)",
                                type="consistency")
        failure.text = "\n".join(suite.problems)
    for verdict in verdicts:
        row = verdict_row(verdict)
        record = verdict_record(verdict)
        case = ET.SubElement(group, "testcase", classname=f"{suite.name}.{record['study']}",
                             name=f"#{verdict.number} {record['norm']} ({record['series']})")
        properties = ET.SubElement(case, "properties")
        for name, value in (("levels", row[5]), ("observed order [95% CI]", row[6]), ("expected", row[7]),
                            ("E/h^p or E", row[8]), ("t", row[4])):
            ET.SubElement(properties, "property", name=name, value=value)
        if not verdict.passed:
            failure = ET.SubElement(case, "failure", message="; ".join(verdict.reasons), type="expectation")
            failure.text = "\n".join(verdict.reasons)
        notes = verdict.warnings + verdict.notes
        ET.SubElement(case, "system-out").text = (
            f"observed {row[6]}, expected {row[7]}, {row[8]}" + ("".join(f"\n{n}" for n in notes)))
    return ET.ElementTree(root)


def write_junit(path, suite, verdicts):
    tree = junit_tree(suite, verdicts)
    ET.indent(tree)
    write_atomically(path, "<?xml version='1.0' encoding='utf-8'?>\n" +
                      ET.tostring(tree.getroot(), encoding="unicode") + "\n")
