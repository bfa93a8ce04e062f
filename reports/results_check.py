"""Check a results file against its documented format (reports/results-format.md):
`mpmvv results check FILE`. Every missing or malformed item is named by its
path in the file, one per line; exit 0 when there is none, 1 when there are,
2 (one line) when FILE is not a readable HDF5 file.

What is checked is what the report and the gate read: the root attributes a
run writes whatever its scene (their types and allowed values, and that
status, failure and health agree), /particles (one row per particle, the
shapes of the table), /errors (a `time` column, increasing, and every column
as long, numbers, each value a norm's: finite and >= 0), /probes/monitors and /probes/coverage likewise, each probe group's `quantity` and the
shape of its values against its `time` and points. A file an external code's
run was ingested into is held to the same rules.

Usage: mpmvv results check FILE [FILE ...]
"""
import argparse
import math
import os
import stat
import sys

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
    "wall_time_s": "real", "h": "real", "end_time": "real", "cells": "int",
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


def check_root(f, problems):
    attrs = f.attrs
    for name, kind in ROOT.items():
        if name not in attrs:
            problems.append(f"/@{name}: missing ({kind})")
            continue
        found = _kind_of(attrs[name])
        # An integer where a real is documented holds the value exactly.
        if found != kind and not (kind == "real" and found == "int"):
            problems.append(f"/@{name}: {found}, the format has {kind}")
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
    for name in ("particle_count", "steps", "particle_steps", "threads"):
        if name in attrs and _kind_of(attrs[name]) == "int" and attrs[name] < 0:
            problems.append(f"/@{name}: negative ({attrs[name]})")
    if "h" in attrs and not (float(attrs["h"]) > 0.0):
        problems.append(f"/@h: {attrs['h']}, not a positive cell size")


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
        if tuple(shape[1:]) != tail or (n is not None and rows != n):
            want = " x ".join(["N" if n is None else str(n)] + [str(d) for d in tail])
            problems.append(f"/particles/{name}: shape {' x '.join(map(str, shape)) or 'scalar'}, the format has {want}")


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
    if np.any(np.diff(time) <= 0):
        problems.append(f"/{path}/time: not increasing")
    for name in required:
        if name not in group:
            problems.append(f"/{path}/{name}: missing")
    for name, item in group.items():
        if isinstance(item, h5py.Dataset) and item.shape[:1] != time.shape:
            problems.append(f"/{path}/{name}: {item.shape[0] if item.shape else 'scalar'} rows, /{path}/time "
                            f"has {time.shape[0]}")
    return time


def check_probes(f, problems):
    if "probes" not in f:
        problems.append("/probes: missing")
        return
    # An external program's run has no monitors: mpmvv does not see its energies (/external).
    if "external" not in f:
        check_table(f, "probes/monitors", problems, required=("kinetic_energy", "strain_energy", "energy_created",
                                                              "min_J", "max_J"))
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
            problems.append(f"/errors/{name}: {item.dtype} values, the format has numbers")
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
    return problems


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
