"""Requirements of the report (reports/report.py): it renders for a suite with
failed, crashed and pending cases and for the stored gold results directory;
report.html is self-contained; orders.csv holds the observed orders; the
contact-pressure and load-approach figures and the measurements tables appear
for the cases that have /probes/contact_pressure, /probes/history and
/measurements, and only then."""
import csv
import dataclasses
import re
from pathlib import Path

import numpy as np
import pytest

from . import figures
from . import gate
from . import report
from . import report_rows
from . import report_tables
from . import orders
from . import report_figures
from .conftest import (HERTZ_END_TIME, HERTZ_SUITE, ROUNDOFF_SUITE, SYNTHETIC_SUITE, hertz_cases, hertz_exact_pressure,
                      hertz_half_width, hertz_load, record_calls, roundoff_cases, synthetic_ring_cases,
                      write_suite_directory)
from .probes import PointHistory
from .results import read_suite

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
    least-squares order, one value per cell; levels.csv one row per level of each
    with its h, error and the pairwise order from the coarser level; the cpdi
    series (0.5 h^2) gives 2.000."""
    with open(synthetic_report[1]["orders"]) as stream:
        rows = list(csv.DictReader(stream))
    with open(synthetic_report[1]["levels"]) as stream:
        levels = list(csv.DictReader(stream))
    keys = {(r["study"], r["series"], r["norm"], r["time"]) for r in rows}
    assert len(keys) == len(rows) == 2 * 3                     # 2 series x 3 norms at the end time
    assert not any(";" in value for r in rows + levels for name, value in r.items() if name != "reason")
    cpdi = next(r for r in rows if r["series"] == "method=cpdi" and r["norm"] == "L1_theta0")
    assert abs(float(cpdi["ls_order"]) - 2.0) < 1e-12
    assert (cpdi["levels"], cpdi["left_out"], cpdi["classification"]) == ("3", "1", "asymptotic")

    def of(series):
        return [l for l in levels if l["series"] == series and l["norm"] == "L1_theta0"]
    cpdi_levels = of("method=cpdi")
    assert [(l["level"], l["used"]) for l in cpdi_levels] == [("32", "1"), ("64", "1"), ("128", "1"), ("256", "0")]
    assert cpdi_levels[0]["order_from_coarser"] == "nan"
    assert [abs(float(l["order_from_coarser"]) - 2.0) < 1e-12 for l in cpdi_levels[1:3]] == [True, True]
    assert [float(l["error"]) for l in cpdi_levels[:3]] == pytest.approx([0.5 * (3.0 / n) ** 2 for n in (32, 64, 128)])
    assert cpdi_levels[3]["reason"] == "pending" and cpdi_levels[3]["error"] == "nan"
    linear = of("method=linear")
    assert [l["level"] for l in linear if l["used"] == "1"] == ["32", "256"]
    assert any(l["level"] == "64" and l["reason"].startswith("no output at t = 1") for l in linear)


def test_report_survives_a_damaged_results_file_and_a_missing_suite_file(tmp_path):
    """Requirement: an unreadable results file and a directory without suite.toml
    still give a report; the damaged case is listed with why it has no results."""
    directory = write_suite_directory(tmp_path / "suite", SYNTHETIC_SUITE, synthetic_ring_cases())
    (directory / "cases" / "ring-method=cpdi-cells=64.h5").write_bytes(b"not an HDF5 file")
    (directory / "suite.toml").unlink()
    page = render(directory, tmp_path / "out")[0]["html"].read_text()
    assert "unreadable results file" in page


def test_report_survives_misshapen_errors_missing_probes_and_an_unwritable_place(tmp_path, capsys):
    """Requirement: a results file whose /errors column is 2-D is listed as
    unreadable with the shape; one whose probe line lost a dataset costs only
    the figures that read it, each named with the cause; a place the report
    cannot be written is one line and exit 2. No traceback."""
    import h5py
    directory = write_suite_directory(tmp_path / "suite", SYNTHETIC_SUITE, synthetic_ring_cases())
    with h5py.File(directory / "cases" / "ring-method=cpdi-cells=64.h5", "r+") as f:
        column = f["errors/L1_theta0"][:]
        del f["errors/L1_theta0"]
        f["errors/L1_theta0"] = np.stack([column, column])
    with h5py.File(directory / "cases" / "ring-method=cpdi-cells=128.h5", "r+") as f:
        del f["probes/theta0/exact_angular_displacement"]
    written, figure_count = render(directory, tmp_path / "out")
    page = written["html"].read_text()
    assert "unreadable results file (/errors/L1_theta0 has shape (2, 3)" in page
    assert "profile figure left out: a results file could not be read for it (KeyError" in page
    assert figure_count > 0
    blocker = tmp_path / "a-file"
    blocker.write_text("not a directory")
    assert report.main([str(directory), "-o", str(blocker / "report")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("mpmvv report: cannot write the report to") and err.count("\n") == 1


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
    # Its results files are not stored (*.h5 is not committed): no expectation
    # can hold, and the gate must say so.
    assert gate.main([str(GOLD)]) == 1


RING_FIGURES = ["gate-verdicts.png", "ring-L1-over-time.png", "ring-error-L1_theta0-end.png", "ring-error-particle_L2-end.png",
                "ring-history-point_R1.png", "ring-profile-theta0.png", "ring-spectrum.png", "ring-stability.png", "ring-work-precision.png"]


def test_suite_without_contact_history_or_measurements_renders_as_before(synthetic_report):
    """Requirement: a suite whose results files have no /probes/contact_pressure,
    /probes/history or /measurements gets exactly the figures and sections it got
    before they were added: no contact-pressure or load-approach figure, no
    measurements table."""
    output, written, figure_count = synthetic_report
    assert sorted(p.name for p in (output / "figures").glob("*.png")) == RING_FIGURES
    markdown = written["markdown"].read_text()
    assert re.findall(r"^## .*", markdown, re.M) == ["## Expectations", "## Cases", "## Observed orders",
                                                     "## Richardson extrapolation and grid convergence index",
                                                     "## Figures", "## Glossary"]
    # the definitions once, in the glossary, not above the orders' table
    orders_paragraph = markdown.split("## Observed orders", 1)[1].split("\n\n")[1]
    assert "glossary" in orders_paragraph and "Norms: L1_" not in orders_paragraph
    assert "Norms: L1_<line> is eq. 3.1" in markdown.split("## Glossary", 1)[1]
    assert "Measurements" not in written["html"].read_text()


@pytest.fixture
def drawn(monkeypatch):
    """The panels handed to figures.pressure_profiles and figures.histories, by figure title."""
    calls = {}
    for name in ("pressure_profiles", "histories"):
        original = getattr(figures, name)

        def record(panels, title, *args, _original=original, **kwargs):
            calls[title] = panels
            return _original(panels, title, *args, **kwargs)
        monkeypatch.setattr(figures, name, record)
    return calls


def test_contact_pressure_figure_of_each_level_against_hertz(tmp_path, drawn):
    """Requirement: for cases with /probes/contact_pressure the report draws, per
    study, the simulated pressure at each case's last output (markers, one series
    per refinement level labelled by the refine key) against the exact curve of
    the finest case (a line), x in mm and pressure in MPa, x up to twice the
    largest x with nonzero exact pressure; the caption names the time."""
    directory = write_suite_directory(tmp_path / "suite", HERTZ_SUITE, hertz_cases())
    written, figure_count = render(directory, tmp_path / "out")
    assert (tmp_path / "out" / "figures" / "mesh-contact-pressure.png").is_file()
    (panel,) = drawn[f"mesh: contact pressure at t = {HERTZ_END_TIME:g} s"]
    assert [c.label for c in panel.curves] == ["cells=25", "cells=50", "cells=100"]     # 200 is pending
    cells, a, p0 = 100, *hertz_half_width(hertz_load(100))
    h = 0.2 / cells
    x = (np.arange(cells // 2 + 2) + 0.5) * h
    extent = x[hertz_exact_pressure(x, p0, a) > 0].max()
    finest = panel.curves[-1]
    assert np.allclose(finest.x, 1e3 * x[x <= 2 * extent])
    assert np.allclose(finest.y, 1e-6 * hertz_exact_pressure(x[x <= 2 * extent], p0, a) * (1 + 2 * h / a))
    assert max(max(c.x) for c in panel.curves) <= 2e3 * extent * (1 + 1e-9)
    assert np.allclose(panel.exact.y, 1e-6 * hertz_exact_pressure(1e-3 * panel.exact.x, p0, a), atol=1e-9)
    assert max(panel.exact.y) == pytest.approx(p0 / 1e6) and max(panel.exact.x) == pytest.approx(2e3 * extent)
    assert f"p0 = {p0 / 1e6:.4g} MPa, a = {a * 1e3:.4g} mm" in panel.title
    page = written["html"].read_text()
    assert page.count("src='data:image/png;base64,") == figure_count
    assert re.search(r"<figcaption>mesh: contact pressure [^<]*at t = 0\.002 s", page)


def test_contact_pressure_figure_draws_hertz_from_the_file_or_the_stored_values(tmp_path, drawn):
    """Requirement: the exact curve is Hertz's ellipse with the p0 and a the results
    file holds for that time (read, not fitted: a p0 1 % off the stored profile is
    the one drawn); a file without them (written before they were) gets the stored
    exact values at the cell midpoints, and no p0 or a in the title."""
    cases = hertz_cases(history=False)
    a, p0 = hertz_half_width(hertz_load(100))
    cases[2]["contact_pressure"]["exact_peak_pressure"] = [1.01 * p0]
    directory = write_suite_directory(tmp_path / "suite", HERTZ_SUITE, cases)
    render(directory, tmp_path / "out")
    (panel,) = drawn[f"mesh: contact pressure at t = {HERTZ_END_TIME:g} s"]
    assert max(panel.exact.y) == pytest.approx(1.01 * p0 / 1e6)
    assert f"p0 = {1.01 * p0 / 1e6:.4g} MPa" in panel.title
    for case in cases:
        if "contact_pressure" in case:
            del case["contact_pressure"]["exact_peak_pressure"], case["contact_pressure"]["exact_half_width"]
    drawn.clear()
    directory = write_suite_directory(tmp_path / "old", HERTZ_SUITE, cases)
    render(directory, tmp_path / "out-old")
    (panel,) = drawn[f"mesh: contact pressure at t = {HERTZ_END_TIME:g} s"]
    h = 0.2 / 100
    x = (np.arange(100 // 2 + 2) + 0.5) * h
    extent = x[hertz_exact_pressure(x, p0, a) > 0].max()
    assert np.allclose(panel.exact.x, 1e3 * x[x <= 2 * extent])
    assert np.allclose(panel.exact.y, 1e-6 * hertz_exact_pressure(x[x <= 2 * extent], p0, a))
    assert "p0 =" not in panel.title


def test_load_approach_figure_one_line_per_case(tmp_path, drawn):
    """Requirement: for cases whose /probes/history has `approach` and `load` the
    report draws load [MN/m] against approach [um], one line per case of the study."""
    directory = write_suite_directory(tmp_path / "suite", HERTZ_SUITE, hertz_cases(contact_pressure=False))
    written = render(directory, tmp_path / "out")[0]
    assert sorted(p.name for p in (tmp_path / "out" / "figures").glob("*load*")) == ["mesh-load-approach.png"]
    assert not list((tmp_path / "out" / "figures").glob("*contact-pressure*"))
    (panel,) = drawn["mesh: load against approach"]
    assert [c.label for c in panel.curves] == ["cells=25", "cells=50", "cells=100"]
    for curve, cells in zip(panel.curves, (25, 50, 100)):
        assert max(curve.x) == pytest.approx(200.0) and max(curve.y) == pytest.approx(hertz_load(cells) / 1e6)
    assert "mesh: load per unit length [MN/m] against approach" in written["html"].read_text()


def test_history_without_approach_and_load_draws_nothing(tmp_path):
    """Requirement: a /probes/history without both `approach` and `load` is skipped."""
    cases = hertz_cases(contact_pressure=False, measurements=False)
    for case in cases:
        if "history" in case:
            case["history"] = {"time": case["history"]["time"], "energy": case["history"]["load"]}
    directory = write_suite_directory(tmp_path / "suite", HERTZ_SUITE, cases)
    render(directory, tmp_path / "out")
    names = [p.name for p in (tmp_path / "out" / "figures").glob("*.png")]
    assert names and not [n for n in names if "load" in n or "contact" in n]


def test_measurements_table_lists_every_attribute_per_case(tmp_path):
    """Requirement: when some case of a study has /measurements, report.md and
    report.html have a "Measurements" table for the study: one row per case, one
    column per attribute present, numbers to 4 significant digits, - where a case
    has none."""
    directory = write_suite_directory(tmp_path / "suite", HERTZ_SUITE, hertz_cases())
    written = render(directory, tmp_path / "out")[0]
    markdown = written["markdown"].read_text()
    assert "## Measurements: mesh" in markdown
    assert "| case | approach | half_width_exact | load | peak_pressure_exact |" in markdown    # as HDF5 lists them
    a, p0 = hertz_half_width(hertz_load(50))
    assert f"| mesh-cells=50 | 0.0002 | {a:.4g} | {hertz_load(50):.4g} | {p0:.4g} |" in markdown
    assert "| mesh-cells=25 | - | - | - | - |" in markdown and "| mesh-cells=200 | - | - | - | - |" in markdown
    page = written["html"].read_text()
    assert "<h2>Measurements: mesh</h2>" in page and f"<td>{hertz_load(100):.4g}</td>" in page
    assert report_tables.measurement_text(0.015854621348) == "0.01585" and report_tables.measurement_text(2.2454e7) == "2.245e+07"


REFERENCE_TABLES = """
[[reference]]
source = "another code, table 9"
study = "ring"
quantity = "time_reached"
columns = ["cells", "amplitude"]
rows = [[32, 0.5, 0.47], [64, 0.5, 0.34], [256, 0.5, 1.0]]

