"""`mpmvv results check` passes what `mpmvv run` writes and names each item a
damaged copy misses or gets wrong: a root attribute removed, a status no run
writes, a failure reason on a completed run, a /particles table of the wrong
shape, an /errors column shorter than its time, a probe without its quantity;
exit 2 with one line for a file that is not HDF5.

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
                          "end_time=0.05", "--threads", "1", "--quiet", "-o", good], capture_output=True, text=True)
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

    text = tmp / "not.h5"
    text.write_text("not HDF5\n")
    done = results_check(text)
    check(done.returncode == 2 and done.stderr.count("\n") == 1 and "not.h5" in done.stderr,
          f"a file that is not HDF5: exit {done.returncode}, {done.stderr!r}")

for f in failures:
    print("FAIL", f)
sys.exit(1 if failures else 0)
