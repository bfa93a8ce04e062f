"""Requirements of the gate (reports/gate.py) and of refinement series
(reports/series.py) on synthetic suite directories written with the layout of
suites/README.md: every expectation is checked per series, a series holds only
when its fitted order is in band, its error constant is under the limit and
(must_complete) every case completed; exit 0 when all hold, 1 when one falls
short, 2 with one line for a directory that cannot be read."""
import json
import math
from dataclasses import replace

import h5py
import numpy as np
import pytest

from . import gate
from . import report_rows
from . import report_tables
from .conftest import (RING_TIMES, ROUNDOFF_SUITE, SYNTHETIC_SUITE, roundoff_cases, synthetic_ring_cases,
                      write_suite_directory)
from .results import read_suite
from .scales import error_scale, settling_scale
from .series import Level, RoundOff, error_floor_kind, refinement_series, series_levels


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


NOISY_SUITE = """description = "synthetic: cpdi errors 0.5 h^2 times 1, 1.3, 0.8, 1.2 on 32-256 cells"

[[study]]
name = "ring"
scene = "scenes/ring.toml"
sweep = { method = ["cpdi"], cells = [32, 64, 128, 256] }

[[expect]]
study = "ring"
norm = "L1_theta0"
order = 2.0
tolerance = 0.5

[[expect]]
study = "ring"
norm = "L1_theta0"
order = 2.0
tolerance = 0.5
interval_within_band = true

[[expect]]
study = "ring"
norm = "L1_theta0"
order = 2.0
tolerance = 0.8
interval_within_band = true

[[expect]]
study = "ring"
norm = "L1_theta0"
levels = [32, 64]
order = 2.0
tolerance = 0.8
interval_within_band = true
"""


def test_an_interval_outside_the_band_is_noted_or_fails_when_asked(tmp_path, capsys):
    """Requirement: errors 0.5 h^2 scattered by +-30 % fit order 1.99 with the 95 %
    interval [1.26, 2.72] (reports/orders.py); against the band [1.5, 2.5] that
    passes with a note, fails with interval_within_band, and passes it against
    [1.2, 2.8]; two levels give no interval, which interval_within_band refuses."""
    cases = []
    for cells, factor in zip((32, 64, 128, 256), (1.0, 1.3, 0.8, 1.2)):
        h = 3.0 / cells
        keys = {"method": "cpdi", "cells": cells, "end_time": 1.0, "output_times": RING_TIMES}
        cases.append({"id": f"ring-method=cpdi-cells={cells}", "study": "ring", "keys": keys, "status": "completed",
                      "h": h, "times": RING_TIMES, "errors": {"L1_theta0": [0.5 * h * h * factor * t for t in RING_TIMES]}})
    directory = write_suite_directory(tmp_path / "suite", NOISY_SUITE, cases)
    status, out, _ = run_gate(directory, capsys)
    assert status == 1
    rows = {r.split()[0]: r for r in rows_of(out)}
    assert "PASS" in rows["1"] and "1.991 [1.26, 2.72]" in rows["1"]
    assert "its 95% interval [1.26, 2.72] reaches outside [1.5, 2.5]" in rows["1"]
    assert "FAIL" in rows["2"] and "95% interval [1.26, 2.72] not within [1.5, 2.5]" in rows["2"]
    assert "PASS" in rows["3"] and "reaches outside" not in rows["3"]
    assert "FAIL" in rows["4"] and "2 usable levels give no confidence interval" in rows["4"]


def test_a_read_where_the_exact_signal_is_trivial_is_warned_about(tmp_path, capsys):
    """Requirement: a read where the exact quantity the norm measures is below 5 %
    of its largest over the run (the RMS exact displacement for particle_L2; the
    mean |exact| on the line for an L1 line norm) is warned about in the row, for
    a PASS as for a FAIL; a read at an informative time is not."""
    cases = []
    for cells in (32, 64, 128):
        h = 3.0 / cells
        keys = {"method": "cpdi", "cells": cells, "end_time": 1.0, "output_times": RING_TIMES}
        errors = {"particle_L2": [0.5 * h * h] * 3, "L1_theta0": [0.5 * h * h] * 3,
                  "exact_displacement_L2": [0.2, 0.4, 0.004]}   # 1 % of its largest at t = 1
        cases.append({"id": f"ring-method=cpdi-cells={cells}", "study": "ring", "keys": keys, "status": "completed",
                      "h": h, "times": RING_TIMES, "errors": errors})
    suite = NOISY_SUITE.split("[[expect]]")[0]
    for norm, time in (("particle_L2", 1.0), ("particle_L2", 0.5), ("L1_theta0", 0.25), ("L1_theta0", 1.0)):
        suite += f'[[expect]]\nstudy = "ring"\nnorm = "{norm}"\ntime = {time}\norder = 2.0\ntolerance = 0.1\n'
    suite += '[[expect]]\nstudy = "ring"\nnorm = "particle_L2"\norder = 3.0\ntolerance = 0.1\n'
    directory = write_suite_directory(tmp_path / "suite", suite, cases)
    status, out, _ = run_gate(directory, capsys)
    rows = {r.split()[0]: r for r in rows_of(out)}
    warning = "warning: read where the exact signal is 1 % of its largest"
    assert "PASS" in rows["1"] and warning in rows["1"]
    assert "PASS" in rows["2"] and "warning" not in rows["2"]
    # The synthetic line's exact values are sin(pi (R - 0.75) / 0.5) t: at t = 0.25 a quarter of their largest.
    assert "PASS" in rows["3"] and "warning" not in rows["3"]
    assert "PASS" in rows["4"] and "warning" not in rows["4"]
    assert "FAIL" in rows["5"] and warning in rows["5"] and "order 2.000 outside [2.9, 3.1]" in rows["5"]
    assert status == 1


