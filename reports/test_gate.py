"""Requirements of the gate (reports/gate.py) and of refinement series
(reports/series.py) on synthetic suite directories written with the layout of
suites/README.md: every expectation is checked per series, a series holds only
when its fitted order is in band, its error constant is under the limit and
(must_complete) every case completed; exit 0 when all hold, 1 when one falls
short, 2 with one line for a directory that cannot be read. Orders that are
hard to read (intervals, trivial signals, round-off, settling) are
test_gate_floors.py's."""
import json
from dataclasses import replace

import h5py
import pytest

from . import gate
from . import report_tables
from .conftest import SYNTHETIC_SUITE, synthetic_ring_cases, write_suite_directory
from .results import read_suite
from .series import refinement_series, series_levels


def run_gate(directory, capsys):
    status = gate.main([str(directory)])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def rows_of(output):
    return [line for line in output.splitlines() if "PASS" in line or "FAIL" in line]


def test_series_are_split_by_every_key_but_the_refine_key(synthetic_suite):
    """Requirement: cases that agree on every key except `cells` form one series."""
    series = refinement_series(read_suite(synthetic_suite).cases_of("ring"))
    assert [s.label for s in series] == ["method=linear", "method=cpdi"]
    assert [[c.keys["cells"] for c in s.cases] for s in series] == [[32, 64, 128, 256]] * 2


def test_a_key_that_follows_the_refine_key_does_not_split_a_series(synthetic_suite):
    """Requirement: a key set per level (an override cfl = 0.25 at 256 cells) or
    written 1 vs 1.0 stays inside the series."""
    cases = read_suite(synthetic_suite).cases_of("ring")
    changed = [replace(c, keys={**c.keys, "cfl": 0.25 if c.keys["cells"] == 256 else 0.3,
                                "end_time": 1 if c.keys["method"] == "cpdi" else 1.0}) for c in cases]
    assert [s.label for s in refinement_series(changed)] == ["method=linear", "method=cpdi"]


def test_zipped_keys_are_named_by_the_first_the_study_lists(synthetic_suite):
    """Requirement: keys zipped together between series (an amplitude with the end
    time it needs) still split the series, and the label names them by the key the
    study sweeps or zips first; without that order, by the first in the case keys."""
    cases = read_suite(synthetic_suite).cases_of("ring")
    zipped = [replace(c, keys={**c.keys, "end_time": 1.0 if c.keys["method"] == "cpdi" else 2.0,
                               "amplitude": 0.5 if c.keys["method"] == "cpdi" else 1.0}) for c in cases]
    series = refinement_series(zipped, "cells", ["method", "cells", "amplitude", "end_time"])
    assert [s.label for s in series] == ["method=linear", "method=cpdi"]
    series = refinement_series(zipped, "cells", ["amplitude", "end_time"])
    assert [s.label for s in series] == ["amplitude=1.0", "amplitude=0.5"]
    assert [s.label for s in refinement_series(zipped, "cells", ["end_time"])] == ["end_time=2.0", "end_time=1.0"]
    assert len(refinement_series(zipped)) == 2


def test_series_levels_are_sorted_coarse_first_even_without_results(synthetic_suite):
    """Requirement: a case without results (pending) takes its place by its refine value."""
    cpdi = refinement_series(read_suite(synthetic_suite).cases_of("ring"))[1]
    assert [c.keys["cells"] for c in cpdi.cases] == [32, 64, 128, 256]
    assert cpdi.cases[-1].status == "pending"


def test_gate_passes_on_an_exact_second_order_series(synthetic_suite, capsys):
    """Requirement: E = 0.5 h^2 on 32, 64, 128 cells holds order 2 +- 0.1 and
    E/h^2 <= 0.6; exit 0 and 'all N expectations hold'."""
    status, out, _ = run_gate(synthetic_suite, capsys)
    assert status == 0
    [row] = rows_of(out)
    assert "PASS" in row and "2.000 [2.00, 2.00]" in row and "[1.9, 2.1]" in row and "0.5 <= 0.6" in row
    assert "all 1 expectations hold" in out


