"""cmake --install gives a tree that works on its own: installed under one
prefix and moved to another, the binary finds its reports package and the
shipped suites under its own prefix (`mpmvv paths`), runs a scene from the
installed scene files, and its gate and report read a suite directory (a copy
of reports/gold). The installed package holds no test and no gold directory.

    /usr/bin/python3 tests/installed_tree.py CMAKE BUILD_DIR   (ctest runs it; exit 1 names what failed)
"""
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

CMAKE, BUILD = sys.argv[1], Path(sys.argv[2])
SOURCE = Path(__file__).resolve().parents[1]
failures = []


def check(condition, what):
    if not condition:
        failures.append(what)


def run(*args, **kw):
    return subprocess.run([str(a) for a in args], capture_output=True, text=True, **kw)


with tempfile.TemporaryDirectory() as tmp:
    tmp = Path(tmp)
    done = run(CMAKE, "--install", BUILD, "--prefix", tmp / "first")
    if done.returncode != 0:
        sys.exit(f"cmake --install failed: {done.stderr}")
    prefix = tmp / "moved"
    shutil.move(tmp / "first", prefix)  # relocated: nothing may point at the first prefix
    mpmvv = prefix / "bin" / "mpmvv"
    data = prefix / "share" / "mpmvv"

    paths = run(mpmvv, "paths")
    lines = dict(line.split(None, 1) for line in paths.stdout.splitlines() if line.strip())
    check(paths.returncode == 0, f"mpmvv paths exited {paths.returncode}")
    for name, where in (("reports", data / "python" / "reports"), ("suites", data / "suites")):
        check(lines.get(name, "").startswith(f"{where} (installed)"),
              f"mpmvv paths: {name} is {lines.get(name)!r}, not {where} (installed)")

    package = data / "python" / "reports"
    stray = sorted(p.name for p in package.rglob("*") if p.name.startswith("test_") or p.name in ("conftest.py", "gold"))
    check(not stray, f"the installed package holds {stray}")
    check((package / "results-format.md").is_file(), "the installed package lacks results-format.md")

    scene = data / "suites" / "scenes" / "ring.toml"
    out = tmp / "ring.h5"
    ran = run(mpmvv, "run", scene, "--set", "cells=32", "--set", "end_time=0.05", "--threads", "1", "--quiet",
              "-o", out, cwd=tmp)
    check(ran.returncode == 0 and out.is_file(), f"mpmvv run of the installed ring scene: {ran.returncode} {ran.stderr}")

    suite = tmp / "gold"
    shutil.copytree(SOURCE / "reports" / "gold", suite)
    gate = run(mpmvv, "gate", suite, cwd=tmp)
    check("expectations" in gate.stdout and gate.returncode in (0, 1),
          f"mpmvv gate on the gold directory: exit {gate.returncode} {gate.stderr[-400:]}")
    report = run(mpmvv, "report", suite, "-o", tmp / "report", cwd=tmp)
    check(report.returncode == 0 and (tmp / "report" / "report.html").is_file(),
          f"mpmvv report on the gold directory: exit {report.returncode} {report.stderr[-400:]}")

for f in failures:
    print("FAIL", f)
sys.exit(1 if failures else 0)