PPD_SUITE = """description = "synthetic: particles per direction 1, 2, 4 at 64 cells; cfl 0.4, 0.2, 0.1 at 64 cells"

[[study]]
name = "markers"
scene = "scenes/ring.toml"
sweep = { particles_per_direction = [1, 2, 4] }

[[study]]
name = "steps"
scene = "scenes/ring.toml"
sweep = { cfl = [0.4, 0.2, 0.1] }

[[expect]]
study = "markers"
norm = "L1_theta0"
refine = "particles_per_direction"
order = 2.0
tolerance = 0.1

[[expect]]
study = "steps"
norm = "L1_theta0"
refine = "cfl"
order = 1.0
tolerance = 0.1

[[expect]]
study = "markers"
norm = "particle_L2"
refine = "particles_per_direction"
order = 2.0
tolerance = 0.1
"""


def test_orders_against_particles_per_direction_and_the_time_step(tmp_path, capsys):
    """Requirement: at a fixed cell size, a study refining particles per direction
    is fitted against the particle spacing h / ppd and one refining cfl against the
    time step (cfl h): E = 3 (h / ppd)^2 gives order 2 and E = 0.05 cfl h order 1;
    a norm that does not change with the key has no order, and the reason names
    the spacing, not h."""
    h = 3.0 / 64
    cases = []
    for ppd in (1, 2, 4):
        keys = {"method": "cpdi", "cells": 64, "particles_per_direction": ppd, "cfl": 0.3, "end_time": 1.0,
                "output_times": RING_TIMES}
        cases.append({"id": f"markers-particles_per_direction={ppd}", "study": "markers", "keys": keys,
                      "status": "completed", "h": h, "times": RING_TIMES,
                      "errors": {"L1_theta0": [3.0 * (h / ppd) ** 2] * 3, "particle_L2": [1e-3] * 3}})
    for cfl in (0.4, 0.2, 0.1):
        keys = {"method": "cpdi", "cells": 64, "particles_per_direction": 2, "cfl": cfl, "end_time": 1.0,
                "output_times": RING_TIMES}
        cases.append({"id": f"steps-cfl={cfl}", "study": "steps", "keys": keys, "status": "completed", "h": h,
                      "times": RING_TIMES, "errors": {"L1_theta0": [0.05 * cfl * h] * 3}})
    directory = write_suite_directory(tmp_path / "suite", PPD_SUITE, cases)
    status, out, _ = run_gate(directory, capsys)
    rows = {r.split()[0]: r for r in rows_of(out)}
    assert "PASS" in rows["1"] and "2.000" in rows["1"] and "1,2,4" in rows["1"]
    assert "PASS" in rows["2"] and "1.000" in rows["2"] and "0.4,0.2,0.1" in rows["2"]
    assert "FAIL" in rows["3"] and "order 0.000 outside" in rows["3"]
    assert status == 1
    series = refinement_series(read_suite(directory).cases_of("markers"), "particles_per_direction")
    assert [l.h for l in series_levels(series[0], "L1_theta0")] == pytest.approx([h, h / 2, h / 4])


ROUNDOFF_EXPECTATIONS = """
[[expect]]
study = "roundoff"
norm = "L1_theta0"
order = 2.0
tolerance = 0.1

[[expect]]
study = "roundoff"
norm = "L1_theta0"
max_error = 1e-12

[[expect]]
study = "roundoff"
norm = "particle_L2"
order = 2.0
tolerance = 0.1

[[expect]]
study = "small"
norm = "particle_L2"
order = 2.0
tolerance = 0.1

[[expect]]
study = "small"
norm = "error_axial_stress"
order = 2.0
tolerance = 0.1
"""