MORE_EXPECTATIONS = """
[[expect]]
study = "ring"
where = { method = "linear" }
norm = "particle_L2"
time = 0.25
order = 1.0
tolerance = 0.2

[[expect]]
study = "ring"
norm = "L1_theta0"
levels = [32, 64, 128]
order = 2.0
tolerance = 0.5
must_complete = false

[[expect]]
study = "ring"
where = { method = "cpdi" }
norm = "L1_theta0"
levels = [32, 64]
order = 2.0
tolerance = 0.5
max_error_constant = 0.1
"""


def test_gate_fails_on_an_incomplete_series_and_out_of_band_orders(tmp_path, capsys):
    """Requirement: a failed case fails a must_complete expectation with exit 1;
    an order outside its band fails; an error constant above the limit fails;
    a series with fewer than two usable levels fails with that reason; the
    table shows observed against expected with the band."""
    directory = write_suite_directory(tmp_path / "suite", SYNTHETIC_SUITE + MORE_EXPECTATIONS, synthetic_ring_cases())
    status, out, _ = run_gate(directory, capsys)
    assert status == 1
    rows = rows_of(out)
    assert len(rows) == 1 + 1 + 2 + 1
    expect_2 = next(r for r in rows if r.startswith("2 "))
    assert "FAIL" in expect_2 and "not completed" in expect_2
    assert "cells=64 failed at t = 0.3 (non-positive J)" in expect_2
    assert "cells=128 crashed" in expect_2
    assert "1.000" in expect_2 and "[0.8, 1.2]" in expect_2      # fitted on 32, 64, 256: each wrote t = 0.25
    linear_3, cpdi_3 = [r for r in rows if r.startswith("3 ")]
    assert "FAIL" in linear_3 and "1 usable level(s), need 2" in linear_3 and "outside" not in linear_3
    assert "PASS" in cpdi_3
    expect_4 = next(r for r in rows if r.startswith("4 "))
    assert "FAIL" in expect_4 and "E/h^2 = 0.5 > 0.1" in expect_4
    assert "3 of 4 expectations fell short (3 of 5 series)" in out


def test_gate_fails_on_an_order_outside_the_band(tmp_path, capsys):
    """Requirement: E = 0.2 h (order 1) against an expected order 2 +- 0.3 fails."""
    suite = SYNTHETIC_SUITE.replace('where = { method = "cpdi" }', 'where = { method = "linear" }')
    suite = suite.replace("levels = [32, 64, 128]", "levels = [32, 256]")
    directory = write_suite_directory(tmp_path / "suite", suite, synthetic_ring_cases())
    status, out, _ = run_gate(directory, capsys)
    [row] = rows_of(out)
    assert status == 1 and "FAIL" in row and "order 1.000 outside [1.9, 2.1]" in row


def test_gate_exit_2_with_one_line_for_a_bad_directory(tmp_path, capsys):
    """Requirement: a missing directory, a missing or broken manifest, a missing
    suite.toml and a manifest that records no expectations (written before it
    did) give exit 2 and one line naming it. A malformed [[expect]] never gets
    here: mpmvv suite refuses the suite file (tests/suite_tests.cpp)."""
    status, out, err = run_gate(tmp_path / "nowhere", capsys)
    assert status == 2 and err.count("\n") == 1 and "no such directory" in err
    directory = write_suite_directory(tmp_path / "suite", SYNTHETIC_SUITE, synthetic_ring_cases())
    (directory / "manifest.json").write_text("{not json")
    status, out, err = run_gate(directory, capsys)
    assert status == 2 and err.count("\n") == 1 and "manifest.json: not valid JSON" in err
    directory = write_suite_directory(tmp_path / "suite2", SYNTHETIC_SUITE, synthetic_ring_cases())
    (directory / "suite.toml").unlink()
    status, out, err = run_gate(directory, capsys)
    assert status == 2 and "suite.toml: missing" in err
    directory = write_suite_directory(tmp_path / "suite3", SYNTHETIC_SUITE, synthetic_ring_cases())
    manifest = json.loads((directory / "manifest.json").read_text())
    del manifest["expectations"]
    (directory / "manifest.json").write_text(json.dumps(manifest))
    status, out, err = run_gate(directory, capsys)
    assert status == 2 and err.count("\n") == 1 and "records no expectations" in err and "run the suite again" in err


