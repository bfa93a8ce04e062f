"""Requirements of the run-health figure (reports/report.py, health_figure): drawn
per study from /probes/monitors (reports/results-format.md, "/probes/monitors"),
one line per case, a failed case's failure time marked; left out for a study
whose results files have no monitors (written before they existed), such as
the stored gold directory; the energy balance error is divided by the scale
the solver wrote (energy_scale)."""
import json
import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest

from . import health_plot
from . import report
from . import scene_figures
from .conftest import record_calls, write_case_results
from .probes import RunMonitors, relative_energy_created
from .results import Case, CaseResults

GOLD = Path(__file__).parent / "gold"
INITIAL_ENERGY = 100.0
# the column each gold study's expectations name (gold/suite.toml), so that /errors has it
GOLD_NORMS = {"ring": "L1_theta0", "ring-stopped": "L1_theta0", "axis-aligned": "L1_line_y_mid",
              "rz-cylinder": "L1_line_z_quarter"}
GOLD_FAILURE = {"ring-stopped": ("nan", 0.121)}    # its manifest detail: "nan at t = 0.121 s"


def synthetic_monitors(times, method, cells, failed=False):
    """Plausible /probes/monitors columns at `times`: a body force doing 20 t J of work,
    damping taking t J, energy made from nothing -1e-3 t (32 / cells) E0 (twice that for
    GIMP, 5 E0 t for a failed run), kinetic and strain splitting what is left 60:40 so that the balance
    closes; J within 1 -+ 0.1 t; distortion 1 + 0.5 t for CPDI, 1 for GIMP, NaN for
    linear MPM."""
    t = np.asarray(times, float)
    work = {"work_body_force": 20.0 * t, "work_constraints": 0.0 * t, "work_contact": 0.0 * t,
            "work_damping": -1.0 * t}
    created = (5.0 if failed else -1e-3 * 32 / cells * (2.0 if method == "gimp" else 1.0)) * INITIAL_ENERGY * t
    energy = INITIAL_ENERGY + sum(work.values()) + created
    distortion = {"cpdi": 1.0 + 0.5 * t, "gimp": 1.0 + 0.0 * t}.get(method, np.full(t.shape, np.nan))
    return {"time": t, "kinetic_energy": 0.6 * energy, "strain_energy": 0.4 * energy, **work,
            "energy_created": created, "energy_scale": np.fmax(INITIAL_ENERGY, 20.0 * t), "min_J": 1.0 - 0.1 * t, "max_J": 1.0 + 0.1 * t,
            "max_speed_over_wave_speed": 0.05 + 0.01 * t, "max_domain_distortion": distortion,
            "particles_near_edge": 0.0 * t}


def gold_with_results(directory, monitors_in=()):
    """A copy of reports/gold (manifest.json, suite.toml, cases/*.json) with a results
    file (conftest.write_case_results) for every case that ran: the gold directory
    keeps no .h5 files (.gitignore). Cases of the studies in `monitors_in` get a
    /probes/monitors group at the output times they reached."""
    shutil.copytree(GOLD, directory)
    manifest = json.loads((directory / "manifest.json").read_text())
    for entry in manifest["cases"]:
        if entry["status"] not in ("completed", "failed"):
            continue                                  # the crashed case keeps no results file, as in the suite
        keys, study = entry["keys"], entry["study"]
        reason, failure_time = GOLD_FAILURE.get(study, ("", float("nan")))
        times = [t for t in keys["output_times"] if not t > failure_time]
        h = float(keys.get("domain", keys.get("length", keys.get("outer_radius", 1.0)))) / keys["cells"]
        errors = {GOLD_NORMS[study]: [h * h * t for t in times], "particle_L2": [h * h * t for t in times]}
        path = directory / entry["results"]
        write_case_results(path, keys, h, errors, times, status=entry["status"], failure_reason=reason,
                           failure_time=failure_time)
        if study in monitors_in:
            with h5py.File(path, "a") as f:
                group = f["probes"].create_group("monitors")
                group.attrs["initial_energy"] = INITIAL_ENERGY
                for name, values in synthetic_monitors(times, keys["method"], keys["cells"],
                                                       entry["status"] == "failed").items():
                    group[name] = values
    return directory


@pytest.fixture
def drawn(monkeypatch):
    """The curves handed to health_plot.run_health, by figure title."""
    return record_calls(monkeypatch, health_plot, "run_health")


