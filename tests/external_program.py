"""An external program run in place of mpmvv's solver (external_command,
reports/external-format.md):

- mpmvv itself as the external program (HDF5): the ingested /errors equal
  those of the direct run bit for bit, status and health too;
- a small independent program, written here, that puts its own particles
  (not mpmvv's seeding: another count, unequal volumes) at the exact motion
  of the user-motion scene plus a known offset, at its own times near the
  output times (CSV): every displacement norm and the probe lines read the
  offset, the velocity norm the velocity's offset, and no stress or F norm is
  made from fields it did not write; moved by a quadratic motion of its own
  and writing no tracers, the probe lines mpmvv measures from tracers it
  places from the particles equal those of the tracers written;
- what goes wrong is named: a program that exits 3 (failed, its last line
  quoted, the outputs it wrote kept), one that writes no output, a malformed
  CSV (file and line), an unknown {name} (refused before anything runs), a
  time-out, a scene an external program cannot be measured on.

    /usr/bin/python3 tests/external_program.py MPMVV   (ctest runs it; exit 1 names what failed)
"""
import json
import math
import subprocess
import sys
import tempfile
from pathlib import Path

import h5py
import numpy as np

MPMVV = sys.argv[1]
SOURCE = Path(__file__).resolve().parents[1]
RING = SOURCE / "suites" / "scenes" / "ring.toml"
USER = SOURCE / "suites" / "scenes" / "user-motion.toml"
failures = []


def check(condition, what):
    if not condition:
        failures.append(what)


def run(scene, *sets, output, timeout=120):
    args = [MPMVV, "run", str(scene), "--threads", "1", "--quiet", "-o", str(output)]
    for s in sets:
        args += ["--set", s]
    return subprocess.run(args, capture_output=True, text=True, timeout=timeout)


# The independent program: the user-motion scene's default motion (its scene
# file's formulas), u_x = A sin(pi X / L) sin(c pi t / L),
# u_y = A sin(pi Y / L) sin(pi (2/3 + c t / L)), A = 0.05, c = 100, L = 1, on a
# 1 x 1 body; particles on a 37 x 23 lattice with unequal volumes; positions
# the exact ones plus OFFSET, velocities the exact ones plus VELOCITY_OFFSET,
# written at the output time plus 1e-6 s (a code with a fixed step), and the
# tracers followed the same way.
OFFSET = (3e-4, -4e-4)
VELOCITY_OFFSET = (0.1, 0.0)
PROGRAM = r'''
import json, math, os, sys
inp = json.load(open(sys.argv[1]))
mode = sys.argv[2] if len(sys.argv) > 2 else "good"
A, c, L = 0.05, 100.0, 1.0
def u(X, Y, t):
    if mode.startswith("quadratic"):  # the motion with sin(pi s) as 4 s (1 - s): a quadratic fit reproduces it
        return (A * 4.0 * X * (1.0 - X) * math.sin(c * math.pi * t / L),
                A * 4.0 * Y * (1.0 - Y) * math.sin(math.pi * (2.0 / 3.0 + c * t / L)))
    return (A * math.sin(math.pi * X / L) * math.sin(c * math.pi * t / L),
            A * math.sin(math.pi * Y / L) * math.sin(math.pi * (2.0 / 3.0 + c * t / L)))
def v(X, Y, t):
    return (A * math.sin(math.pi * X / L) * math.cos(c * math.pi * t / L) * c * math.pi / L,
            A * math.sin(math.pi * Y / L) * math.cos(math.pi * (2.0 / 3.0 + c * t / L)) * c * math.pi / L)
nx, ny = 37, 23
xs = [(i + 0.5) / nx for i in range(nx)]
ys = [(j + 0.5) / ny for j in range(ny)]
os.makedirs(inp["output"], exist_ok=True)
for k, t_out in enumerate(inp["output_times"]):
    if mode == "fail" and k == 2:
        print("the toy code gave up at output", k); sys.exit(3)
    if mode == "silent":
        break
    t = t_out + 1e-6
    with open(os.path.join(inp["output"], "particles_%d.csv" % k), "w") as f:
        f.write("# time = %.17g\n" % t)
        f.write("X,Y,x,y,V0,vx,vy\n" if mode != "ragged" else "X,Y,x,y,V0,vx\n")
        for j, Y in enumerate(ys):
            for i, X in enumerate(xs):
                V0 = (1.0 + 0.5 * ((i + j) % 3)) / (nx * ny)
                ux, uy = u(X, Y, t)
                vx, vy = v(X, Y, t)
                f.write("%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n" % (
                    X, Y, X + ux + OX, Y + uy + OY, V0, vx + VOX, vy + VOY))
    if mode.endswith("notracers"):
        continue
    with open(os.path.join(inp["output"], "tracers_%d.csv" % k), "w") as f:
        f.write("x,y\n")
        for X, Y in inp["tracer_reference"]:
            ux, uy = u(X, Y, t)
            f.write("%.17g,%.17g\n" % (X + ux + OX, Y + uy + OY))
'''
for name, value in (("VOX", VELOCITY_OFFSET[0]), ("VOY", VELOCITY_OFFSET[1]), ("OX", OFFSET[0]), ("OY", OFFSET[1])):
    PROGRAM = PROGRAM.replace(name, repr(value))

