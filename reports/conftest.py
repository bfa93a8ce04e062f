"""Shared pytest fixtures: synthetic ring results files with the layout of
reports/results-format.md and synthetic suite output directories with the
layout of suites/README.md, so the report, the gate and the tables are tested
on data whose answer is known."""
import json
import tomllib

import h5py
import numpy as np
import pytest


def configuration_text(keys):
    """The `configuration` attribute a run writes: its resolved keys as TOML
    (the gate checks them against the manifest's, reports/consistency.py)."""
    def value(v):
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, (list, tuple)):
            return "[" + ", ".join(value(x) for x in v) + "]"
        return json.dumps(v) if isinstance(v, str) else repr(v)
    return "".join(f"{k} = {value(v)}\n" for k, v in keys.items())


def write_ring_results(path, cells, l1_at_times, times, method="cpdi", amplitude=0.5,
                       status="completed", failure_reason="", failure_time=float("nan")):
    h = 3.0 / cells
    with h5py.File(path, "w") as f:
        f.attrs["h"] = h
        f.attrs["cells"] = np.int64(cells)
        f.attrs["scene"] = "ring"
        f.attrs["particles_per_direction"] = np.int64(2)
        f.attrs["forcing_time_s"] = 0.1
        f.attrs["method"] = method
        f.attrs["amplitude"] = amplitude
        f.attrs["status"] = status
        f.attrs["failure_reason"] = failure_reason
        f.attrs["failure_time"] = failure_time
        f.attrs["time_reached"] = times[-1] if status == "completed" else failure_time
        f.attrs["wall_time_s"] = 1.0
        f.attrs["end_time"] = times[-1]
        f.attrs["steps"] = np.int64(10)
        f.attrs["particle_steps_per_second"] = 1e6
        e = f.create_group("errors")
        e["time"] = np.asarray(times, dtype=float)
        for name in ("L1_theta0", "L1_theta_plus45", "L1_theta_minus45", "particle_L1"):
            e[name] = np.asarray(l1_at_times, dtype=float)


@pytest.fixture
def second_order_series(tmp_path):
    """Three meshes whose error is exactly 0.7 h^2 at every output time."""
    times = [0.25, 1.0]
    paths = []
    for cells in (32, 64, 128):
        h = 3.0 / cells
        path = tmp_path / f"ring-{cells}.h5"
        write_ring_results(path, cells, [0.7 * h * h, 0.7 * h * h], times)
        paths.append(str(path))
    return paths


RING_TIMES = [0.25, 0.5, 1.0]
PROBE_POINTS = 11
CIRCLE_POINTS = 16


