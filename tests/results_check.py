"""`mpmvv results check` passes what `mpmvv run` writes and names each item a
damaged copy misses or gets wrong: a root attribute removed, a status no run
writes, a failure reason on a completed run, a /particles table of the wrong
shape, an /errors column shorter than its time, a probe without its quantity,
and (DAMAGE) one line for each value the format rules out: times before 0 or
not increasing, a time reached off its end time, attributes that disagree
with `configuration` or are not TOML, h off domain / cells, an inverted or
lost particle in a healthy run, steps and wall times out of range, monitors
out of order, overrides naming no key; exit 2 with one line for a file that
is not HDF5.

    /usr/bin/python3 tests/results_check.py MPMVV   (ctest runs it; exit 1 names what failed)
"""
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import h5py

MPMVV = sys.argv[1]
SOURCE = Path(__file__).resolve().parents[1]
failures = []


def check(condition, what):
    if not condition:
        failures.append(what)


def results_check(path):
    return subprocess.run([MPMVV, "results", "check", str(path)], capture_output=True, text=True)


with tempfile.TemporaryDirectory() as tmp:
    tmp = Path(tmp)
    good = tmp / "ring.h5"
    ran = subprocess.run([MPMVV, "run", SOURCE / "suites" / "scenes" / "ring.toml", "--set", "cells=32", "--set",
                          "end_time=0.05", "--set", "output_times=[0.02, 0.035]", "--threads", "1", "--quiet",
                          "-o", good], capture_output=True, text=True)
    if ran.returncode != 0:
        sys.exit(f"mpmvv run: {ran.stderr}")
    done = results_check(good)
    check(done.returncode == 0 and "follows the results format" in done.stdout,
          f"a file mpmvv run wrote: exit {done.returncode}: {done.stdout}{done.stderr}")

    bad = tmp / "damaged.h5"
    shutil.copy(good, bad)
    with h5py.File(bad, "r+") as f:
        del f.attrs["version"]
        f.attrs["status"] = "finished"
        f.attrs["failure_reason"] = "nan"
        position = f["particles/position"][...]
        del f["particles/position"]
        f["particles/position"] = position[:-1]
        column = f["errors/particle_L2"][...]
        del f["errors/particle_L2"]
        f["errors/particle_L2"] = column[:-1] if column.size > 1 else []
        del f["probes/theta0"].attrs["quantity"]
    done = results_check(bad)
    check(done.returncode == 1, f"a damaged file: exit {done.returncode}, not 1")
    for item in ("/@version: missing", "/@status: 'finished' is none of", "/particles/position: shape",
                 "/errors/particle_L2:", "/probes/theta0/@quantity:"):
        check(item in done.stdout, f"a damaged file: '{item}' not named in:\n{done.stdout}")
    shutil.copy(good, bad)
    with h5py.File(bad, "r+") as f:
        f.attrs["failure_reason"] = "nan"
    done = results_check(bad)
    check(done.returncode == 1 and "/@failure_reason: 'nan' on a completed run" in done.stdout,
          f"a completed run with a failure reason: {done.stdout}")

    # Values the format rules out, one damage a copy: each is exit 1 and one line naming the item and its value.
    def put(group, name, data):
        del group[name]
        group[name] = data

    def attribute(name, value):
        return lambda f: f.attrs.__setitem__(name, value)

    with h5py.File(good, "r") as f:
        times, n = list(f["errors/time"][...]), f["particles/J"].shape[0]   # 0.02, 0.035, 0.05
    rows = len(times)
    DAMAGE = {   # what is done -> what the one line must say
        "errors time negative": (lambda f: put(f["errors"], "time", [-t for t in times[:1]] + times[1:]),
                                 "/errors/time: starts at -0.02, before t = 0"),
        "probe time decreasing": (lambda f: put(f["probes/theta0"], "time", times[::-1]),
                                  "/probes/theta0/time: not increasing"),
        "time_reached short of end_time": (attribute("time_reached", 0.01),
                                           "/@time_reached: 0.01 on a completed run, not its end_time 0.05"),
        "time_reached past end_time": (attribute("time_reached", 9.0), "/@time_reached: 9 exceeds end_time 0.05"),
        "time_reached negative": (attribute("time_reached", -1.0), "/@time_reached: -1, not finite and >= 0"),
        "cells negative": (attribute("cells", -5), "/@cells: -5, the configuration has cells = 32"),
        "cells not the configuration's": (attribute("cells", 24), "/@cells: 24, the configuration has cells = 32"),
        "configuration not TOML": (attribute("configuration", "[[[ not toml"), "/@configuration: not TOML"),
        "scene not the configuration's": (attribute("scene", "nope"),
                                          "/@scene: 'nope' (text), the configuration has scene = 'ring'"),
        "method not the configuration's": (attribute("method", "nope"), "/@method: 'nope' (text), the configuration"),
        "h not domain / cells": (attribute("h", 7.0), "/@h: 7, not domain / cells = 3 / 32"),
        "J negative in a healthy run": (lambda f: put(f["particles"], "J", [-1.0] * n), "/particles/J: "),
        "J NaN in a healthy run": (lambda f: put(f["particles"], "J", [float("nan")] * n), "/particles/J: "),
        "position NaN in a healthy run": (lambda f: put(f["particles"], "position", [[float("nan")] * 2] * n),
                                          "/particles/position: "),
        "completed with its solution lost": (attribute("health", "solution lost"),
                                             "/@status: 'completed' with health 'solution lost'"),
        "dt zero": (attribute("dt", 0.0), "/@dt: 0, not positive and finite"),
        "dt_min past dt_max": (attribute("dt_min", 1.0), "/@dt_min: 1 exceeds dt_max"),
        "wall time negative": (attribute("wall_time_s", -3.0), "/@wall_time_s: -3, not finite and >= 0"),
        "energy_scale negative": (lambda f: put(f["probes/monitors"], "energy_scale", [-1.0] * rows),
                                  "/probes/monitors/energy_scale: -1 at t ="),
        "min_J past max_J": (lambda f: put(f["probes/monitors"], "min_J", [1e9] * rows),
                             "/probes/monitors/min_J: 1e+09 at t ="),
        "overrides naming no key": (attribute("overrides", "nokey=1"), "/@overrides: 'nokey=1' is not key=value"),
        "output_times as text": (attribute("output_times", "0.05"), "/@output_times: '0.05' (text), the configuration"),
    }
    for what, (damage, said) in DAMAGE.items():
        shutil.copy(good, bad)
        with h5py.File(bad, "r+") as f:
            damage(f)
        done = results_check(bad)
        lines = done.stdout.splitlines()[1:]
        check(done.returncode == 1 and len(lines) == 1 and said in lines[0],
              f"{what}: exit {done.returncode}, not one line with '{said}':\n{done.stdout}{done.stderr}")

    text = tmp / "not.h5"
    text.write_text("not HDF5\n")
    done = results_check(text)
    check(done.returncode == 2 and done.stderr.count("\n") == 1 and "not.h5" in done.stderr,
          f"a file that is not HDF5: exit {done.returncode}, {done.stderr!r}")

for f in failures:
    print("FAIL", f)
sys.exit(1 if failures else 0)
