"""summary.json: the one machine-readable file of a suite's report. It joins
what the other files say in parts: each case's state (manifest.json) and run
(its results file), the gate's verdicts (the records of `mpmvv gate --json`,
gate_files.py) and every row of orders.csv, so a CI job or a dashboard reads
a suite from one file.

{"format_version": 1, "suite", "description", "directory", "generated",
 "status_counts": {status: count},
 "problems": [results not their cases' or damaged, one line each (consistency.py)],
 "cases": [{"id", "study", "keys" (the keys its study sweeps or zips),
            "status", "health", "failure_reason", "time_reached", "h",
            "particle_count", "steps", "wall_time_s", "external" (run by
            another program: external_command), "results" (path, relative to
            the directory), "problems" (this case's)}],
 "gate": {"expectations", "holds", "verdicts": [...]} or null without
         expectations (or when they could not be checked: "gate_error"),
 "orders": [{column of orders.csv: value}]}
A number that is not finite is null.
"""
import json
import numbers

from .gate_files import _number, gate_record, write_atomically
from .report_rows import ORDERS_CSV_COLUMNS
from .report_tables import order_row_values


def _integer(v):
    """A count as JSON has it: an int, or None."""
    return int(v) if isinstance(v, numbers.Integral) and not isinstance(v, bool) else None


def _value(v):
    """An orders.csv value as JSON has it: numbers as numbers (None when not finite), an empty cell None."""
    if isinstance(v, numbers.Integral) and not isinstance(v, bool):
        return int(v)
    if isinstance(v, numbers.Real):
        return _number(v)
    return None if v in ("", None) else v


def case_record(suite, case):
    keys = {k: case.keys[k] for k in suite.varied_keys(case.study) if k in case.keys}
    path = case.results_path
    try:
        path = str(path.relative_to(suite.directory))
    except (ValueError, AttributeError):
        path = str(path)
    return {"id": case.id, "study": case.study, "keys": keys, "status": case.status,
            "health": case.attribute("health", None), "failure_reason": case.failure_reason or None,
            "time_reached": _number(case.time_reached), "h": _number(case.h),
            "particle_count": _integer(case.attribute("particle_count")), "steps": _integer(case.attribute("steps")),
            "wall_time_s": _number(case.wall_time_s), "external": bool(case.keys.get("external_command")),
            "results": path, "problems": list(case.problems)}


def summary_record(report):
    suite = report.suite
    names = [name for name, _ in ORDERS_CSV_COLUMNS]
    record = {"format_version": 1, "suite": suite.name, "description": suite.description,
              "directory": str(suite.directory), "generated": report.generated.isoformat(timespec="seconds"),
              "status_counts": report.status_counts,
              "problems": list(suite.problems),
              "cases": [case_record(suite, c) for c in suite.cases],
              "gate": gate_record(suite, report.verdicts) if report.verdicts is not None else None,
              "orders": [dict(zip(names, map(_value, order_row_values(r)))) for r in report.order_rows]}
    if report.gate_error:
        record["gate_error"] = report.gate_error
    return record


def write_summary(path, report):
    write_atomically(path, json.dumps(summary_record(report), indent=1, allow_nan=False) + "\n")
