"""Check a results file against its documented format (reports/results-format.md):
`mpmvv results check FILE`. Every missing or malformed item is named by its
path in the file, one per line; exit 0 when there is none, 1 when there are,
2 (one line) when FILE is not a readable HDF5 file.

What is checked is what the report and the gate read: the root attributes a
run writes whatever its scene (their types and allowed values, and that
status, failure and health agree, and each that is a key of `configuration`
holds its value), /particles (one row per particle, the
shapes of the table), /errors (a `time` column, increasing, and every column
as long, numbers, each value a norm's: finite and >= 0), /probes/monitors and /probes/coverage likewise, each probe group's `quantity` and the
shape of its values against its `time` and points; the value rules beyond
the tables are listed under "mpmvv results check" in results-format.md. A file an external code's
run was ingested into is held to the same rules.

Usage: mpmvv results check FILE [FILE ...]
"""
import argparse
import math
import os
import stat
import sys
import tomllib

import h5py
import numpy as np

from .consistency import norm_problems

STATUSES = ("completed", "lost", "failed", "interrupted")
GEOMETRIES = ("plane-strain", "axisymmetric")
HEALTH = ("healthy", "solution lost")
QUANTITIES = ("angular_displacement", "radial_displacement", "displacement_x", "displacement_y")

# Root attribute -> its kind: "text", "int", "real"; every run writes these.
ROOT = {
    "scene": "text", "configuration": "text", "version": "text", "status": "text", "failure_reason": "text",
    "failure_detail": "text", "health": "text", "health_reason": "text", "geometry": "text", "threads": "int",
    "steps": "int", "particle_count": "int", "particle_steps": "int", "failure_step": "int",
    "failure_particle": "int", "time_reached": "real", "failure_time": "real", "health_time": "real",
    "wall_time_s": "real", "h": "real", "end_time": "real", "cells": "int", "overrides": "text",
    "solver_time_s": "real", "forcing_time_s": "real", "particle_steps_per_second": "real",
    "dt": "real", "dt_min": "real", "dt_max": "real", "frequency_measurements": "real",
}
# The value rule of each numeric root attribute: name -> (test of its value and the attributes, what it must be).
# The step sizes are NaN in a run of no steps (an external program's); `dt_first` is checked where present.
_STEP = (lambda v, a: (v > 0.0 and math.isfinite(v)) or (math.isnan(v) and _number(a.get("steps")) == 0),
         "positive and finite (NaN only in a run of no steps)")
_POSITIVE = (lambda v, a: v > 0.0 and math.isfinite(v), "positive and finite")
_AT_LEAST_ZERO = (lambda v, a: v >= 0.0 and math.isfinite(v), "finite and >= 0")
VALUES = {
    "h": _POSITIVE, "end_time": _POSITIVE, "dt": _STEP, "dt_min": _STEP, "dt_max": _STEP, "dt_first": _STEP,
    "time_reached": _AT_LEAST_ZERO, "wall_time_s": _AT_LEAST_ZERO, "solver_time_s": _AT_LEAST_ZERO,
    "forcing_time_s": _AT_LEAST_ZERO, "particle_steps_per_second": _AT_LEAST_ZERO,
    "frequency_measurements": _AT_LEAST_ZERO, "particle_count": _AT_LEAST_ZERO, "steps": _AT_LEAST_ZERO,
    "particle_steps": _AT_LEAST_ZERO, "threads": _AT_LEAST_ZERO,
}
# Root attributes in order: (smaller, larger), equal within a relative 1e-9.
ORDERED = (("dt_min", "dt_max"), ("time_reached", "end_time"))
# Scene keys whose root attribute says what the run did rather than repeating the configuration
# (results-format.md: `body_force`; an external program's run writes "the external program's own" to both).
DESCRIBED_KEYS = ("body_force", "seeding")