def test_gate_reports_an_expectation_that_matches_no_case(tmp_path, capsys):
    """Requirement: an expectation whose `where` selects nothing fails instead of passing vacuously."""
    suite = SYNTHETIC_SUITE.replace('where = { method = "cpdi" }', 'where = { method = "gimp" }')
    directory = write_suite_directory(tmp_path / "suite", suite, synthetic_ring_cases())
    status, out, _ = run_gate(directory, capsys)
    assert status == 1 and "no case of study 'ring' matches" in out


def test_manifest_status_is_kept_for_cases_without_results(synthetic_suite):
    """Requirement: pending and crashed cases are read without results and with their status."""
    cases = {c.id: c for c in read_suite(synthetic_suite).cases}
    assert cases["ring-method=cpdi-cells=256"].status == "pending"
    assert cases["ring-method=cpdi-cells=256"].results is None
    crashed = cases["ring-method=linear-cells=128"]
    assert crashed.status == "crashed" and crashed.failure_reason == "signal 11 (SIGSEGV)"
    manifest = json.loads((synthetic_suite / "manifest.json").read_text())
    assert len(manifest["cases"]) == len(cases)


MAX_ERROR_SUITE = """description = "synthetic ring suite: a bound on the error itself"

[[study]]
name = "ring"
scene = "scenes/ring.toml"
sweep = { method = ["linear", "cpdi"], cells = [32, 64, 128, 256] }

[[expect]]
study = "ring"
where = { method = "cpdi" }
norm = "L1_theta0"
levels = [32, 64, 128]
max_error = 0.005

[[expect]]
study = "ring"
where = { method = "cpdi" }
norm = "L1_theta0"
levels = [64, 128]
max_error = 0.001
"""


def test_gate_checks_a_bound_on_the_error_itself(tmp_path, capsys):
    """Requirement: `max_error` alone (no order) holds when every usable level's
    error is at most the bound and fails naming the levels above it. The cpdi
    errors are 0.5 h^2 at t = 1: 4.39e-3, 1.10e-3, 2.75e-4 on 32, 64, 128 cells."""
    directory = write_suite_directory(tmp_path / "suite", MAX_ERROR_SUITE, synthetic_ring_cases())
    status, out, _ = run_gate(directory, capsys)
    assert status == 1
    first, second = rows_of(out)
    assert "PASS" in first and "E = 0.00439 <= 0.005" in first
    assert "FAIL" in second and "error above 0.001: cells=64: 0.0011" in second
    assert "1 of 2 expectations fell short" in out
    # Such an expectation claims no order, and none is shown (the observed-order column is "-").
    assert "2.000" not in first and first.split()[first.split().index("32,64,128") + 1] == "-"
    assert "2.000" not in second


def test_a_lost_case_is_not_completed_anywhere(tmp_path, capsys):
    """Requirement: a case whose results file says its solution was lost (status
    "lost", with the health verdict's reason and time) counts as not completed
    even where the manifest says "completed": the gate fails a must_complete
    expectation naming the rule and the time, no order is fitted through it,
    and the report's case table shows the status and the reason."""
    directory = write_suite_directory(tmp_path / "suite", SYNTHETIC_SUITE, synthetic_ring_cases())
    with h5py.File(directory / "cases" / "ring-method=cpdi-cells=64.h5", "r+") as f:
        f.attrs.update({"status": "lost", "failure_reason": "solution lost", "health": "solution lost",
                        "health_time": 0.5, "health_reason": "J / J_exact ranged over [0.0064, 25.6], outside "
                                                            "[1/20, 20] (health_J_factor)"})
    suite = read_suite(directory)
    lost = next(c for c in suite.cases if c.id == "ring-method=cpdi-cells=64")
    assert lost.status == "lost" and not lost.completed
    assert lost.failure_reason.startswith("solution lost at t = 0.5 s: J / J_exact ranged over [0.0064, 25.6]")
    status, out, _ = run_gate(directory, capsys)
    assert status == 1
    row = next(r for r in rows_of(out) if r.startswith("1 "))
    assert "FAIL" in row and "cells=64 lost (solution lost at t = 0.5 s: J / J_exact" in row
    # Its errors from t = 0.5 s on are refused; before, they are usable, as a failed run's are.
    cpdi = refinement_series(suite.cases_of("ring"))[1]
    at_end = {l.value: l for l in series_levels(cpdi, "L1_theta0", 1.0)}
    assert at_end[64].reason.startswith("solution lost at t = 0.5 s (J / J_exact")
    assert at_end[32].reason == "" and at_end[128].reason == ""
    early = {l.value: l for l in series_levels(cpdi, "L1_theta0", 0.25)}
    assert early[64].reason == "" and early[64].error == pytest.approx(0.5 * (3.0 / 64) ** 2 * 0.25, rel=1e-12)
    table = report_tables.case_table(suite)
    cells = next(r for r in table.rows if r[0] == "ring-method=cpdi-cells=64")
    assert cells[1] == "lost" and "health_J_factor" in cells[3]


