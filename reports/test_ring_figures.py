"""The ring's figures in the Sandia report's manner (ring_figures.py): L1 over
time per case, and the marker refinement at fixed mesh."""
import pytest

from . import figures
from . import report
from .conftest import RING_TIMES, SYNTHETIC_SUITE, record_calls, synthetic_ring_cases, write_suite_directory

MARKER_SUITE = """description = "synthetic marker refinement: E = 0.1 h + 0.01 / ppd"

[[study]]
name = "markers"
scene = "scenes/ring.toml"
sweep = { cells = [32, 64], particles_per_direction = [2, 4, 8] }
"""


def marker_cases():
    cases = []
    for cells in (32, 64):
        for ppd in (2, 4, 8):
            keys = {"method": "cpdi", "cells": cells, "particles_per_direction": ppd, "amplitude": 0.5,
                    "end_time": 1.0, "output_times": RING_TIMES}
            h = 3.0 / cells
            law = 0.1 * h + 0.01 / ppd
            case = {"id": f"markers-cells={cells}-particles_per_direction={ppd}", "study": "markers", "keys": keys,
                    "status": "completed", "h": h, "times": RING_TIMES,
                    "errors": {n: [law * t for t in RING_TIMES] for n in ("L1_theta0", "particle_L2")}}
            if cells == 64 and ppd == 8:
                case.update(status="failed", failure_reason="non-positive J", failure_time=0.6,
                            times=RING_TIMES[:2], errors={n: v[:2] for n, v in case["errors"].items()})
            cases.append(case)
    return cases


def test_l1_over_time_draws_every_case_with_results_to_where_it_stopped(tmp_path, monkeypatch):
    """Requirement: with three or more output times, one panel per probe line, one
    curve per case that has results, its /errors column at each output time; a
    failed case's curve ends at its last output and its label says so; crashed and
    pending cases draw nothing."""
    calls = record_calls(monkeypatch, figures, "log_curves")
    directory = write_suite_directory(tmp_path / "suite", SYNTHETIC_SUITE, synthetic_ring_cases())
    report.main([str(directory), "-o", str(tmp_path / "out")])
    (panel,) = calls["ring: L1 of each probe line over time"]
    assert panel.title == "L1_theta0"
    labels = [c.label for c in panel.curves]
    assert labels == ["method=linear, cells=32", "method=linear, cells=64 (failed at t = 0.3 s)",
                      "method=linear, cells=256", "method=cpdi, cells=32", "method=cpdi, cells=64",
                      "method=cpdi, cells=128"]
    cpdi_64 = panel.curves[4]
    assert list(cpdi_64.x) == RING_TIMES
    assert list(cpdi_64.y) == pytest.approx([0.5 * (3.0 / 64) ** 2 * t for t in RING_TIMES])
    assert list(panel.curves[1].x) == RING_TIMES[:1]
    assert (tmp_path / "out" / "figures" / "ring-L1-over-time.png").is_file()


def test_marker_refinement_one_curve_per_mesh_against_particles_per_direction(tmp_path, monkeypatch):
    """Requirement: a study sweeping cells and particles_per_direction gets the error at
    the end time against particles per direction, one curve per cell count; a case
    that stopped before the end time leaves its point out."""
    calls = record_calls(monkeypatch, figures, "log_curves")
    directory = write_suite_directory(tmp_path / "suite", MARKER_SUITE, marker_cases())
    report.main([str(directory), "-o", str(tmp_path / "out")])
    (panel,) = calls["markers: marker refinement at fixed mesh, L1_theta0 at the end time"]
    assert [c.label for c in panel.curves] == ["cells=32", "cells=64"]
    coarse, fine = panel.curves
    assert coarse.x == [2.0, 4.0, 8.0]
    assert coarse.y == pytest.approx([0.1 * 3.0 / 32 + 0.01 / p for p in (2, 4, 8)])
    assert fine.y[:2] == pytest.approx([0.1 * 3.0 / 64 + 0.01 / p for p in (2, 4)])
    assert fine.y[2] != fine.y[2]     # NaN: the failed case has no value at the end time
    assert (tmp_path / "out" / "figures" / "markers-marker-refinement-L1_theta0.png").is_file()


def test_no_ring_figures_without_their_data(tmp_path, monkeypatch):
    """Two output times and no particles-per-direction sweep: neither figure."""
    calls = record_calls(monkeypatch, figures, "log_curves")
    cases = synthetic_ring_cases()
    for c in cases:
        if "times" in c:
            c["times"] = c["times"][:2]
            c["errors"] = {n: v[:2] for n, v in c["errors"].items()}
    directory = write_suite_directory(tmp_path / "suite", SYNTHETIC_SUITE, cases)
    report.main([str(directory), "-o", str(tmp_path / "out")])
    assert calls == {}