def test_an_order_of_errors_at_round_off_fails_and_max_error_holds(tmp_path, capsys):
    """Requirement: an expectation that asks for an order of a series whose errors
    rounding alone can explain (conftest.roundoff_cases: an exact h^2 law whose 64-
    and 128-cell L1 errors are within (256 + steps) ulps of pi, whose 128-cell
    particle_L2 error is within them of the body's 1 m) fails with one reason
    naming the class, the levels and the error over the exact signal, and shows
    no fitted order; a max_error expectation on the same errors holds; the same
    law on a body a billion times smaller, moved a hundred thousand times less,
    is no round-off and passes (the rule is relative, not absolute)."""
    directory = write_suite_directory(tmp_path / "suite", ROUNDOFF_SUITE + ROUNDOFF_EXPECTATIONS, roundoff_cases())
    status, out, _ = run_gate(directory, capsys)
    rows = {r.split()[0]: r for r in rows_of(out)}
    assert "FAIL" in rows["1"] and ("errors at round-off at cells=64,128 (up to 1.7e-13 of the exact signal; "
                                    "round-off floor 4.3e-13): no order can be observed; check max_error instead"
                                    ) in rows["1"]
    assert "- (round-off)" in rows["1"] and "2.000" not in rows["1"] and "outside" not in rows["1"]
    assert "PASS" in rows["2"] and "E = 4e-13 <= 1e-12" in rows["2"]
    assert "FAIL" in rows["3"] and "errors at round-off at cells=128 (up to 2.5e-08 of the exact signal; " \
                                   "round-off floor 7.9e-08)" in rows["3"]
    assert "PASS" in rows["4"] and "2.000 [2.00, 2.00]" in rows["4"]
    assert "PASS" in rows["5"] and "2.000 [2.00, 2.00]" in rows["5"]
    assert status == 1 and "2 of 5 expectations fell short" in out


def _settle(directory, case_id, **attributes):
    """Gives a results file a /settling group (results-format.md), in place of any it has."""
    norms = attributes.pop("norms", None)
    with h5py.File(directory / "cases" / f"{case_id}.h5", "a") as f:
        if "settling" in f:
            del f["settling"]
        group = f.create_group("settling")
        group.attrs.update(attributes)
        if norms is not None:
            group.create_group("norms").attrs.update(norms)


def test_an_order_at_the_settling_level_fails_and_says_so(tmp_path, capsys):
    """Requirement: a static run's error that its stopping short of the static
    state could leave gives no order. The "small" study of
    conftest.roundoff_cases (particle_L2 4e-13, 1e-13, 2.5e-14 m, far above
    round-off; error_axial_stress 1e-9 .. 6.25e-11) passes its order expectations
    (4, 5) until: a relaxation that would still change the 64-cell particle_L2 by
    1.5e-13 m classes the series "settling", and the gate names the level and
    the ratio; a change of 1e-15 m does not. Load steps that end 5e-14 m (mass-
    weighted RMS) from equilibrium hold the 128-cell particle_L2; a strain RMS of
    1e-11 over a largest |F - I| of 0.2 leaves 1e-10 in a relative stress (twice
    over a region), which holds the 128-cell error_axial_stress (6.25e-11). A
    read before the end is not judged by the end's settling."""
    directory = write_suite_directory(tmp_path / "suite", ROUNDOFF_SUITE + ROUNDOFF_EXPECTATIONS, roundoff_cases())
    _settle(directory, "small-cells=64", method="relaxation", displacement=1e-9, strain=1e-9,
            norms={"particle_L2": 1.5e-13, "error_axial_stress": 0.0})
    _settle(directory, "small-cells=32", method="relaxation", displacement=1e-9, strain=1e-9,
            norms={"particle_L2": 1e-15})
    status, out, _ = run_gate(directory, capsys)
    rows = {r.split()[0]: r for r in rows_of(out)}
    assert "FAIL" in rows["4"] and "- (settling)" in rows["4"] and (
        "errors at the settling level at cells=64 (the run's distance from its static state at the end could "
        "leave up to 1.5 times the error") in rows["4"]
    assert "PASS" in rows["5"] and "2.000 [2.00, 2.00]" in rows["5"]
    # The report's orders table gives the series the same class, and no order.
    [row] = [r for r in report_rows.order_rows(read_suite(directory))
             if r.study == "small" and r.norm == "particle_L2" and r.at_end]
    assert row.classification == "settling" and not row.has_order
    assert "the settling level at cells=64" in report_tables.order_cells(row)[-1]

    _settle(directory, "small-cells=64", method="newton", displacement=1e-16, strain=0.0)
    for cells in (64, 128):
        with h5py.File(directory / "cases" / f"small-cells={cells}.h5", "a") as f:
            f["particles/deformation_gradient"] = np.array([[[1.2, 0.0], [0.0, 1.0]]] * 4)
    _settle(directory, "small-cells=128", method="newton", displacement=5e-14, strain=1e-11)
    status, out, _ = run_gate(directory, capsys)
    rows = {r.split()[0]: r for r in rows_of(out)}
    assert "FAIL" in rows["4"] and "the settling level at cells=128 (" in rows["4"] and "up to 2 times" in rows["4"]
    assert "FAIL" in rows["5"] and "the settling level at cells=128 (" in rows["5"]
    case = {c.id: c for c in read_suite(directory).cases}["small-cells=128"]
    assert settling_scale(case, "error_axial_stress", 1.0) == pytest.approx(2.0 * 1e-11 / 0.2)
    assert settling_scale(case, "particle_L2", 1.0) == pytest.approx(5e-14)
    assert settling_scale(case, "particle_L2", 0.5) is None
    assert settling_scale(case, "particle_pressure_L2", 1.0) is None
    # A level checked for settling alone (no known exact signal) is judged,
    # and its relative numbers are NaN, not infinite.
    alone = RoundOff(Level(case, 128, case.h, 2.5e-14, ""), float("nan"), 0.0, 5e-14)
    assert alone.floor_kind == "settling"
    assert all(math.isnan(v) for v in (alone.relative_error, alone.relative_floor, alone.relative_settling))


