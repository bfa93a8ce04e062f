"""The ring's figures in the Sandia report's manner (ring_figures.py): L1 over
time per case, and the marker refinement at fixed mesh."""
import h5py
import numpy as np
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


def add_snapshots(path, times, n=50):
    """/snapshots/<k> as particle_fields = "outputs" writes them: velocity (k + 1) e_x and
    displacement error 0.001 k e_y on n particles."""
    with h5py.File(path, "a") as f:
        for k, t in enumerate(times):
            g = f.create_group(f"snapshots/{k}")
            g.attrs["time"] = t
            g["position"] = np.stack([np.linspace(0.75, 1.25, n), np.zeros(n)], axis=1)
            g["velocity"] = np.tile([k + 1.0, 0.0], (n, 1))
            g["displacement_error"] = np.tile([0.0, 0.001 * k], (n, 1))


def test_particle_maps_of_the_finest_completed_case_at_spread_times(tmp_path, monkeypatch):
    """Requirement: the finest completed case with /snapshots is drawn at up to four of
    its output times, spread over them and ending at the last, coloured by speed and by
    the magnitude of the displacement error."""
    calls = record_calls(monkeypatch, figures, "particle_maps")
    directory = write_suite_directory(tmp_path / "suite", SYNTHETIC_SUITE, synthetic_ring_cases())
    times = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6]
    for cells in (32, 64, 128):          # cpdi 128 is the finest completed; linear 256 too, but on its own series
        add_snapshots(directory / "cases" / f"ring-method=cpdi-cells={cells}.h5", times)
    report.main([str(directory), "-o", str(tmp_path / "out")])
    (maps,) = calls.values()
    assert list(calls) == ["ring: particles of method=cpdi, cells=128"]
    assert [m.label for m in maps] == ["t = 0.1 s", "t = 0.3 s", "t = 0.4 s", "t = 0.6 s"]
    assert [float(m.field[0]) for m in maps] == [1.0, 3.0, 4.0, 6.0]
    assert [float(m.error[0]) for m in maps] == pytest.approx([0.0, 0.002, 0.003, 0.005])
    assert (tmp_path / "out" / "figures" / "ring-particle-maps.png").is_file()