needs_gold = pytest.mark.skipif(not (GOLD / "manifest.json").is_file(), reason="reports/gold is not there")


@needs_gold
def test_health_figure_per_study_with_monitors(tmp_path, drawn):
    """Requirement: each study whose results files have /probes/monitors gets a
    run-health figure, embedded in report.html and linked from report.md, one line
    per case labelled like the other figures; a failed case is labelled with its
    status and failure time and marked there; a study without monitors gets none."""
    directory = gold_with_results(tmp_path / "suite", monitors_in=("ring", "ring-stopped", "rz-cylinder"))
    written, figure_count = report.write_report(directory, tmp_path / "out")
    names = sorted(p.name for p in (tmp_path / "out" / "figures").glob("*-health.png"))
    assert names == ["ring-health.png", "ring-stopped-health.png", "rz-cylinder-health.png"]   # not axis-aligned
    markdown = written["markdown"].read_text()
    assert all(f"](figures/{name})" in markdown for name in names)
    assert "ring: the run's health at each output time (/probes/monitors)" in markdown
    page = written["html"].read_text()
    assert page.count("src='data:image/png;base64,") == figure_count
    assert "<figcaption>ring-stopped: the run&#x27;s health at each output time" in page

    ring = drawn["ring: run health at the output times"]
    assert [c.label for c in ring] == ["method=gimp, cells=32", "method=gimp, cells=64", "method=cpdi, cells=32",
                                       "method=cpdi, cells=64"]
    assert all(np.isnan(c.stopped_at) for c in ring)
    # the energy balance error of the finest cpdi case: 1e-3 t (32/64) E0 over the scale, the larger
    # of E0 and the body force's work so far (20 t, growing)
    finest = ring[-1]
    scale = np.maximum(INITIAL_ENERGY, 20.0 * finest.time)
    assert np.allclose(finest.energy_error, 0.5e-3 * INITIAL_ENERGY * finest.time / scale)
    assert np.allclose(finest.distortion, 1.0 + 0.5 * finest.time)

    (stopped,) = drawn["ring-stopped: run health at the output times"]
    assert stopped.label == "method=linear, cells=32 (failed at t = 0.121 s: nan)"
    assert stopped.stopped_at == pytest.approx(0.121)
    assert list(stopped.time) == [0.1] and np.isnan(stopped.distortion).all()    # linear MPM: no CPDI domains


@needs_gold
def test_gold_without_monitors_has_no_health_figure(tmp_path, drawn):
    """Requirement: results files without /probes/monitors (written before the
    monitors existed) give no run-health figure, no error and no empty figure:
    the stored gold directory as it is, and with results files but no monitors."""
    for name, directory in (("gold", GOLD), ("results", gold_with_results(tmp_path / "suite"))):
        written, figure_count = report.write_report(directory, tmp_path / name)
        assert figure_count > 0
        assert not list((tmp_path / name / "figures").glob("*health*"))
        # (the case table's health column stays: it gives each case's verdict)
        text = written["markdown"].read_text()
        assert "run health" not in text and "health.png" not in text
    assert drawn == {}


def test_energy_balance_error_is_over_the_scale_the_solver_wrote():
    """Requirement: the energy balance error is abs(energy_created) over the file's
    energy_scale at each output time (the solver's blow-up and health scale; the
    report forms no scale of its own); NaN where the scale is not positive, and at
    every time for a file written before energy_scale."""
    columns = {"energy_created": np.array([-1.0, 1.2, 3.0, np.nan, 1.0]),
               "energy_scale": np.array([10.0, 12.0, 30.0, 30.0, 0.0]),
               "work_body_force": np.array([0.0, -12.0, 3.0, 4.0, 5.0])}
    monitors = RunMonitors(10.0, np.array([0.0, 1.0, 2.0, 3.0, 4.0]), columns)
    ratio = relative_energy_created(monitors)
    assert np.allclose(ratio[:3], 0.1) and np.isnan(ratio[3]) and np.isnan(ratio[4])
    del columns["energy_scale"]
    assert np.isnan(relative_energy_created(RunMonitors(10.0, np.arange(5.0), columns))).all()


