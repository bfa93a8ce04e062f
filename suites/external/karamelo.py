#!/usr/bin/python3
"""Runs Karamelo (an open C++ MPM code) on a case of mpmvv's ring scene, the
stiff vortex (scenes/stiff-vortex.toml), as an external program
(reports/external-format.md):

    external_command = "/usr/bin/python3 {suites}/external/karamelo.py {input}"
    external_format = "csv"

It writes a Karamelo input script for the case, runs Karamelo (the binary
$KARAMELO, default /work/karamelo/build/karamelo) and turns its particle
dumps into particles_<k>.csv in {output}. Exit status 2 when the case asks
for something Karamelo is not given here, or when the binary is missing.

What is mapped, and what Karamelo does its own way:
- the grid: Karamelo's total Lagrangian grid spans the bounding box of the
  region the solid is seeded in, so the solid is seeded in the scene's square
  domain (nodes at -domain/2 + i h, h = domain / cells, mpmvv's grid) and the
  particles outside the ring are deleted: a particle where its sub-cell
  centre lies in the ring, of volume (h / n)^2 (mpmvv's seeding = "centre",
  not its exact clipped volumes). Karamelo's vortex example seeds the disk
  R <= R_o, so its grid starts at -R_o, half a cell off mpmvv's on 30 cells;
- formulation total -> tlmpm; method linear; velocity_transfer flip -> FLIP
  with Karamelo's PIC share of its vortex example (FLIP blend 0.99, or
  $KARAMELO_FLIP), apic -> APIC; scheme usl, usf, musl as named (Karamelo's
  own default and its example's is musl);
- the body force: Karamelo applies it at the grid nodes, b(node) times the
  node's mass, b evaluated at the node's reference position (mpmvv takes it
  at the particles or over their domains, body_force_quadrature); the
  example's force reads x, y, which this Karamelo's body_force fix does not
  set at the nodes (it sets x0, y0);
- the time step: fixed (time_step = "cfl" required), the largest dt of at
  most cfl h / (c0 + v0) that lands on every output time, c0 the P-wave speed
  and v0 the largest initial speed; Karamelo's example takes 0.2 of its own
  CFL step, which it recomputes every step;
- rims held: the grid nodes strictly outside the ring held at rest, as the
  scene does (the example also holds the nodes on the inner rim). Free rims
  are refused: so run, Karamelo's ring leaves the exact motion within 0.05 s
  (30 cells, cosine: relative L2 0.8-1.0 where mpmvv's own is 0.08), with
  the force at every node or at the ring's only;
- the initial velocity of the exact motion, R g'(0) h(R) e_theta (the
  example starts the ring at rest whatever g'(0) is).
Karamelo reads every number of its input in single precision (h, dt, E, nu,
the force's constants: relative rounding about 6e-8) and writes its dumps
with 6 significant digits, so positions carry a rounding of about 1e-6 m.
It cannot follow tracer points, so the probe lines' L1 is not measured, only
the particle norms.
"""
import json
import math
import os
import shutil
import struct
import subprocess
import sys


def num(x):
    """A number as Karamelo's parser reads it: digits and a point, no exponent
    (it reads every number in single precision, so 17 decimals are plenty)."""
    text = repr(float(x))
    return text if "e" not in text else f"{x:.20f}".rstrip("0")


def single(x):
    """x rounded to single precision, as Karamelo holds a number it parsed."""
    return struct.unpack("f", struct.pack("f", x))[0]


def refuse(message):
    print("karamelo.py: " + message, file=sys.stderr)
    sys.exit(2)


if len(sys.argv) != 2:
    refuse("usage: karamelo.py CASE.input.json")
case = json.load(open(sys.argv[1]))
k = case["keys"]
binary = os.environ.get("KARAMELO", "/work/karamelo/build/karamelo")
if not (os.path.isfile(binary) and os.access(binary, os.X_OK)):
    refuse(f"no Karamelo executable at {binary} (build it, or set KARAMELO to its path)")

# What this adapter can hand Karamelo; anything else is refused, not approximated.
wanted = {"scene": (case["scene"], ["ring"]), "formulation": (k["formulation"], ["total"]),
          "method": (k["method"], ["linear"]), "material": (k["material"], ["neo-hookean"]),
          "rims": (k["rims"], ["held"]), "time_step": (k["time_step"], ["cfl"]),
          "scheme": (k["scheme"], ["usl", "usf", "musl"]),
          "velocity_transfer": (k["velocity_transfer"], ["flip", "apic"]),
          "output_format": (case["output_format"], ["csv"])}