# /probes/monitors columns -> (the test of every row, what the value must be); NaN passes (a run that lost its
# numbers), a name "a <= b" compares two columns row by row.
MONITORS = {
    "energy_scale": (lambda v: ~(v < 0.0), ">= 0 (the larger of the initial energy and abs(work))"),
    "min_J <= max_J": (lambda a, b: ~(a > b), "<= max_J"),
    "min_J_over_exact <= max_J_over_exact": (lambda a, b: ~(a > b), "<= max_J_over_exact"),
}
# /particles dataset -> its shape after N.
PARTICLES = {"reference_position": (2,), "position": (2,), "velocity": (2,), "volume": (), "J": (),
             "deformation_gradient": (2, 2)}
PARTICLES_OPTIONAL = {"domain_corners": (4, 2)}


def _kind_of(value):
    if isinstance(value, (bytes, str)):
        return "text"
    if isinstance(value, (np.integer, int)) and not isinstance(value, (bool, np.bool_)):
        return "int"
    if isinstance(value, (np.floating, float)):
        return "real"
    return type(value).__name__


def _text(value):
    return value.decode() if isinstance(value, bytes) else str(value)


def _number(value):
    """A numeric attribute as a float, None for anything else (text, arrays, booleans)."""
    return float(value) if _kind_of(value) in ("int", "real") else None


def _plain(value):
    """An attribute as the TOML value it came from: text, number, boolean or list."""
    if isinstance(value, bytes):
        return value.decode()
    if isinstance(value, np.ndarray):
        return value.tolist()
    return value.item() if isinstance(value, np.generic) else value


def _same(attribute, configured):
    """Whether a root attribute holds the configuration's value, of the same kind (text, boolean, number,
    list; an integer configured is an integer stored)."""
    value = _plain(attribute)
    if isinstance(configured, list):
        return isinstance(value, list) and len(value) == len(configured) and \
            all(_same(v, c) for v, c in zip(value, configured))
    if isinstance(configured, (str, bool)) or isinstance(value, (str, bool)):
        return type(value) is type(configured) and value == configured
    if isinstance(configured, int) and not isinstance(value, int):
        return False
    return isinstance(value, (int, float)) and math.isclose(value, configured, rel_tol=1e-12, abs_tol=0.0)


def _shown(value):
    value = _plain(value)
    return f"'{value}' (text)" if isinstance(value, str) else repr(value)


def check_configuration(f, problems):
    """`configuration` is TOML; every root attribute that is one of its keys (scene, method, cells, ...) holds
    its value; each `--set` override names one of its keys; h = domain / cells where both are keys (the
    ring's and the expanding ring's square grid)."""
    attrs = f.attrs
    if _kind_of(attrs.get("configuration")) != "text":
        return
    try:
        configuration = tomllib.loads(_text(attrs["configuration"]))
    except tomllib.TOMLDecodeError as error:
        problems.append(f"/@configuration: not TOML ({error})")
        return
    if "scene" not in configuration:
        problems.append("/@configuration: no `scene` key")
    for key, configured in configuration.items():
        if key in DESCRIBED_KEYS:
            continue
        if key not in attrs:
            problems.append(f"/@{key}: missing, the configuration has {key} = {configured!r}")
        elif not _same(attrs[key], configured):
            problems.append(f"/@{key}: {_shown(attrs[key])}, the configuration has {key} = {configured!r}")
    if _kind_of(attrs.get("overrides")) == "text":
        for line in _text(attrs["overrides"]).splitlines():
            if "=" not in line or line.split("=", 1)[0].strip() not in configuration:
                problems.append(f"/@overrides: '{line}' is not key=value for a key of the configuration")
    domain, cells, h = configuration.get("domain"), configuration.get("cells"), _number(attrs.get("h"))
    if isinstance(domain, (int, float)) and isinstance(cells, int) and cells > 0 and h is not None and \
            not math.isclose(h, domain / cells, rel_tol=1e-9):
        problems.append(f"/@h: {h:g}, not domain / cells = {domain:g} / {cells} = {domain / cells:g}")