def test_many_cases_draw_the_finest_failed_and_completed_of_each_method():
    """Requirement: with more than scene_figures.HEALTH_MAX_CASES cases the figure draws, per
    method, the finest completed case and the finest case that did not complete."""
    def case(method, cells, status="completed"):
        results = CaseResults({"h": 1.0 / cells, "status": status}, np.zeros(0), {}, {})
        return Case(f"{method}-{cells}", "s", {"method": method, "cells": cells}, status, "", Path("x.h5"),
                    results=results)
    cases = [case(m, n, "failed" if (m, n) == ("linear", 256) else "completed")
             for m in ("linear", "cpdi") for n in (8, 16, 32, 64, 128, 256, 512)]
    chosen, selected = scene_figures.health_selection(cases)
    assert selected and [c.id for c in chosen] == ["linear-256", "linear-512", "cpdi-512"]
    # many failures: only the finest of them per method
    failing = [case(m, n, "failed" if n >= 64 else "completed")
               for m in ("linear", "gimp") for n in (8, 16, 32, 64, 128, 256, 512)]
    chosen, selected = scene_figures.health_selection(failing)
    assert selected and [c.id for c in chosen] == ["linear-32", "linear-512", "gimp-32", "gimp-512"]
    few, selected = scene_figures.health_selection(cases[:scene_figures.HEALTH_MAX_CASES])
    assert not selected and len(few) == scene_figures.HEALTH_MAX_CASES


@needs_gold
def test_measured_stable_step_adds_the_step_ratio(tmp_path, drawn):
    """Requirement: where the runs measured their stable step (the monitors
    largest_frequency, stable_step and cfl_step of stable_step_iterations), each
    curve carries cfl_step / stable_step, the figure gets its fifth panel and the
    caption says what it is; without those columns the curves carry NaN there."""
    directory = gold_with_results(tmp_path / "suite", monitors_in=("ring", "rz-cylinder"))
    for path in (directory / "cases").glob("ring-method=*.h5"):
        with h5py.File(path, "a") as f:
            group = f["probes/monitors"]
            t = group["time"][:]
            group["largest_frequency"] = 100.0 * (1.0 + t)
            group["stable_step"] = 2.0 / (100.0 * (1.0 + t))
            group["cfl_step"] = 0.004 + 0.0 * t
    written, _ = report.write_report(directory, tmp_path / "out")
    ring = drawn["ring: run health at the output times"]
    assert ring and all(np.allclose(c.step_ratio, 0.004 * 100.0 * (1.0 + c.time) / 2.0) for c in ring)
    assert all(np.isnan(c.step_ratio).all() for c in drawn["rz-cylinder: run health at the output times"])
    assert "the step the CFL rule takes over the measured stable step" in written["markdown"].read_text()
    figure = health_plot.run_health(ring, "five panels")
    assert len(figure.axes) == 5
    four = health_plot.run_health(drawn["rz-cylinder: run health at the output times"], "four panels")
    assert len(four.axes) == 4


@needs_gold
def test_what_slows_the_step_gets_its_panel(tmp_path, drawn):
    """Requirement: where the results files carry max_wave_speed_ratio and
    max_basis_stiffening (what lifts the CFL step's signal speed above the
    small-strain wave speed), each curve carries both, the figure gets a panel
    for them and the caption names them; files without them draw no such panel."""
    directory = gold_with_results(tmp_path / "suite", monitors_in=("ring", "rz-cylinder"))
    for path in (directory / "cases").glob("ring-method=*.h5"):
        with h5py.File(path, "a") as f:
            group = f["probes/monitors"]
            t = group["time"][:]
            group["max_wave_speed_ratio"] = 1.0 + 2.0 * t
            group["max_basis_stiffening"] = 1.0 + 0.5 * t
    written, _ = report.write_report(directory, tmp_path / "out")
    ring = drawn["ring: run health at the output times"]
    assert ring and all(np.allclose(c.wave_ratio, 1.0 + 2.0 * c.time) for c in ring)
    assert all(np.allclose(c.basis_stiffening, 1.0 + 0.5 * c.time) for c in ring)
    cylinder = drawn["rz-cylinder: run health at the output times"]
    assert all(np.isnan(c.wave_ratio).all() and np.isnan(c.basis_stiffening).all() for c in cylinder)
    assert "the particle's state and density, max c_p / c0 (solid), and the basis, max k_p" in written["markdown"].read_text()
    assert len(health_plot.run_health(ring, "with what slows the step").axes) == 5
    assert len(health_plot.run_health(cylinder, "without").axes) == 4