def write_case_results(path, keys, h, errors_at_times, times, status="completed", failure_reason="",
                       failure_time=float("nan"), wall_time_s=1.0, contact_pressure=None, history=None,
                       measurements=None, particle_positions=None):
    """A results file with the layout of reports/results-format.md: root attributes
    (every key, h, status, ...), /errors with `errors_at_times` (column -> values at
    `times`), and ring-like probes whose arrays reproduce the L1_theta0 column:
    simulated = exact + that error at every point, so eq. 3.1 gives it back.
    Optionally /probes/contact_pressure (dict of its datasets x, time, pressure,
    exact_pressure), /probes/history (dict: time and one array per scalar),
    /measurements (dict: attribute name -> value) and /particles/reference_position
    (N x 2)."""
    end_time = float(keys.get("end_time", RING_TIMES[-1]))
    radius = np.linspace(0.75, 1.25, PROBE_POINTS)
    angle = np.linspace(0.0, 2.0 * np.pi, CIRCLE_POINTS, endpoint=False)
    line_error = np.asarray(errors_at_times.get("L1_theta0", [0.0] * len(times)), float)
    with h5py.File(path, "w") as f:
        for name, value in keys.items():
            f.attrs[name] = np.asarray(value, dtype=float) if isinstance(value, list) else value
        f.attrs["configuration"] = configuration_text(keys)
        f.attrs.update({"h": h, "status": status, "failure_reason": failure_reason, "failure_time": failure_time,
                        "time_reached": end_time if status == "completed" else failure_time,
                        "wall_time_s": wall_time_s, "end_time": end_time, "steps": np.int64(100),
                        "particle_count": np.int64(1000), "scene": "ring"})
        e = f.create_group("errors")
        e["time"] = np.asarray(times, float)
        for name, values in errors_at_times.items():
            e[name] = np.asarray(values, float)
        probes = f.create_group("probes")
        line = probes.create_group("theta0")
        line.attrs["quantity"] = "angular_displacement"
        line["reference_radius"] = radius
        line["reference_position"] = np.stack([radius, 0.0 * radius], axis=1)
        line["time"] = np.asarray(times, float)
        exact = np.array([np.sin(np.pi * (radius - 0.75) / 0.5) * t for t in times]).reshape(len(times), -1)
        line["exact_angular_displacement"] = exact
        line["angular_displacement"] = exact + line_error[:, None]
        point = probes.create_group("point_R1")
        point.attrs["quantity"] = "angular_displacement"
        point.attrs["reference_position"] = np.array([1.0, 0.0])
        steps = np.linspace(0.0, times[-1] if times else 0.0, 21)
        point["time"] = steps
        point["exact_angular_displacement"] = 0.5 * np.sin(np.pi * steps)
        point["angular_displacement"] = 0.5 * np.sin(np.pi * steps) + h * h * steps
        circle = probes.create_group("circle")
        circle.attrs["quantity"] = "angular_displacement"
        circle.attrs["reference_radius"] = 1.0
        circle["reference_angle"] = angle
        circle["time"] = np.asarray(times, float)
        circle["exact_angular_displacement"] = np.zeros((len(times), CIRCLE_POINTS))
        circle["angular_displacement"] = np.array([h * np.cos(4 * angle) for _ in times]).reshape(len(times), -1)
        circle["error_spectrum"] = np.array([[h * (k == 4) + 1e-12 for k in range(CIRCLE_POINTS // 2 + 1)]
                                             for _ in times]).reshape(len(times), -1)
        for name, datasets in (("contact_pressure", contact_pressure), ("history", history)):
            if datasets is not None:
                group = probes.create_group(name)
                for dataset, values in datasets.items():
                    group[dataset] = np.asarray(values, float)
        if measurements is not None:
            f.create_group("measurements").attrs.update(measurements)
        if particle_positions is not None:
            f.create_group("particles")["reference_position"] = np.asarray(particle_positions, float)


def write_suite_directory(directory, suite_toml, cases):
    """DIR/suite.toml, DIR/manifest.json and DIR/cases/<id>.{h5,json} (suites/README.md).
    cases: dicts with id, study, keys, status and, for cases that ran, h, errors,
    times (and optionally failure_reason, failure_time, contact_pressure, history,
    measurements, particle_positions: see write_case_results)."""
    directory.mkdir(parents=True, exist_ok=True)
    (directory / "cases").mkdir(exist_ok=True)
    (directory / "suite.toml").write_text(suite_toml)
    entries = []
    for case in cases:
        entry = {"id": case["id"], "study": case["study"], "keys": case["keys"], "results": f"cases/{case['id']}.h5",
                 "status": case["status"], "exit_code": 0, "wall_time_s": 1.0, "detail": case.get("detail", "")}
        if "errors" in case:
            write_case_results(directory / entry["results"], case["keys"], case["h"], case["errors"], case["times"],
                               status="failed" if case["status"] == "failed" else "completed",
                               failure_reason=case.get("failure_reason", ""),
                               failure_time=case.get("failure_time", float("nan")),
                               contact_pressure=case.get("contact_pressure"), history=case.get("history"),
                               measurements=case.get("measurements"),
                               particle_positions=case.get("particle_positions"))
        (directory / "cases" / f"{case['id']}.json").write_text(json.dumps(entry))
        entries.append(entry)
    # The [[expect]] tables as mpmvv suite records them (checked there; here taken as written).
    expectations = tomllib.loads(suite_toml).get("expect", [])
    (directory / "manifest.json").write_text(json.dumps({"suite": "synthetic", "suite_file": "suites/synthetic.toml",
                                                         "expectations": expectations, "cases": entries}))
    return directory


SYNTHETIC_SUITE = """description = "synthetic ring suite: cpdi errors exactly 0.5 h^2, linear errors 0.2 h"

[[study]]
name = "ring"
scene = "scenes/ring.toml"
sweep = { method = ["linear", "cpdi"], cells = [32, 64, 128, 256] }

[[expect]]
study = "ring"
where = { method = "cpdi" }
norm = "L1_theta0"
levels = [32, 64, 128]
order = 2.0
tolerance = 0.1
max_error_constant = 0.6
"""


def synthetic_ring_cases(linear_fails_at_64=True):
    """Two series on cells 32..256: cpdi with E = 0.5 h^2 (its 256-cell case still
    pending), linear with E = 0.2 h whose 64-cell case failed at t = 0.3 (after the
    first output) and whose 128-cell case crashed; particle norms follow the same law."""
    cases = []
    for method, law in (("linear", lambda h: 0.2 * h), ("cpdi", lambda h: 0.5 * h * h)):
        for cells in (32, 64, 128, 256):
            keys = {"method": method, "cells": cells, "amplitude": 0.5, "end_time": 1.0,
                    "particles_per_direction": 2, "output_times": RING_TIMES}
            case = {"id": f"ring-method={method}-cells={cells}", "study": "ring", "keys": keys,
                    "status": "completed"}
            h = 3.0 / cells
            errors = {name: [law(h) * t for t in RING_TIMES] for name in ("L1_theta0", "particle_L1", "particle_L2")}
            if method == "linear" and cells == 64 and linear_fails_at_64:
                case.update(status="failed", failure_reason="non-positive J", failure_time=0.3, times=RING_TIMES[:1],
                            errors={k: v[:1] for k, v in errors.items()}, h=h)
            elif method == "linear" and cells == 128:
                case.update(status="crashed", detail="signal 11 (SIGSEGV)")
            elif method == "cpdi" and cells == 256:
                case.update(status="pending")
            else:
                case.update(h=h, times=RING_TIMES, errors=errors)
            cases.append(case)
    return cases


@pytest.fixture
def synthetic_suite(tmp_path):
    return write_suite_directory(tmp_path / "suite", SYNTHETIC_SUITE, synthetic_ring_cases())


HERTZ_SUITE = """description = "synthetic Hertz suite: contact pressure, load-approach history, measurements"

[[study]]
name = "mesh"
scene = "scenes/hertz-cylinder.toml"
sweep = { cells = [25, 50, 100, 200] }
"""
HERTZ_END_TIME = 0.002
HERTZ_WIDTH = 0.2            # plate width [m]: h = HERTZ_WIDTH / cells


def hertz_exact_pressure(x, p0, a):
    """Hertz's p0 sqrt(1 - x^2/a^2), zero outside the contact."""
    return p0 * np.sqrt(np.clip(1.0 - (np.asarray(x) / a) ** 2, 0.0, None))


def hertz_load(cells):
    """The load [N/m] each level measures: 2 % high on the coarsest, converging as h."""
    return 2.2e7 * (1.0 + 0.5 / cells)


def hertz_half_width(load):
    """a [m] and p0 [Pa] of steel on steel (E* = 1.15e11 Pa, R = 2 m) at a load per unit length [N/m]."""
    a = np.sqrt(4.0 * load * 2.0 / (np.pi * 1.15e11))
    return float(a), float(2.0 * load / (np.pi * a))


def hertz_cases(history=True, contact_pressure=True, measurements=True):
    """cells 25, 50, 100 completed, 200 pending: /probes/contact_pressure at the one
    output (simulated = exact (1 + 2 h / a) inside the contact), /probes/history with
    approach ramped to 0.2 mm and load = approach x stiffness, and /measurements
    (the 25-cell case has none)."""
    cases = []
    for cells in (25, 50, 100, 200):
        keys = {"method": "cpdi", "cells": cells, "end_time": HERTZ_END_TIME, "output_times": [HERTZ_END_TIME]}
        case = {"id": f"mesh-cells={cells}", "study": "mesh", "keys": keys, "status": "completed"}
        if cells == 200:
            case["status"] = "pending"
            cases.append(case)
            continue
        h = HERTZ_WIDTH / cells
        load = hertz_load(cells)
        a, p0 = hertz_half_width(load)
        x = (np.arange(cells // 2 + 2) + 0.5) * h
        exact = hertz_exact_pressure(x, p0, a)
        case.update(h=h, times=[HERTZ_END_TIME], errors={"error_peak_pressure": [0.5 / cells]})
        if contact_pressure:
            case["contact_pressure"] = {"x": x, "time": [HERTZ_END_TIME], "pressure": [exact * (1.0 + 2.0 * h / a)],
                                        "exact_pressure": [exact], "exact_peak_pressure": [p0],
                                        "exact_half_width": [a]}
        if history:
            steps = np.linspace(0.0, HERTZ_END_TIME, 50 * cells // 25)
            approach = 2e-4 * np.minimum(steps / (0.5 * HERTZ_END_TIME), 1.0)
            case["history"] = {"time": steps, "approach": approach, "load": approach * load / 2e-4}
        if measurements and cells != 25:
            case["measurements"] = {"load": load, "half_width_exact": a, "peak_pressure_exact": p0,
                                    "approach": 2e-4}
        cases.append(case)
    return cases


ROUNDOFF_SUITE = """description = "synthetic: errors at round-off beside errors that are small but far above it"

[[study]]
name = "roundoff"
scene = "scenes/ring.toml"
sweep = { cells = [32, 64, 128] }

[[study]]
name = "small"
scene = "scenes/ring.toml"
sweep = { cells = [32, 64, 128] }
"""
ROUNDOFF_L1 = (4e-13, 1e-13, 2.5e-14)        # rad: falls as h^2, but below 64 cells within the floor


def roundoff_cases():
    """Two studies on 32, 64, 128 cells, 100 steps each (write_case_results), whose
    errors fall exactly as h^2. `roundoff`: L1_theta0 errors ROUNDOFF_L1 on the
    ring-like line, whose mean |exact| is 0.574 rad at t = 1 and whose angles give
    M = pi: the round-off floor (256 + 100) eps pi = 2.48e-13 rad, 4.3e-13 of the
    signal, holds the 64- and 128-cell errors; particle_L2 follows the same law in m
    on a body 1 m across moved 1e-6 m (floor 7.9e-14 m: the 128-cell error).
    `small`: the same absolute particle_L2 errors on a body 1e-9 m across moved
    1e-11 m (0.04 to 0.0025 of the signal; floor 7.9e-23 m), and
    error_axial_stress 1e-9, 2.5e-10, 6.25e-11 (floor 7.9e-14): small, but far above
    what rounding can leave."""
    cases = []
    for study, size, displacement in (("roundoff", 1.0, 1e-6), ("small", 1e-9, 1e-11)):
        for cells, error in zip((32, 64, 128), ROUNDOFF_L1):
            keys = {"method": "cpdi", "cells": cells, "end_time": 1.0, "output_times": RING_TIMES}
            positions = np.array([[0.0, 0.0], [size, 0.0], [0.0, size], [0.6 * size, 0.8 * size]])
            errors = {"particle_L2": [error] * 3, "exact_displacement_L2": [displacement] * 3}
            if study == "roundoff":
                errors["L1_theta0"] = [error] * 3
            else:
                errors["error_axial_stress"] = [1e-9 * (32 / cells) ** 2] * 3
            cases.append({"id": f"{study}-cells={cells}", "study": study, "keys": keys, "status": "completed",
                          "h": 3.0 / cells, "times": RING_TIMES, "errors": errors, "particle_positions": positions})
    return cases


def record_calls(monkeypatch, module, name):
    """Replaces the figure function `module.name(curves, title, ...)` with one that
    records the curves it is handed, by figure title, and still draws them; returns
    that record."""
    calls = {}
    original = getattr(module, name)

    def record(curves, title, *args, **kwargs):
        calls[title] = curves
        return original(curves, title, *args, **kwargs)
    monkeypatch.setattr(module, name, record)
    return calls