def test_a_small_strain_is_rounded_to_ulps_of_one(tmp_path):
    """Requirement: the relative error of a strain (or a stress formed from one)
    is rounded to ulps of F's entries, near 1, over the strain: with the largest
    |F - I| entry 2e-4 and 100 steps its floor is (256 + 100) eps / 2e-4 = 4e-10,
    so a relative strain error of 1e-11 is at round-off and one of 1e-6 is not;
    an error_* column of another quantity keeps the floor of the ratio itself."""
    cases = []
    for cells in (8, 16):
        keys = {"method": "cpdi", "cells": cells, "end_time": 1.0, "output_times": RING_TIMES}
        errors = {"error_axial_strain": [1e-11] * 3, "error_period": [1e-11] * 3}
        cases.append({"id": f"bar-cells={cells}", "study": "bar", "keys": keys, "status": "completed",
                      "h": 1.0 / cells, "times": RING_TIMES, "errors": errors})
    directory = write_suite_directory(tmp_path / "suite", "[[study]]\nname = \"bar\"\nscene = \"scenes/ring.toml\"\n",
                                      cases)
    with h5py.File(directory / "cases" / "bar-cells=8.h5", "a") as f:
        f["particles/deformation_gradient"] = np.array([[[1.0 + 2e-4, 0.0], [0.0, 1.0 - 0.5e-4]]] * 4)
    by_id = {c.id: c for c in read_suite(directory).cases}
    case = by_id["bar-cells=8"]
    assert error_scale(case, "error_axial_strain", 1.0) == pytest.approx((1.0, 1.0 / 2e-4))
    assert error_floor_kind(case, "error_axial_strain", 1.0, 1e-11) == "round-off"
    assert error_floor_kind(case, "error_axial_strain", 1.0, 1e-6) is None
    assert error_scale(case, "error_period", 1.0) == (1.0, 1.0)
    assert error_floor_kind(case, "error_period", 1.0, 1e-11) is None
    # Without F in the file the ratio's own floor, 7.9e-14.
    assert error_scale(by_id["bar-cells=16"], "error_axial_strain", 1.0) == (1.0, 1.0)



def test_a_fit_on_fewer_levels_than_the_figure_says_which(tmp_path, capsys):
    """Requirement: where an expectation names fewer levels than the series has
    usable (64, 128 of 32, 64, 128), its row says which it fitted and that the
    report's figure fits them all; where it names them all, no such note."""
    suite = SYNTHETIC_SUITE.replace("levels = [32, 64, 128]", "levels = [64, 128]")
    directory = write_suite_directory(tmp_path / "suite", suite, synthetic_ring_cases())
    status, out, _ = run_gate(directory, capsys)
    [row] = rows_of(out)
    assert status == 0 and "PASS" in row
    assert "fitted on cells=64,128; the report's figure fits all 3 usable levels" in row
    directory = write_suite_directory(tmp_path / "all", SYNTHETIC_SUITE, synthetic_ring_cases())
    _, out, _ = run_gate(directory, capsys)
    assert "fitted on" not in out