def check_root(f, problems):
    attrs = f.attrs
    for name, kind in ROOT.items():
        if name not in attrs:
            problems.append(f"/@{name}: missing ({kind})")
            continue
        found = _kind_of(attrs[name])
        # An integer where a real is documented holds the value exactly.
        if found != kind and not (kind == "real" and found == "int"):
            problems.append(f"/@{name}: {_shown(attrs[name]) if found == 'text' else found}, the format has {kind}")
    for name, allowed in (("status", STATUSES), ("geometry", GEOMETRIES), ("health", HEALTH)):
        if name in attrs and _text(attrs[name]) not in allowed:
            problems.append(f"/@{name}: '{_text(attrs[name])}' is none of {', '.join(allowed)}")
    status = _text(attrs.get("status", ""))
    reason = _text(attrs.get("failure_reason", ""))
    if status == "completed" and reason:
        problems.append(f"/@failure_reason: '{reason}' on a completed run")
    if status in ("failed", "lost", "interrupted") and not reason:
        problems.append(f"/@failure_reason: empty on a run whose status is {status}")
    if status == "lost" and _text(attrs.get("health", "")) != "solution lost":
        problems.append("/@health: a lost run's health is 'solution lost'")
    if status == "completed" and _text(attrs.get("health", "")) == "solution lost":
        problems.append("/@status: 'completed' with health 'solution lost': the format has status 'lost'")
    for name, (test, what) in VALUES.items():
        value = _number(attrs.get(name))
        if value is not None and not test(value, attrs):
            problems.append(f"/@{name}: {value:g}, not {what}")
    for small, large in ORDERED:
        a, b = _number(attrs.get(small)), _number(attrs.get(large))
        if a is not None and b is not None and a > b and not math.isclose(a, b, rel_tol=1e-9):
            problems.append(f"/@{small}: {a:g} exceeds {large} {b:g}")
    reached, end = _number(attrs.get("time_reached")), _number(attrs.get("end_time"))
    if status in ("completed", "lost") and reached is not None and end is not None and \
            not math.isclose(reached, end, rel_tol=1e-9, abs_tol=1e-12):
        problems.append(f"/@time_reached: {reached:g} on a {status} run, not its end_time {end:g}")
    check_configuration(f, problems)


def check_particles(f, problems):
    if "particles" not in f:
        problems.append("/particles: missing")
        return
    group = f["particles"]
    n = int(f.attrs["particle_count"]) if _kind_of(f.attrs.get("particle_count")) == "int" else None
    for name, tail in {**PARTICLES, **{k: v for k, v in PARTICLES_OPTIONAL.items() if k in group}}.items():
        if name not in group:
            problems.append(f"/particles/{name}: missing")
            continue
        shape = group[name].shape
        rows = shape[0] if shape else None
        if group[name].dtype.kind not in "fiu":
            problems.append(f"/particles/{name}: {group[name].dtype} values, the format has numbers")
        if tuple(shape[1:]) != tail or (n is not None and rows != n):
            want = " x ".join(["N" if n is None else str(n)] + [str(d) for d in tail])
            problems.append(f"/particles/{name}: shape {' x '.join(map(str, shape)) or 'scalar'}, the format has {want}")
    # A run that went on to its end time and is healthy has no particle inverted or lost (a failed run keeps the
    # state of the step that stopped it, whose health was judged at the output times before).
    if _text(f.attrs.get("status", "")) == "completed" and _text(f.attrs.get("health", "")) == "healthy":
        for name, test, what in (("J", lambda v: v > 0.0, "positive"), ("position", np.isfinite, "finite")):
            if name in group and isinstance(group[name], h5py.Dataset) and group[name].dtype.kind in "fiu" \
                    and group[name].ndim >= 1:
                values = np.asarray(group[name], float).reshape(group[name].shape[0], -1)
                bad = np.flatnonzero(~np.all(test(values) & np.isfinite(values), axis=1))
                if bad.size:
                    problems.append(f"/particles/{name}: {bad.size} particle(s) not {what} (particle {bad[0]}: "
                                    f"{values[bad[0]].tolist()}) in a completed run whose health is 'healthy'")


def time_problem(where, time, problems):
    """One rule for every `time` column (/errors, the monitors, coverage, each probe): increasing, from t >= 0."""
    time = np.asarray(time, float) if time.dtype.kind in "fiu" else None
    if time is None:
        problems.append(f"{where}: not numbers")
    elif np.any(np.diff(time) <= 0):
        problems.append(f"{where}: not increasing")
    elif time.size and not time[0] >= 0.0:
        problems.append(f"{where}: starts at {time[0]:g}, before t = 0")