def test_holes_between_domains_get_their_panel(tmp_path, drawn):
    """Requirement: where the results files carry /probes/coverage at the output
    times of /probes/monitors, each curve carries the share of the material in
    holes (all, and away from the sides), the figure gets a panel for it and the
    caption names it; coverage at other times is not read, and files without it
    draw no such panel."""
    directory = gold_with_results(tmp_path / "suite", monitors_in=("ring", "rz-cylinder"))
    for path in (directory / "cases").glob("ring-method=*.h5"):
        with h5py.File(path, "a") as f:
            t = f["probes/monitors/time"][:]
            group = f["probes"].create_group("coverage")
            group["time"] = t
            group["uncovered_fraction"] = 0.1 * t
            group["inside_fraction"] = 0.05 * t
            group["largest_hole_area"] = 0.0 * t
            group["largest_hole_cells"] = 0.0 * t
    for path in (directory / "cases").glob("rz-cylinder-*.h5"):
        with h5py.File(path, "a") as f:
            t = f["probes/monitors/time"][:]
            group = f["probes"].create_group("coverage")
            group["time"] = t + 1.0                                 # not the monitors' times: left unread
            group["uncovered_fraction"] = 0.1 * t
    written, _ = report.write_report(directory, tmp_path / "out")
    ring = drawn["ring: run health at the output times"]
    assert ring and all(np.allclose(c.holes, 0.1 * c.time) and np.allclose(c.holes_inside, 0.05 * c.time)
                        for c in ring)
    cylinder = drawn["rz-cylinder: run health at the output times"]
    assert all(np.isnan(c.holes).all() for c in cylinder)
    assert "the share of the material that no particle domain covers" in written["markdown"].read_text()
    assert len(health_plot.run_health(ring, "with holes").axes) == 5
    assert len(health_plot.run_health(cylinder, "without").axes) == 4


@needs_gold
def test_folded_corner_domains_are_named_in_the_caption(tmp_path, drawn):
    """Requirement: a case whose results file counts CPDI corner domains turned over
    (folded_domains > 0 at some output time) is named in its study's run-health
    caption with the largest count and the first output time it was seen; a study
    whose counts are all zero, or whose files have no such column, names none."""
    directory = gold_with_results(tmp_path / "suite", monitors_in=("ring", "rz-cylinder"))
    for path in (directory / "cases").glob("ring-method=*.h5"):
        with h5py.File(path, "a") as f:
            group = f["probes/monitors"]
            t = group["time"][:]
            folded = "method=cpdi" in path.name and "cells=64" in path.name
            group["folded_domains"] = np.where(t >= t[-1], 4.0, 0.0) if folded else 0.0 * t
    written, _ = report.write_report(directory, tmp_path / "out")
    markdown = written["markdown"].read_text()
    ring_caption = next(line for line in markdown.splitlines() if line.startswith("_ring: the run's health"))
    assert "CPDI corner domains turned over (folded_domains" in ring_caption
    assert "in method=cpdi, cells=64: 4 at most, from t = " in ring_caption
    assert "cells=32: " not in ring_caption.split("turned over")[1]
    cylinder_caption = next(line for line in markdown.splitlines() if line.startswith("_rz-cylinder: the run's health"))
    assert "turned over" not in cylinder_caption


def test_few_output_times_are_markers_not_lines():
    """Requirement: a case with one or two output times is drawn as markers
    alone (two points joined read as a trend); more output times as lines."""
    def curve(times):
        t = np.asarray(times, float)
        return health_plot.HealthCurve("case", t, 1e-3 + 0 * t, 1 - 0.1 * t, 1 + 0.1 * t, 0.1 + 0 * t, 1 + t,
                                       holes=0.01 * t, holes_inside=0.005 * t)
    few = health_plot.run_health([curve([0.5, 1.0])], "few")
    many = health_plot.run_health([curve([0.25, 0.5, 0.75, 1.0])], "many")
    for figure, style in ((few, "None"), (many, "-")):
        lines = [line for axes in figure.axes for line in axes.get_lines() if len(line.get_xdata()) > 1
                 and line.get_marker() not in ("None", "", None, "x")]
        assert lines and all(line.get_linestyle() == style for line in lines if line.get_linestyle() != ":"
                             or style == "None")
