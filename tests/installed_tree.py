"""cmake --install gives a tree that works on its own: installed under one
prefix and moved to another, the binary finds its reports package and the
shipped suites under its own prefix (`mpmvv paths`), runs a scene from the
installed scene files, runs a small suite whose gate must hold (and one
whose gate must fall short), and its report reads a suite directory (a copy
of reports/gold). The installed package holds no test and no gold directory.
Programs outside the tree (tests/installed/: C, C++ through find_package,
Fortran through iso_c_binding, and Python through `import mpmvv`) evaluate the
ring's body force with the installed library: the same bits in every language,
and the force `mpmvv mms eval` gives to round-off.

    /usr/bin/python3 tests/installed_tree.py CMAKE BUILD_DIR   (ctest runs it; exit 1 names what failed)
"""
import json
import math
import os
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

    # A small suite on the installed scene files, run and gated by the
    # installed tree: the gate must give the verdict the numbers call for,
    # all hold for an order the axis-aligned problem reaches (1.75, 1.97 on
    # 8-16-32 cells), one short for an order it does not.
    for name, order, verdict, status in (("holds", 2.0, "all 1 expectations hold", 0),
                                         ("falls-short", 4.0, "1 of 1 expectations fell short", 1)):
        small = tmp / f"{name}.toml"
        small.write_text(f'[[study]]\nname = "axis"\nscene = "{data / "suites" / "scenes" / "axis-aligned.toml"}"\n'
                         'set = { method = "cpdi" }\nsweep = { cells = [8, 16, 32] }\n'
                         f'[[expect]]\nstudy = "axis"\nnorm = "L1_line_y_mid"\ntime = 0.015\norder = {order}\n'
                         'tolerance = 0.3\n')
        ran = run(mpmvv, "suite", small, "-o", tmp / name, "-t", "1", "--quiet", cwd=tmp)
        check(ran.returncode == 0, f"mpmvv suite {small.name} with the installed tree: exit {ran.returncode} {ran.stderr[-400:]}")
        gate = run(mpmvv, "gate", tmp / name, cwd=tmp)
        check(gate.returncode == status and verdict in gate.stdout,
              f"mpmvv gate on {name}: exit {gate.returncode}, not {status} with '{verdict}': {gate.stdout[-400:]} "
              f"{gate.stderr[-400:]}")

    # The report renders the stored gold directory. Its results files are not
    # stored, so the report is written and says, first and by its exit status
    # (1), that the cases the manifest calls completed have none.
    suite = tmp / "gold"
    shutil.copytree(SOURCE / "reports" / "gold", suite)
    report = run(mpmvv, "report", suite, "-o", tmp / "report", cwd=tmp)
    check(report.returncode == 1 and (tmp / "report" / "report.html").is_file() and
          "the manifest says completed, and it has no results file" in report.stderr,
          f"mpmvv report on the gold directory: exit {report.returncode} {report.stderr[-400:]}")

    # The manufactured solutions from other languages (tests/installed/).
    here = SOURCE / "tests" / "installed"
    library = ["-I", prefix / "include", "-L", prefix / "lib", "-lmpmvv-mms", f"-Wl,-rpath,{prefix / 'lib'}"]
    outputs = {}

    def program(language, builds, command, env=None):
        for build in builds:
            made = run(*build, cwd=tmp)
            if made.returncode != 0:
                failures.append(f"{language}: the build failed: {made.stdout[-300:]} {made.stderr[-600:]}")
                return
        done = run(*command, cwd=tmp, env=env)
        check(done.returncode == 0, f"{language}: exit {done.returncode} {done.stderr[-300:]}")
        outputs[language] = done.stdout

    program("C", [["cc", "-std=c11", "-O2", here / "ring.c", *library, "-lm", "-o", tmp / "ring-c"]],
            [tmp / "ring-c", "100000"])
    program("C++", [[CMAKE, "-S", here, "-B", tmp / "cxx", f"-DCMAKE_PREFIX_PATH={prefix}"],
                    [CMAKE, "--build", tmp / "cxx"]], [tmp / "cxx" / "ring", "100000"])
    if shutil.which("gfortran"):
        program("Fortran", [["gfortran", "-O2", here / "ring.f90", *library, "-o", tmp / "ring-f"]], [tmp / "ring-f"])
    else:
        print("SKIP Fortran: gfortran is not installed (tools/install-deps installs it)")
    script = ("import numpy as np, mpmvv\n"
              "X = np.array([[1.0, 0.0], [0.8, 0.5], [-0.3, -0.9]])\n"
              "b = mpmvv.Solution('ring', amplitude=0.5).body_force(X, 0.25)\n"
              "for x, f in zip(X, b): print('b', *(repr(float(v)) for v in (*x, *f)))\n"
              "try:\n    mpmvv.Solution('ring', nonsense=1)\nexcept ValueError as e:\n    print('error', e)\n")
    program("Python", [], [sys.executable, "-c", script],
            env=dict(os.environ, PYTHONPATH=str(prefix / "lib" / "python3" / "dist-packages")))
    # A refused setting is named as the library's caller gave it, not as the command line's --set.
    errors = [line for line in outputs.get("Python", "").splitlines() if line.startswith("error ")]
    check(len(errors) == 1 and errors[0].startswith("error setting nonsense=1: ") and "--set" not in errors[0],
          f"the library's message for an unknown key: {errors}")
    forces = {}
    for language, text in outputs.items():
        rows = [line.split()[1:] for line in text.splitlines() if line.startswith("b ")]
        forces[language] = [tuple(float(v) for v in row) for row in rows]
        check(len(rows) == 3, f"{language}: {len(rows)} points printed, not 3")
        if language in ("C", "C++"):
            check("status 0" in text and "points 100000" in text, f"{language}: the 10^5 points were not evaluated")
    reference = forces.get("C")
    for language, values in forces.items():
        check(values == reference, f"{language} gives {values}, C {reference}: not the same bits")
    for X, Y, bx, by in reference or []:
        evaluated = run(mpmvv, "mms", "eval", "ring", "--at", f"{X!r},{Y!r}", "--time", "0.25", "--set",
                        "amplitude=0.5", "--json")
        b = json.loads(evaluated.stdout)["body_force"]
        scale = math.hypot(*b)
        check(math.hypot(bx - b[0], by - b[1]) <= 1e-13 * scale,
              f"at ({X}, {Y}) the library gives ({bx}, {by}), mpmvv mms eval ({b[0]}, {b[1]})")

for language, values in forces.items():
    print(f"{language}: b at the three points {values and [v[2:] for v in values]}")
for f in failures:
    print("FAIL", f)
sys.exit(1 if failures else 0)