def check_table(f, path, problems, required=()):
    """A group of equal-length columns with an increasing `time`."""
    if path not in f:
        problems.append(f"/{path}: missing")
        return None
    group = f[path]
    if "time" not in group:
        problems.append(f"/{path}/time: missing")
        return None
    time = np.asarray(group["time"])
    if time.ndim != 1:
        problems.append(f"/{path}/time: {time.ndim} dimensions, the format has 1")
        return None
    time_problem(f"/{path}/time", time, problems)
    if time.dtype.kind not in "fiu":
        return None
    for name in required:
        if name not in group:
            problems.append(f"/{path}/{name}: missing")
    for name, item in group.items():
        if isinstance(item, h5py.Dataset) and item.dtype.kind not in "fiu":
            problems.append(f"/{path}/{name}: {item.dtype} values, the format has numbers")
        elif isinstance(item, h5py.Dataset) and item.shape[:1] != time.shape:
            problems.append(f"/{path}/{name}: {item.shape[0] if item.shape else 'scalar'} rows, /{path}/time "
                            f"has {time.shape[0]}")
    return time


def check_monitor_values(monitors, problems):
    """The MONITORS rules, row by row; the first row that breaks one is named."""
    if not isinstance(monitors, h5py.Group) or "time" not in monitors:
        return
    time = monitors["time"]
    for rule, (test, what) in MONITORS.items():
        names = rule.split(" <= ")
        if not all(n in monitors and isinstance(monitors[n], h5py.Dataset) and monitors[n].dtype.kind in "fiu"
                   and monitors[n].shape == time.shape for n in names):
            continue   # missing or of the wrong length: check_table names it
        columns = [np.asarray(monitors[n], float) for n in names]
        bad = np.flatnonzero(~test(*columns))
        if bad.size:
            problems.append(f"/probes/monitors/{names[0]}: {columns[0][bad[0]]:g} at t = {time[bad[0]]:g}, "
                            f"not {what}")


def check_probes(f, problems):
    if "probes" not in f:
        problems.append("/probes: missing")
        return
    # An external program's run has no monitors: mpmvv does not see its energies (/external).
    if "external" not in f:
        check_table(f, "probes/monitors", problems, required=("kinetic_energy", "strain_energy", "energy_created",
                                                              "min_J", "max_J"))
        check_monitor_values(f["probes"].get("monitors"), problems)
    for name in ("contact_pressure", "history"):
        if isinstance(f["probes"].get(name), h5py.Group) and "time" in f["probes"][name]:
            time_problem(f"/probes/{name}/time", np.asarray(f["probes"][name]["time"]), problems)
    if "coverage" in f["probes"]:
        check_table(f, "probes/coverage", problems, required=("uncovered_fraction", "inside_fraction",
                                                              "largest_hole_area", "largest_hole_cells"))
    for name, group in f["probes"].items():
        # The scene groups without a quantity the format documents.
        if name in ("monitors", "coverage", "contact_pressure", "history", "axis_stress") or \
                not isinstance(group, h5py.Group):
            continue
        where = f"/probes/{name}"
        quantity = _text(group.attrs.get("quantity", ""))
        if quantity not in QUANTITIES:
            problems.append(f"{where}/@quantity: '{quantity}' is none of {', '.join(QUANTITIES)}")
            continue
        for dataset in ("time", quantity, f"exact_{quantity}"):
            if dataset not in group:
                problems.append(f"{where}/{dataset}: missing")
        if any(d not in group for d in ("time", quantity, f"exact_{quantity}")):
            continue
        time_problem(f"{where}/time", np.asarray(group["time"]), problems)
        rows = group["time"].shape[0]
        shape = group[quantity].shape
        if shape != group[f"exact_{quantity}"].shape:
            problems.append(f"{where}/exact_{quantity}: shape {shape and group[f'exact_{quantity}'].shape}, "
                            f"{quantity} has {shape}")
        if shape[:1] != (rows,):
            problems.append(f"{where}/{quantity}: {shape[0] if shape else 'no'} rows, its time has {rows}")


