"""Requirements of summary.json (reports/summary_file.py): one file that holds
every case's state, the gate's verdicts and orders.csv's rows, with the same
values as the files it joins, numbers as numbers and nothing that is not JSON."""
import csv
import json
import math

from .conftest import SYNTHETIC_SUITE, synthetic_ring_cases, write_suite_directory
from . import report


def test_summary_joins_cases_gate_and_orders(tmp_path):
    directory = write_suite_directory(tmp_path / "suite", SYNTHETIC_SUITE, synthetic_ring_cases())
    written, _ = report.write_report(directory, tmp_path / "report")
    text = written["summary"].read_text()
    assert "NaN" not in text and "Infinity" not in text
    summary = json.loads(text)
    manifest = json.loads((directory / "manifest.json").read_text())
    assert [c["id"] for c in summary["cases"]] == [c["id"] for c in manifest["cases"]]
    assert {c["id"]: c["status"] for c in summary["cases"]} == {c["id"]: c["status"] for c in manifest["cases"]}
    assert sum(summary["status_counts"].values()) == len(manifest["cases"])
    failed = next(c for c in summary["cases"] if c["status"] == "failed")
    assert failed["failure_reason"] and failed["keys"]["method"] == "linear"
    with open(written["orders"]) as stream:
        rows = list(csv.DictReader(stream))
    assert len(summary["orders"]) == len(rows)
    for row, record in zip(rows, summary["orders"]):
        assert list(record) == list(row)
        for name, cell in row.items():
            value = record[name]
            if isinstance(value, (int, float)):
                assert math.isclose(value, float(cell), rel_tol=0, abs_tol=0)
            elif value is None:
                assert cell in ("", "nan")
            else:
                assert value == cell
    gate = summary["gate"]
    assert gate["expectations"] == len(manifest["expectations"]) and isinstance(gate["holds"], bool)
    assert all(v["status"] in ("pass", "fail") for v in gate["verdicts"])