with tempfile.TemporaryDirectory() as tmp:
    tmp = Path(tmp)

    # mpmvv as the external program: the same bits.
    common = ["cells=32", "end_time=0.3", "output_times=[0.1, 0.2]"]
    direct = run(RING, *common, output=tmp / "direct.h5")
    own = run(RING, *common, "external_command={mpmvv} run {scene} --set particle_fields=outputs --threads 1 "
              "--quiet -o {output}", output=tmp / "own.h5")
    check(direct.returncode == 0 and own.returncode == 0,
          f"ring directly and through mpmvv as an external program: exit {direct.returncode}, {own.returncode}: "
          f"{own.stdout}{own.stderr}")
    check("(external program): completed t = 0.3 s" in own.stdout, f"the external run's line: {own.stdout}")
    with h5py.File(tmp / "direct.h5") as a, h5py.File(tmp / "own.h5") as b:
        check(list(a["errors"]) == list(b["errors"]), f"columns {list(a['errors'])} against {list(b['errors'])}")
        for name in a["errors"]:
            check(name in b["errors"] and np.array_equal(a["errors"][name][()], b["errors"][name][()]),
                  f"/errors/{name}: the ingested values differ from the direct run's")
        for attribute in ("status", "health"):
            check(a.attrs[attribute] == b.attrs[attribute], f"{attribute}: {a.attrs[attribute]} against {b.attrs[attribute]}")
        check(b["external"].attrs["ended"] == "exit status 0", f"/external ended: {b['external'].attrs['ended']}")
        check(b["external"].attrs["J_rule"] == "applied", "the J rule is applied with F given")
    inp = json.loads((tmp / "own.input.json").read_text())
    check(inp["output_times"] == [0.1, 0.2, 0.3] and inp["keys"]["cells"] == 32 and inp["keys"]["external_command"] == ""
          and len(inp["tracer_reference"]) == len(inp["tracer_start"]) > 0,
          f"the input file: {sorted(inp)}")

    # The independent program, in CSV.
    program = tmp / "toy_code.py"
    program.write_text(PROGRAM)
    user = ["cells=16", "end_time=0.02", "external_format=csv"]
    toy = run(USER, *user, f"external_command=/usr/bin/python3 {program} {{input}}", output=tmp / "toy.h5")
    check(toy.returncode == 0, f"the independent program: exit {toy.returncode}: {toy.stdout}{toy.stderr}")
    offset = math.hypot(*OFFSET)
    if toy.returncode == 0:
        with h5py.File(tmp / "toy.h5") as f:
            e = f["errors"]
            columns = list(e)
            check("particle_pressure_L2" not in columns and "particle_deformation_L2" not in columns,
                  f"norms of fields the program did not write: {columns}")
            for name in ("particle_L1", "particle_L2", "particle_Linf"):
                check(np.allclose(e[name][()], offset, rtol=1e-9, atol=0), f"{name} = {e[name][()]}, the offset {offset}")
            check(np.allclose(e["particle_velocity_L2"][()], math.hypot(*VELOCITY_OFFSET), rtol=1e-6),
                  f"particle_velocity_L2 = {e['particle_velocity_L2'][()]}")
            lines = [n for n in columns if n.startswith("L1_")]
            check(len(lines) >= 1, f"no probe line from the tracers: {columns}")
            for name in lines:
                quantity = f["probes"][name[3:]].attrs["quantity"]
                expected = {"displacement_x": abs(OFFSET[0]), "displacement_y": abs(OFFSET[1])}.get(quantity)
                check(expected is not None and np.allclose(e[name][()], expected, rtol=1e-8),
                      f"{name} ({quantity}) = {e[name][()]}, expected {expected}")
            check(f.attrs["status"] == "completed" and f.attrs["health"] == "healthy",
                  f"status {f.attrs['status']}, health {f.attrs['health']}")
            check(f["external"].attrs["J_rule"].startswith("not applied"), "no F, J or volume: the J rule is not applied")
            check(np.allclose(f["external"]["output_time"][()] - e["time"][()], 1e-6), "the program's own times kept")
            check(f.attrs["particle_count"] == 37 * 23, f"particle_count {f.attrs['particle_count']}")

    # A program that follows no tracers: mpmvv places them from its particles
    # (tracer_interpolation.hpp), exactly for a quadratic motion, so the probe
    # lines read what the program's own tracers give.
    written = run(USER, *user, f"external_command=/usr/bin/python3 {program} {{input}} quadratic",
                  output=tmp / "written.h5")
    placed = run(USER, *user, f"external_command=/usr/bin/python3 {program} {{input}} quadratic-notracers",
                 output=tmp / "placed.h5")
    check(written.returncode == 0 and placed.returncode == 0,
          f"tracers written and placed: exit {written.returncode}, {placed.returncode}: {placed.stdout}{placed.stderr}")
    if written.returncode == 0 and placed.returncode == 0:
        with h5py.File(tmp / "written.h5") as a, h5py.File(tmp / "placed.h5") as b:
            lines = [n for n in a["errors"] if n.startswith("L1_")]
            check(lines and list(a["errors"]) == list(b["errors"]) and a.attrs["health"] == "healthy",
                  f"columns {list(a['errors'])} against {list(b['errors'])}")
            for name in lines:
                want, got = a["errors"][name][()], b["errors"][name][()]
                check(np.all(want > 1e-5) and np.allclose(got, want, rtol=1e-10, atol=1e-15),
                      f"/errors/{name}: placed {got}, written {want}")
            check(a["external"].attrs["tracers"] == "written by the program (tracer_position)"
                  and b["external"].attrs["tracers"].startswith("interpolated by mpmvv from the particles"),
                  f"/external tracers: {a['external'].attrs['tracers']!r}, {b['external'].attrs['tracers']!r}")
            check("tracer_position" not in b["external"].attrs["fields"], f"fields: {b['external'].attrs['fields']}")

    # Failures, each named, nothing computed lost.
    failed = run(USER, *user, f"external_command=/usr/bin/python3 {program} {{input}} fail", output=tmp / "fail.h5")
    check(failed.returncode == 1 and "external program failed" in failed.stdout and "exit status 3" in failed.stdout
          and "gave up at output 2" in failed.stdout, f"a program exiting 3: {failed.returncode}: {failed.stdout}")
    with h5py.File(tmp / "fail.h5") as f:
        check(f.attrs["status"] == "failed" and len(f["errors"]["time"]) == 2,
              f"the two outputs written before the failure are kept: {f.attrs['status']}, {len(f['errors']['time'])}")
    silent = run(USER, *user, f"external_command=/usr/bin/python3 {program} {{input}} silent", output=tmp / "silent.h5")
    check(silent.returncode == 1 and "missing output" in silent.stdout and "no output for t = 0.005 s" in silent.stdout,
          f"a program that writes nothing: {silent.stdout}")
    ragged = run(USER, *user, f"external_command=/usr/bin/python3 {program} {{input}} ragged", output=tmp / "ragged.h5")
    check(ragged.returncode == 1 and "malformed output" in ragged.stdout and "particles_0.csv:3: 7 values" in ragged.stdout,
          f"a row longer than its header: {ragged.stdout}")
    unknown = run(USER, *user, "external_command=prog {nonsense}", output=tmp / "unknown.h5")
    check(unknown.returncode == 2 and "external_command" in unknown.stderr and "{nonsense}" in unknown.stderr
          and not (tmp / "unknown.input.json").exists(), f"an unknown name: {unknown.returncode}: {unknown.stderr}")
    slow = run(USER, *user, "external_command=sleep 30", "external_timeout=1", output=tmp / "slow.h5")
    check(slow.returncode == 1 and "external_timeout" in slow.stdout, f"a time-out: {slow.stdout}")
    hertz = run(SOURCE / "suites" / "scenes" / "hertz-cylinder.toml", "external_command=true", output=tmp / "hertz.h5")
    check(hertz.returncode == 2 and "has no exact motion" in hertz.stderr, f"a scene without an exact motion: {hertz.stderr}")

for f in failures:
    print("FAILED:", f)
sys.exit(1 if failures else 0)