def check_errors(f, problems):
    time = check_table(f, "errors", problems)
    if time is None:
        return
    # Values as well as layout: numbers stored as numbers, one per output
    # time, and each a norm's (consistency.norm_problems: finite and >= 0; NaN
    # only where nothing was measured).
    healthy = _text(f.attrs.get("status", "")) == "completed" and _text(f.attrs.get("health", "")) != "solution lost"
    for name, item in f["errors"].items():
        if not isinstance(item, h5py.Dataset):
            problems.append(f"/errors/{name}: a group, the format has a column")
        elif item.dtype.kind not in "fiu":
            continue   # check_table names it
        elif item.ndim != 1:
            problems.append(f"/errors/{name}: {item.ndim} dimensions, the format has 1")
        elif name == "time":
            if not np.all(np.isfinite(time)):
                problems.append("/errors/time: not finite")
        elif item.shape == time.shape:
            problem = norm_problems(name, time, np.asarray(item, float), healthy)
            if problem:
                problems.append(problem)
    if _text(f.attrs.get("status", "")) == "completed" and time.size and "end_time" in f.attrs:
        end = float(f.attrs["end_time"])
        if not math.isclose(float(time[-1]), end, rel_tol=1e-9, abs_tol=1e-12):
            problems.append(f"/errors/time: a completed run's last output time {time[-1]:g} is not end_time {end:g}")


def check_external(f, problems):
    """An external program's run (reports/external-format.md): what ran and how it ended."""
    if "external" not in f:
        return
    group = f["external"]
    for name in ("command", "command_template", "format", "ended", "exit_status", "fields", "J_rule"):
        if name not in group.attrs:
            problems.append(f"/external/@{name}: missing")
    # Files ingested before output_spacing was written lack it: the floor then counts doubles.
    spacing = group.attrs.get("output_spacing")
    if spacing is not None and not (isinstance(spacing, (float, np.floating)) and 0.0 <= spacing < 1.0):
        problems.append(f"/external/@output_spacing: {spacing!r} is not a relative spacing in [0, 1)")
    if "output_time" not in group:
        problems.append("/external/output_time: missing")
    elif "errors" in f and "time" in f["errors"] and group["output_time"].shape != f["errors"]["time"].shape:
        problems.append(f"/external/output_time: {group['output_time'].shape[0]} rows, /errors/time has "
                        f"{f['errors']['time'].shape[0]}")


def check_file(path):
    """The problems of one results file (empty when it follows the format); raises OSError if unreadable."""
    problems = []
    # A FIFO would block the reader, a device or directory is no file.
    if not stat.S_ISREG(os.stat(path).st_mode):
        raise OSError(f"{path} is not a regular file")
    with h5py.File(path, "r") as f:
        check_root(f, problems)
        check_particles(f, problems)
        check_errors(f, problems)
        check_probes(f, problems)
        check_external(f, problems)
    # One message an item: the first rule it breaks (a rule that follows from it says the same again).
    first = {}
    for problem in problems:
        first.setdefault(problem.split(" ", 1)[0].rstrip(":"), problem)
    return list(first.values())


class _OneLineParser(argparse.ArgumentParser):
    def error(self, message):
        self.exit(2, f"mpmvv results check: {message} (see --help)\n")


def main(argv):
    parser = _OneLineParser(prog="mpmvv results check", description=__doc__.split("\n\n")[0],
                            epilog="Exit 0: every file follows the format; 1: some item is missing or malformed; "
                                   "2: a file is not a readable HDF5 file.")
    parser.add_argument("files", metavar="FILE", nargs="+", help="a results file (mpmvv run ... -o FILE)")
    args = parser.parse_args(argv)
    worst = 0
    for path in args.files:
        try:
            problems = check_file(path)
        except (OSError, KeyError) as error:
            print(f"mpmvv results check: {path}: not a readable HDF5 results file ({error})", file=sys.stderr)
            return 2
        if problems:
            worst = 1
            print(f"{path}: {len(problems)} item(s) missing or malformed")
            for p in problems:
                print(f"  {p}")
        else:
            print(f"{path}: follows the results format")
    return worst


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