[[reference]]
source = "another code, its figure 4"
study = "ring"
quantity = "error"
norm = "L1_theta0"
columns = ["cells", "amplitude"]
rows = [[64, 0.5, 0.002]]

[[reference]]
source = "another code, figure 9"
study = ["ring"]
quantity = "order"
norm = "L1_theta0"
time = 1.0
columns = ["amplitude"]
rows = [[0.5, 1.25]]
"""


def test_published_results_stand_beside_the_suites_own(tmp_path):
    """Requirement: a [[reference]] time_reached table puts, for each published row,
    the time each matching case reached (and why it stopped) beside the published
    time, one column per method; an error table puts each matching case's error in
    the same norm (or why it has none) beside the published one; an order table puts
    every matching series' observed order beside the published one; the gate ignores
    them all."""
    directory = write_suite_directory(tmp_path / "suite", SYNTHETIC_SUITE + REFERENCE_TABLES, synthetic_ring_cases())
    written = render(directory, tmp_path / "out")[0]
    markdown = written["markdown"].read_text()
    assert "## Against published results: time reached" in markdown and "another code, table 9" in markdown
    assert "| cells | amplitude | reference [s] | ring method=linear | ring method=cpdi |" in markdown
    assert "| 32 | 0.5 | 0.47 | 1 | 1 |" in markdown
    assert "| 64 | 0.5 | 0.34 | 0.3 non-positive J | 1 |" in markdown
    assert "| 256 | 0.5 | 1 | 1 | pending |" in markdown
    assert "## Against published results: L1_theta0" in markdown and "another code, its figure 4" in markdown
    assert "| cells | amplitude | reference [rad] | ring method=linear | ring method=cpdi |" in markdown
    error_row = next(line for line in markdown.splitlines() if line.startswith("| 64 | 0.5 | 0.002 |"))
    assert "| no output at t = 1 (reached 0.3) |" in error_row       # the linear case stopped at 0.3 s
    assert "## Against published results: observed order of L1_theta0" in markdown
    rows = [line for line in markdown.splitlines() if line.startswith("| 0.5 | 1.25 | ring: ")]
    assert len(rows) == 2
    cpdi = next(line for line in rows if "method=cpdi" in line)
    assert "| 32, 64, 128 |" in cpdi and "2.000" in cpdi and "asymptotic" in cpdi
    linear = next(line for line in rows if "method=linear" in line)
    assert "| 32, 256 |" in linear and "1.000" in linear
    assert gate.main([str(directory)]) == 0


def test_a_reference_the_report_cannot_read_is_said_not_fatal(tmp_path):
    """Requirement: a hand-made suite.toml whose [[reference]] is malformed still gives a
    report, which says why the comparison is not shown."""
    bad = SYNTHETIC_SUITE + '\n[[reference]]\nsource = "x"\nstudy = "ring"\nquantity = "speed"\nrows = [[1.0]]\n'
    directory = write_suite_directory(tmp_path / "suite", bad, synthetic_ring_cases())
    page = render(directory, tmp_path / "out")[0]["html"].read_text()
    assert "Not shown: [[reference]] 1: needs &#x27;study&#x27; and &#x27;quantity&#x27;" in page


def test_report_gives_no_order_for_errors_at_round_off(tmp_path, monkeypatch):
    """Requirement: a series with a level at round-off (conftest.roundoff_cases)
    gets the class "round-off" and no order anywhere the report shows orders: "-"
    in the table with the levels, their error over the exact signal and the floor;
    an empty pairwise_orders and NaN least-squares order in orders.csv, with each
    level's relative error and floor; no fitted line and "no order" in the figure
    legend. The same h^2 law on a small body moved little is no round-off: order 2."""
    drawn = record_calls(monkeypatch, figures, "error_against_h")
    directory = write_suite_directory(tmp_path / "suite", ROUNDOFF_SUITE, roundoff_cases())
    written = render(directory, tmp_path / "out")[0]
    with open(written["orders"]) as stream:
        rows = {(r["study"], r["norm"]): r for r in csv.DictReader(stream)}
    with open(written["levels"]) as stream:
        levels = list(csv.DictReader(stream))

    def levels_of(key):
        return [l for l in levels if (l["study"], l["norm"]) == key and l["used"] == "1"]
    for key in (("roundoff", "L1_theta0"), ("roundoff", "particle_L2")):
        assert rows[key]["classification"] == "round-off"
        assert rows[key]["ls_order"] == "nan"
        assert all(l["order_from_coarser"] == "nan" for l in levels_of(key))
    line = levels_of(("roundoff", "L1_theta0"))
    relative = [float(l["relative_error"]) for l in line]
    floor = [float(l["roundoff_floor"]) for l in line]
    assert relative == pytest.approx([4e-13 / 0.573977410425004, 1e-13 / 0.573977410425004,
                                      2.5e-14 / 0.573977410425004], rel=1e-9)
    assert floor == pytest.approx([356 * 2.220446049250313e-16 * np.pi / 0.573977410425004] * 3, rel=1e-9)
    for key in (("small", "particle_L2"), ("small", "error_axial_stress")):
        assert rows[key]["classification"] == "asymptotic" and float(rows[key]["ls_order"]) == pytest.approx(2.0)
    markdown = written["markdown"].read_text()
    assert ("| roundoff | method=cpdi | L1_theta0 [rad] | 1 | 32, 64, 128 | 2.5e-14 | - | - | round-off at "
            "cells=64,128 (up to 1.7e-13 of the exact signal; round-off floor 4.3e-13) |") in markdown
    [roundoff_curve] = drawn["roundoff: L1_theta0 at t = 1 s"]
    assert roundoff_curve.label == "method=cpdi: round-off, no order" and roundoff_curve.fit is None
    [small_curve] = drawn["small: particle_L2 at t = 1 s"]
    assert small_curve.label == "method=cpdi" and small_curve.fit.order == pytest.approx(2.0)
    assert "No order, errors at round-off at cells=64,128 (up to 1.7e-13" in markdown


def test_grid_convergence_of_changes_at_round_off_has_no_order(tmp_path):
    """Requirement: Roache's study of a point value whose changes between levels are
    within the round-off floor ((256 + steps) ulps of the point's |X|) is classed
    "round-off" and has no order; changes above it are studied as before."""
    directory = write_suite_directory(tmp_path / "suite", ROUNDOFF_SUITE, roundoff_cases())
    cases = read_suite(directory).cases_of("roundoff")         # 100 steps each
    point = PointHistory("p", "displacement_x", np.array([0.6, 0.8]), np.zeros(1), np.zeros(1), np.zeros(1))
    floor = 356 * 2.220446049250313e-16 * 1.0
    assert report_rows.point_changes_at_roundoff(cases, point, (1e-6, 1e-6 + 0.5 * floor, 1e-6 + 0.75 * floor))
    assert not report_rows.point_changes_at_roundoff(cases, point, (1e-6, 1e-6 + 4 * floor, 1e-6 + 6 * floor))



def test_report_tells_its_progress_by_study_unless_quiet(tmp_path, capsys):
    """Requirement: mpmvv report says on stderr how far it is, a line before
    each study's figures (study k of n, the figures written so far, the time)
    and one at the end; --quiet says nothing there."""
    directory = write_suite_directory(tmp_path / "suite", SYNTHETIC_SUITE, synthetic_ring_cases())
    assert report.main([str(directory), "-o", str(tmp_path / "out")]) == 0
    lines = capsys.readouterr().err.splitlines()
    studies = len(report.read_suite(directory).study_names())
    assert lines[0].startswith(f"mpmvv report: study 1 of {studies}: ") and "(0 figures, " in lines[0]
    assert re.match(rf"mpmvv report: {studies} of {studies} studies \(([1-9][0-9]*) figures, [0-9]+ s\)$", lines[-1])
    assert len(lines) == studies + 1
    assert report.main([str(directory), "-o", str(tmp_path / "out"), "--quiet"]) == 0
    assert capsys.readouterr().err == ""


def test_the_report_opens_with_the_gates_verdict(synthetic_report, tmp_path):
    """Requirement: the first thing the report says, under its title, is the
    gate's verdict (PASS, FAIL, or that the suite gates nothing), and for a FAIL
    each series that fell short with its observed and expected order and why;
    the expectations' table is the first section."""
    output, written, _ = synthetic_report
    markdown = written["markdown"].read_text().splitlines()
    assert markdown[2] == "**Verdict: PASS. All 1 expectations hold (1 series checked).**"
    assert "<div class='verdict pass'><p><strong>Verdict: PASS." in written["html"].read_text()
    unreachable = SYNTHETIC_SUITE.replace("order = 2.0", "order = 3.0")
    directory = write_suite_directory(tmp_path / "short", unreachable, synthetic_ring_cases())
    written, _ = render(directory, tmp_path / "short-report")
    markdown = written["markdown"].read_text().splitlines()
    assert markdown[2] == "**Verdict: FAIL. 1 of 1 expectations fell short (1 of 1 series):**"
    assert markdown[4].startswith("- expectation 1 (ring, method=cpdi, L1_theta0 at t = ")
    assert "observed 2.000" in markdown[4] and "expected [2.9, 3.1]" in markdown[4]
    assert "<div class='verdict fail'>" in written["html"].read_text()
    # under the verdict, the figure of every checked series against its band, before any section
    page = written["html"].read_text()
    assert page.index("alt='gate-verdicts.png'") < page.index("<h2>Expectations</h2>")
    assert (tmp_path / "short-report" / "figures" / "gate-verdicts.png").is_file()
    ungated = SYNTHETIC_SUITE[:SYNTHETIC_SUITE.index("[[expect]]")]
    directory = write_suite_directory(tmp_path / "ungated", ungated, synthetic_ring_cases())
    written, _ = render(directory, tmp_path / "ungated-report")
    assert written["markdown"].read_text().splitlines()[2].startswith("**Verdict: none. This suite has no [[expect]]")
    assert not (tmp_path / "ungated-report" / "figures" / "gate-verdicts.png").exists()


def test_the_order_legend_claims_only_what_its_labels_show():
    """Requirement: the error figure's legend title promises a 95 % interval only
    when some series has one (three levels or more), an order only when one was
    fitted."""
    two = orders.least_squares_order([0.1, 0.05], [1e-2, 2.5e-3])
    three = orders.least_squares_order([0.1, 0.05, 0.025], [1e-2, 2.6e-3, 6e-4])

    def title(fit):
        levels = fit.levels if fit else 2
        curve = figures.Curve("s", [0.1, 0.05, 0.025][:levels], [1e-2, 2.6e-3, 6e-4][:levels], fit=fit)
        return figures.error_against_h([curve], "t", "E").axes[0].get_legend().get_title().get_text()

    assert title(two) == "series: least-squares order p"
    assert title(three) == "series: least-squares order p [95% CI]"
    assert title(None) == "series"


def test_a_stability_study_where_every_case_completed_is_a_sentence(tmp_path):
    """Requirement: a stability map of one colour (every case reached its end
    with its solution kept) is replaced by a sentence saying so."""
    directory = write_suite_directory(tmp_path / "suite", SYNTHETIC_SUITE, synthetic_ring_cases())
    every = report_figures.study_series(report.read_suite(directory), "ring")
    assert report_figures.stability_figure("ring", every, tmp_path).path is not None   # a case failed
    done = [dataclasses.replace(s, cases=tuple(c for c in s.cases if c.completed)) for s in every]
    entry = report_figures.stability_figure("ring", done, tmp_path)
    assert entry.path is None and "every one of its" in entry.caption and "reached the end time" in entry.caption


def test_spectra_are_markers_over_the_round_off_floor():
    """Requirement: the error spectrum draws each mode as a marker (no line joins
    discrete modes) and starts its axis a decade under the smallest mode above
    the round-off floor, the floor dotted when within the axis and named when
    below it."""
    near = figures.Curve("near", [0, 1, 2, 3], [1e-3, 1e-12, 1e-16, 1e-5])
    far = figures.Curve("far", [0, 1, 2], [1e-3, 1e-4, 1e-17])
    figure = figures.error_spectra([("near", [near]), ("far", [far])], "t", "A", {"near": 1e-13, "far": 1e-13})
    near_axes, far_axes = figure.axes[:2]
    assert all(line.get_linestyle() == "None" for line in near_axes.get_lines() if line.get_label() == "near")
    assert near_axes.get_ylim()[0] == pytest.approx(1e-13 / 3.0)          # 1e-12 / 10 is under floor / 3
    assert any(line.get_label() == "round-off floor" for line in near_axes.get_lines())
    assert far_axes.get_ylim()[0] == pytest.approx(1e-5)                  # a decade under 1e-4
    assert any("below the axis" in text.get_text() for text in far_axes.texts)