for key, (value, allowed) in wanted.items():
    if value not in allowed:
        refuse(f"{key} = {value!r} is not run through Karamelo here (one of {', '.join(allowed)})")
n_ppd = int(k["particles_per_direction"])
if n_ppd == 3:  # Karamelo puts 3 per direction at Gauss points, not sub-cell centres
    refuse("particles_per_direction = 3: Karamelo seeds those at Gauss points, not at mpmvv's sub-cell centres")

# The case in numbers.
A, Ri, Ro = k["amplitude"], k["inner_radius"], k["outer_radius"]
lam, mu, rho0 = k["lambda"], k["mu"], k["density"]
E, nu = mu * (3 * lam + 2 * mu) / (lam + mu), lam / (2 * (lam + mu))
half, h = 0.5 * k["domain"], k["domain"] / k["cells"]
times, end = case["output_times"], case["end_time"]
width, Rm = Ro - Ri, 0.5 * (Ri + Ro)

# g(t) and its derivatives, as Karamelo expressions of its variable `time`.
if k["time_function"] == "sine":
    g, gp, gpp = f"{num(A)}*sin(PI*time)", f"{num(A)}*PI*cos(PI*time)", f"(0-PI*PI)*{num(A)}*sin(PI*time)"
    gp0 = A * math.pi
else:
    g, gp, gpp = (f"0.5*{num(A)}*(1-cos(2*PI*time))", f"{num(A)}*PI*sin(2*PI*time)",
                  f"2*PI*PI*{num(A)}*cos(2*PI*time)")
    gp0 = 0.0

# The fixed step: at most cfl h / (c0 + v0), an integer number of steps to
# end_time, and every output time within a hundredth of its gap of a step.
# Karamelo holds dt in single precision, and its time is steps times that.
c0 = math.sqrt((lam + 2 * mu) / rho0)
radii = [Ri + width * i / 1000 for i in range(1001)]
v0 = abs(gp0) * max(R * (1 - 4 * ((R - Rm) / width) ** 2) ** 2 for R in radii)
steps = math.ceil(end / (k["cfl"] * h / (c0 + v0)))
gaps = [b - a for a, b in zip([0.0] + times[:-1], times)]
for tries in range(1000):
    dt = single(end / steps)
    at = [round(t / dt) for t in times]
    if all(abs(n * dt - t) <= 0.01 * gap for n, t, gap in zip(at, times, gaps)) and len(set(at)) == len(at):
        break
    steps += 1
else:
    refuse("found no fixed step that lands on the output times")
every = at[0]
for n in at[1:]:
    every = math.gcd(every, n)

out = case["output"]
work = out.rstrip("/") + ".karamelo"
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
os.makedirs(out, exist_ok=True)