def test_ci_tier_is_named_and_its_table_sets_the_varied_keys(tmp_path, capsys):
    """Requirement: a manifest of the ci tier is read as such: the gate names the
    tier, the study's `ci` table decides which keys vary (a key the ci tier sets is
    not varied there; one it sweeps is), references are the full tier's, and a
    tier that is neither is refused with one line."""
    suite_toml = SYNTHETIC_SUITE.replace(
        'sweep = { method = ["linear", "cpdi"], cells = [32, 64, 128, 256] }',
        'sweep = { method = ["linear", "cpdi"], cells = [32, 64, 128, 256] }\n'
        'ci = { set = { method = "cpdi" }, sweep = { cells = [32, 64, 128], particles_per_direction = [2] } }')
    # (an expectation without `tier` is the full study's alone: mpmvv suite records it in no ci manifest)
    suite_toml = suite_toml.replace('norm = "L1_theta0"\n', 'norm = "L1_theta0"\ntier = ["full", "ci"]\n', 1)
    suite_toml += '\n[[reference]]\nsource = "x"\nstudy = "ring"\nquantity = "time_reached"\n' \
                  'columns = ["cells"]\nrows = [[32, 1.0]]\n'
    cases = [c for c in synthetic_ring_cases(linear_fails_at_64=False)
             if c["keys"]["method"] == "cpdi" and c["keys"]["cells"] <= 128]
    directory = write_suite_directory(tmp_path / "ci", suite_toml, cases)
    manifest = json.loads((directory / "manifest.json").read_text())
    manifest["tier"] = "ci"
    (directory / "manifest.json").write_text(json.dumps(manifest))
    suite = read_suite(directory)
    assert suite.tier == "ci" and suite.references == []
    assert suite.varied_keys("ring") == ["cells", "particles_per_direction"]
    status, out, _ = run_gate(directory, capsys)
    assert status == 0 and out.startswith("synthetic (ci tier): 1 expectations")
    manifest["tier"] = "quick"
    (directory / "manifest.json").write_text(json.dumps(manifest))
    status, _, err = run_gate(directory, capsys)
    assert status == 2 and "'tier' is 'quick'" in err and err.count("\n") == 1
    del manifest["tier"]
    (directory / "manifest.json").write_text(json.dumps(manifest))
    suite = read_suite(directory)
    assert suite.tier == "full" and suite.varied_keys("ring") == ["method", "cells"] and len(suite.references) == 1


def test_a_ci_manifest_of_a_suite_without_a_ci_tier_fails(tmp_path, capsys):
    """Requirement: "tier": "ci" in the manifest of a suite whose studies have no
    `ci` table (or whose [ci] says skip) is not a run mpmvv suite made: FAIL,
    naming the study; the same suite read as the full tier passes."""
    suite_toml = SYNTHETIC_SUITE.split("[[expect]]")[0]
    directory = write_suite_directory(tmp_path / "suite", suite_toml, synthetic_ring_cases())
    manifest = json.loads((directory / "manifest.json").read_text())
    manifest["tier"] = "ci"
    (directory / "manifest.json").write_text(json.dumps(manifest))
    status, out, err = run_gate(directory, capsys)
    assert status == 1 and "study 'ring' of suite.toml has no `ci` table" in err
    (directory / "suite.toml").write_text(suite_toml + '[ci]\nskip = "too slow"\n')
    status, out, err = run_gate(directory, capsys)
    assert status == 1 and "suite.toml has no ci tier ([ci] skip = 'too slow')" in err
