"""Requirements of the report (reports/report.py): it renders for a suite with
failed, crashed and pending cases and for the stored gold results directory;
report.html is self-contained; orders.csv holds the observed orders."""
import csv
import re
from pathlib import Path

import pytest

import gate
import report
from conftest import SYNTHETIC_SUITE, synthetic_ring_cases, write_suite_directory

GOLD = Path(__file__).parent / "gold"


def render(directory, output):
    written, figure_count = report.write_report(directory, output)
    return written, figure_count


@pytest.fixture(scope="module")
def synthetic_report(tmp_path_factory):
    """The report of the synthetic suite of conftest.py, rendered once for this module."""
    directory = write_suite_directory(tmp_path_factory.mktemp("suite"), SYNTHETIC_SUITE, synthetic_ring_cases())
    output = directory / "report"
    written, figure_count = render(directory, output)
    return output, written, figure_count


def test_report_renders_with_failed_crashed_and_pending_cases(synthetic_report):
    """Requirement: a report never stops on a case that failed, crashed or is pending;
    every case is listed with its status, and the figures are embedded."""
    output, written, figure_count = synthetic_report
    page = written["html"].read_text()
    for case_id, status in (("ring-method=linear-cells=64", "failed"), ("ring-method=linear-cells=128", "crashed"),
                            ("ring-method=cpdi-cells=256", "pending")):
        assert re.search(f"<td>{re.escape(case_id)}</td><td>{status}</td>", page)
    pngs = sorted((output / "figures").glob("*.png"))
    assert figure_count == len(pngs) >= 6
    assert page.count("src='data:image/png;base64,") == figure_count
    assert "non-positive J" in page and "signal 11 (SIGSEGV)" in page
    markdown = written["markdown"].read_text()
    assert all(f"](figures/{p.name})" in markdown for p in pngs)


def test_report_html_is_self_contained(synthetic_report):
    """Requirement: report.html links nothing outside itself."""
    page = synthetic_report[1]["html"].read_text()
    assert not re.search(r"(src|href)\s*=\s*['\"](?!data:)", page)
    assert "http://" not in page and "https://" not in page


def test_orders_csv_holds_the_exact_order_of_the_synthetic_series(synthetic_report):
    """Requirement: orders.csv has one row per (study, series, norm, time) with the
    pairwise and least-squares orders; the cpdi series (0.5 h^2) gives 2.000."""
    with open(synthetic_report[1]["orders"]) as stream:
        rows = list(csv.DictReader(stream))
    keys = {(r["study"], r["series"], r["norm"], r["time"]) for r in rows}
    assert len(keys) == len(rows) == 2 * 3                     # 2 series x 3 norms at the end time
    cpdi = next(r for r in rows if r["series"] == "method=cpdi" and r["norm"] == "L1_theta0")
    assert abs(float(cpdi["ls_order"]) - 2.0) < 1e-12
    assert [abs(float(p) - 2.0) < 1e-12 for p in cpdi["pairwise_orders"].split(";")] == [True, True]
    assert cpdi["levels"] == "32;64;128" and cpdi["classification"] == "asymptotic"
    assert "256: pending" in cpdi["left_out"]
    linear = next(r for r in rows if r["series"] == "method=linear" and r["norm"] == "L1_theta0")
    assert linear["levels"] == "32;256" and "64: no output at t = 1" in linear["left_out"]


def test_report_survives_a_damaged_results_file_and_a_missing_suite_file(tmp_path):
    """Requirement: an unreadable results file and a directory without suite.toml
    still give a report; the damaged case is listed with why it has no results."""
    directory = write_suite_directory(tmp_path / "suite", SYNTHETIC_SUITE, synthetic_ring_cases())
    (directory / "cases" / "ring-method=cpdi-cells=64.h5").write_bytes(b"not an HDF5 file")
    (directory / "suite.toml").unlink()
    page = render(directory, tmp_path / "out")[0]["html"].read_text()
    assert "unreadable results file" in page


def test_report_exit_2_for_a_directory_that_is_not_a_suite(tmp_path, capsys):
    """Requirement: one clear line and exit 2 for a missing manifest."""
    assert report.main([str(tmp_path)]) == 2
    assert "manifest.json: missing" in capsys.readouterr().err


def test_gold_results_directory_renders_and_gates(tmp_path):
    """Requirement: the stored gold suite output (reports/gold/, committed by the
    suite runner) renders without error, and the gate reads every expectation."""
    if not (GOLD / "manifest.json").is_file():
        pytest.skip("reports/gold/manifest.json is not there yet: the suite runner's gold output directory "
                    "(mpmvv suite ... -o reports/gold) has not been committed")
    written, figure_count = render(GOLD, tmp_path / "gold-report")
    assert written["html"].stat().st_size > 0 and figure_count > 0
    assert gate.main([str(GOLD)]) in (0, 1)