# The script. The force is eqs. 2.14-2.15 (suites/PROBLEMS.md section 1):
# components in the current polar basis, theta = Theta + alpha, R the
# reference radius; at a total Lagrangian node, (x0, y0) is the reference
# position. Karamelo expands every variable into the text of the expressions
# that use it and parses that text again at every node and step, which is
# most of its run time here: h(R) = c (k - d^2)^2, d = R - R_m, c = 16 / w^4,
# k = w^2 / 4, keeps R and d to one or two mentions each.
transfer = "FLIP" if k["velocity_transfer"] == "flip" else "APIC"
blend = os.environ.get("KARAMELO_FLIP", "0.99") if transfer == "FLIP" else ""
c, kk = 16 / width ** 4, width ** 2 / 4
script = f"""# written by mpmvv's suites/external/karamelo.py for {case['scene']}, {k['cells']} cells
method(tlmpm, {transfer}, linear{', ' + blend if blend else ''})
scheme({k['scheme']})
dimension(2, {num(-half)}, {num(half)}, {num(-half)}, {num(half)}, {num(h)})
material(mat, neo-hookean, {num(rho0)}, {num(E)}, {num(nu)})
region(square, block, {num(-half)}, {num(half)}, {num(-half)}, {num(half)})
region(disk, cylinder, 0, 0, {num(Ro)})
region(hole, cylinder, 0, 0, {num(Ri)})
region(inner, cylinder, 0, 0, {num(Ri * (1 - 1e-6))})
region(beyond, difference, square, disk)
region(annulus, difference, disk, inner)
solid(ring, region, square, {n_ppd}, mat, {num(h)}, 0)
delete_particles(ring, region, hole)
delete_particles(ring, region, beyond)

# Held rims: the nodes strictly outside the ring at rest, as mpmvv's scene
# holds them; the force is then needed only at the others. The region inner
# is the hole shrunk by 1e-6, more than single precision's rounding, so that
# a node on the inner rim stays free.
region(outside, cylinder, 0, 0, {num(Ro)}, exterior)
group(gout, nodes, region, outside, solid, ring)
group(gin, nodes, region, inner, solid, ring)
group(gring, nodes, region, annulus, solid, ring)
fix(fout, velocity_nodes, gout, 0, 0)
fix(fin, velocity_nodes, gin, 0, 0)
R = sqrt(x0*x0 + y0*y0)
d = R - {num(Rm)}
h = {num(c)}*({num(kk)} - d^2)^2
hp = {num(4 * c)}*d*(d^2 - {num(kk)})
hpp = {num(12 * c)}*d^2 - {num(c * width ** 2)}
g = {g}
gp = {gp}
gpp = {gpp}
th = atan2(y0, x0) + g*h
br = R*({num(mu / rho0)}*(hp*g)^2 - (gp*h)^2)
bt = R*gpp*h - {num(mu / rho0)}*(3*hp + R*hpp)*g
fix(force, body_force, gring, br*cos(th) - bt*sin(th), br*sin(th) + bt*cos(th))
fix(start, initial_velocity_particles, all, 0 - gp*h*y0, gp*h*x0, NULL)

# Karamelo's own error measures in its log, to set beside mpmvv's: check_s the
# L2 displacement error over the volume, check_z its time-integrated relative L2.
fix(check, check_solution, all, (cos(g*h) - 1)*x0 - sin(g*h)*y0, sin(g*h)*x0 + (cos(g*h) - 1)*y0)

set_dt({num(dt)})
dump(particles, all, particle, {every}, {work}/dump.*.LAMMPS, x, y, x0, y0, vx, vy, s11, s22, s12, volume, mass)
set_output({every})
log_modify(custom, step, dt, time, check_s, check_z)
run({steps})
"""
script_path = os.path.join(work, "ring.mpm")
with open(script_path, "w") as f:
    f.write(script)
print(f"karamelo.py: h = {h!r} m, dt = {dt!r} s, {steps} steps, dumps every {every}", flush=True)
status = subprocess.run([binary, "-i", script_path], cwd=work).returncode
if status != 0:
    sys.exit(status)

# The dumps as the CSV layout. Karamelo's time advances by exactly dt a step,
# so the time of step n is n dt; the reference positions are its x0, y0 and
# the reference volumes its masses over rho_0 (Karamelo's vol0 = mass / rho0).
columns = "X,Y,x,y,V0,vx,vy,sxx,syy,sxy,V"
for index, n in enumerate(at):
    path = os.path.join(work, f"dump.{n}.LAMMPS")
    if not os.path.exists(path):  # the outputs before it stand; mpmvv names the first one missing
        print(f"karamelo.py: Karamelo wrote no dump at step {n}", file=sys.stderr)
        sys.exit(1)
    with open(path) as f:
        lines = f.read().splitlines()
    names = lines[8].split()[2:]  # "ITEM: ATOMS id type tag x y ..."
    rows = sorted((line.split() for line in lines[9:]), key=lambda r: int(r[0]))
    col = {name: i for i, name in enumerate(names)}
    with open(os.path.join(out, f"particles_{index}.csv"), "w") as f:
        f.write(f"# time = {n * dt!r}\n# Karamelo step {n}\n{columns}\n")
        for r in rows:
            v = lambda name: r[col[name]]
            V0 = repr(float(v("mass")) / rho0)
            f.write(",".join([v("x0"), v("y0"), v("x"), v("y"), V0, v("vx"), v("vy"),
                              v("s11"), v("s22"), v("s12"), v("volume")]) + "\n")
for name in os.listdir(work):
    if name.endswith(".LAMMPS"):
        os.remove(os.path.join(work, name))
