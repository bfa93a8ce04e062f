"""An external program's particles as VTK files (external_format = "vtk",
reports/external-format.md): the same particles written as CSV and in every
VTK layout mpmvv reads give the same results file.

The program here puts its own particles at the exact motion of the
user-motion scene plus a known offset, with a stress and a deformation
gradient of its own (not symmetric, so that a transposed or misplaced
component shows), and writes them:

- as CSV, the reference;
- through meshio (python3-meshio, a writer independent of mpmvv's reader):
  .vtu binary (base64, zlib-compressed), .vtu ascii (12 digits), legacy .vtk
  binary and ascii (5.1: OFFSETS, CONNECTIVITY, FIELD arrays);
- by hand, in the layouts meshio does not write: .vtp with raw appended data
  and UInt64 headers, the stress as VTK's 6 symmetric components; .vtu with
  base64 appended data in zlib blocks of 4 kB, header and data encoded as
  two runs as VTK does; legacy .vtk ascii with SCALARS, VECTORS, TENSORS and
  the time as field data.

Every binary layout gives /errors and /particles equal to the CSV's bit for
bit; the 12-digit ascii one within 1e-9, its output_spacing 1e-11 (the
doubles' 2.2e-16). A missing required array, particles moved out of the
plane and two files for one output time are named. Arrays named as the
program names them, mapped by external_names, read as the CSV; a name the
layout lacks, or one file name for two items, is refused. A stress written in
Voigt's order reads as the CSV with external_stress_order, and is refused as
out of the plane without it.

    /usr/bin/python3 tests/external_vtk.py MPMVV   (ctest runs it; exit 1 names what failed)
"""
import subprocess
import sys
import tempfile
from pathlib import Path

import h5py
import numpy as np

MPMVV = sys.argv[1]
SOURCE = Path(__file__).resolve().parents[1]
USER = SOURCE / "suites" / "scenes" / "user-motion.toml"
failures = []


def check(condition, what):
    if not condition:
        failures.append(what)


PROGRAM = r'''
import base64, json, math, os, struct, sys, zlib
import numpy as np
import meshio

inp = json.load(open(sys.argv[1]))
mode = sys.argv[2]
A, c, L = 0.05, 100.0, 1.0          # the user-motion scene's default motion
OFFSET = np.array([3e-4, -4e-4])


def u(X, Y, t):
    return np.stack([A * np.sin(np.pi * X / L) * np.sin(c * np.pi * t / L),
                     A * np.sin(np.pi * Y / L) * np.sin(np.pi * (2.0 / 3.0 + c * t / L))], axis=-1)


nx, ny = 29, 17
X, Y = [a.ravel() for a in np.meshgrid((np.arange(nx) + 0.5) / nx, (np.arange(ny) + 0.5) / ny)]
N = X.size
V0 = (1.0 + 0.5 * (np.arange(N) % 3)) / N
tracer_X = np.array(inp["tracer_reference"], dtype=float)
os.makedirs(inp["output"], exist_ok=True)


def path(stem, k, ext):
    return os.path.join(inp["output"], "%s_%d.%s" % (stem, k, ext))


def xyz(a2):
    return np.c_[a2, np.zeros(len(a2))]


def full(t2, zz=0.0):  # N x 2 x 2 -> N x 9, the plane's entries in a 3 x 3 (F: zz = F_33 = 1)
    f = np.zeros((len(t2), 3, 3))
    f[:, :2, :2] = t2
    f[:, 2, 2] = zz
    return f.reshape(-1, 9)


def appended(arrays, header, compress, encode):
    """The DataArray elements and the appended section of an XML VTK file."""
    h = "Q" if header == "UInt64" else "I"
    blob, elements = b"", []
    out_text = ""
    for name, a in arrays:
        a = np.ascontiguousarray(a, dtype="<f8")
        raw = a.tobytes()
        if compress:
            blocks = [raw[i:i + 4096] for i in range(0, len(raw), 4096)] or [b""]
            packed = [zlib.compress(b) for b in blocks]
            head = struct.pack("<" + h * (3 + len(packed)), len(blocks), 4096, len(blocks[-1]) % 4096, *map(len, packed))
            body = b"".join(packed)
        else:
            head, body = struct.pack("<" + h, len(raw)), raw
        offset = len(out_text) if encode else len(blob)
        if encode:
            out_text += base64.b64encode(head).decode() + base64.b64encode(body).decode()
        else:
            blob += head + body
        comps = 1 if a.ndim == 1 else a.shape[1]
        attr = '' if name == "Points" else ' Name="%s"' % name
        elements.append((name, '<DataArray type="Float64"%s NumberOfComponents="%d" format="appended" offset="%d"/>'
                         % (attr, comps, offset)))
    return elements, (out_text.encode() if encode else blob)


def write_xml(file, kind, points, arrays, t, header, compress, encode):
    elements, data = appended([("Points", points)] + arrays, header, compress, encode)
    point_element = elements[0][1]
    rest = "\n".join(e for _, e in elements[1:])
    head = ('<?xml version="1.0"?>\n<VTKFile type="%s" version="1.0" byte_order="LittleEndian" header_type="%s"%s>\n'
            '<%s>\n<FieldData><DataArray type="Float64" Name="TimeValue" NumberOfTuples="1" format="ascii">%s'
            '</DataArray></FieldData>\n<Piece NumberOfPoints="%d"%s>\n<Points>%s</Points>\n<PointData>\n%s\n</PointData>\n'
            '</Piece>\n</%s>\n<AppendedData encoding="%s">\n_'
            % (kind, header, ' compressor="vtkZLibDataCompressor"' if compress else "", kind, repr(t), len(points),
               ' NumberOfVerts="0"' if kind == "PolyData" else ' NumberOfCells="0"', point_element, rest, kind,
               "base64" if encode else "raw"))
    with open(file, "wb") as f:
        f.write(head.encode() + data + b"\n</AppendedData>\n</VTKFile>\n")


def write_legacy_ascii(file, points, t, scalars=(), vectors=(), tensors=()):
    g = lambda a: " ".join(repr(float(v)) for v in np.ravel(a))
    with open(file, "w") as f:
        f.write("# vtk DataFile Version 3.0\nparticles\nASCII\nDATASET POLYDATA\n")
        f.write("FIELD FieldData 1\nTimeValue 1 1 double\n%s\n" % repr(t))
        f.write("POINTS %d double\n%s\n" % (len(points), g(points)))
        f.write("VERTICES %d %d\n%s\n" % (len(points), 2 * len(points),
                                          " ".join("1 %d" % i for i in range(len(points)))))
        if scalars or vectors or tensors:
            f.write("POINT_DATA %d\n" % len(points))
        for name, a in scalars:
            f.write("SCALARS %s double 1\nLOOKUP_TABLE default\n%s\n" % (name, g(a)))
        for name, a in vectors:
            f.write("VECTORS %s double\n%s\n" % (name, g(a)))
        for name, a in tensors:
            f.write("TENSORS %s double\n%s\n" % (name, g(a)))


for k, t_out in enumerate(inp["output_times"]):
    # Near the output time, as a code with a fixed step lands, where the file
    # can say when (meshio writes no field data); else on it.
    t = t_out if "ontime" in sys.argv[3:] else t_out + 1e-6
    x = np.c_[X, Y] + u(X, Y, t) + OFFSET
    vel = np.c_[0.1 + X, -0.2 * Y]
    S = np.zeros((N, 2, 2))
    S[:, 0, 0], S[:, 1, 1], S[:, 0, 1] = 1e3 * X, 2e3 * Y + t, 500.0 * X * Y
    S[:, 1, 0] = S[:, 0, 1]
    F = np.zeros((N, 2, 2))
    F[:, 0, 0], F[:, 0, 1], F[:, 1, 0], F[:, 1, 1] = 1 + 0.01 * X, 0.02 * Y, -0.03 * X, 1 + 0.04 * Y + t
    V = V0 * np.linalg.det(F)
    tx = tracer_X + u(tracer_X[:, 0], tracer_X[:, 1], t) + OFFSET
    if mode == "csv":
        with open(path("particles", k, "csv"), "w") as f:
            f.write("# time = %r\nX,Y,x,y,V0,vx,vy,sxx,syy,sxy,F11,F12,F21,F22,V\n" % t)
            for p in range(N):
                f.write(",".join(repr(float(v)) for v in (X[p], Y[p], x[p, 0], x[p, 1], V0[p], vel[p, 0], vel[p, 1],
                        S[p, 0, 0], S[p, 1, 1], S[p, 0, 1], F[p, 0, 0], F[p, 0, 1], F[p, 1, 0], F[p, 1, 1], V[p])) + "\n")
        with open(path("tracers", k, "csv"), "w") as f:
            f.write("x,y\n" + "".join("%r,%r\n" % (a, b) for a, b in tx))
    elif mode.startswith("meshio"):
        _, ext, encoding = mode.split("-")
        data = {"reference_position": np.c_[X, Y], "reference_volume": V0, "velocity": xyz(vel),
                "stress": full(S), "deformation_gradient": F.reshape(-1, 4), "volume": V}
        if k == 1 and "missing" in sys.argv[3:]:
            del data["reference_volume"]
        for stem, pts, pd in (("particles", xyz(x), data), ("tracers", xyz(tx), {})):
            n = len(pts)
            mesh = meshio.Mesh(pts, [("vertex", np.arange(n).reshape(-1, 1))], point_data=pd,
                               field_data={"TimeValue": np.array([t])})
            meshio.write(path(stem, k, ext), mesh, file_format="vtu" if ext == "vtu" else "vtk",
                         binary=encoding == "binary")
        if "twice" in sys.argv[3:]:
            write_legacy_ascii(path("particles", k, "vtk"), xyz(x), t)
    elif mode == "vtp":
        S6 = np.c_[S[:, 0, 0], S[:, 1, 1], np.zeros(N), S[:, 0, 1], np.zeros(N), np.zeros(N)]
        if "voigt" in sys.argv[3:]:  # xx, yy, zz, yz, xz, xy (external_stress_order says so)
            S6 = S6[:, [0, 1, 2, 4, 5, 3]]
        arrays = [("reference_position", xyz(np.c_[X, Y])), ("reference_volume", V0), ("velocity", vel),
                  ("stress", S6), ("deformation_gradient", full(F, 1.0)), ("volume", V)]
        if "renamed" in sys.argv[3:]:  # a code's own names (external_names maps them)
            own = {"reference_volume": "vol0", "velocity": "velocities", "stress": "stresses"}
            arrays = [(own.get(n, n), a) for n, a in arrays]
        points = xyz(x)
        if "bent" in sys.argv[3:]:  # a 3-D code's motion out of the plane
            points[:, 2] = 1e-3 * X * t
        write_xml(path("particles", k, "vtp"), "PolyData", points, arrays, t, "UInt64", False, False)
        write_xml(path("tracers", k, "vtp"), "PolyData", xyz(tx), [], t, "UInt64", False, False)
    elif mode == "vtu-base64":
        arrays = [("reference_position", np.c_[X, Y]), ("reference_volume", V0), ("velocity", xyz(vel)),
                  ("stress", S.reshape(-1, 4)), ("deformation_gradient", F.reshape(-1, 4)), ("volume", V)]
        write_xml(path("particles", k, "vtu"), "UnstructuredGrid", xyz(x), arrays, t, "UInt32", True, True)
        write_xml(path("tracers", k, "vtu"), "UnstructuredGrid", xyz(tx), [], t, "UInt32", True, True)
    elif mode == "legacy-ascii":
        write_legacy_ascii(path("particles", k, "vtk"), xyz(x), t,
                           scalars=[("reference_volume", V0), ("volume", V)],
                           vectors=[("reference_position", xyz(np.c_[X, Y])), ("velocity", xyz(vel))],
                           tensors=[("stress", full(S)), ("deformation_gradient", full(F, 1.0))])
        write_legacy_ascii(path("tracers", k, "vtk"), xyz(tx), t)
'''

SETS = ["cells=16", "end_time=0.02"]


def run(tmp, name, fmt, *args, names="", order=None):
    output = tmp / f"{name}.h5"
    command = f"/usr/bin/python3 {tmp / 'toy.py'} {{input}} {' '.join(args)}"
    r = subprocess.run([MPMVV, "run", str(USER), "--threads", "1", "--quiet", "-o", str(output), "--set", SETS[0],
                        "--set", SETS[1], "--set", f"external_format={fmt}", "--set", f"external_command={command}",
                        "--set", f"external_names={names}"]
                       + (["--set", f"external_stress_order={order}"] if order is not None else []),
                       capture_output=True, text=True, timeout=120)
    return r, output


def datasets(path):
    with h5py.File(path) as f:
        out = {f"errors/{n}": f["errors"][n][()] for n in f["errors"]}
        for n in ("position", "velocity", "stress", "deformation_gradient", "J", "volume"):
            if n in f["particles"]:
                out[f"particles/{n}"] = f["particles"][n][()]
        out["output_time"] = f["external"]["output_time"][()]
        out["status"] = f.attrs["status"]
        out["fields"] = f["external"].attrs["fields"]
    return out


with tempfile.TemporaryDirectory() as tmp:
    tmp = Path(tmp)
    (tmp / "toy.py").write_text(PROGRAM)
    references = {}
    for when in ("", "ontime"):
        r, path = run(tmp, f"csv{when}", "csv", "csv", when)
        check(r.returncode == 0, f"the CSV run: exit {r.returncode}: {r.stdout}{r.stderr}")
        references[when] = datasets(path) if r.returncode == 0 else {}
    check(all(f"errors/{n}" in references[""] for n in ("particle_pressure_L2", "particle_deformation_L2",
                                                        "particle_velocity_L2"))
          and any(n.startswith("errors/L1_") for n in references[""]), f"the CSV run's norms: {sorted(references[''])}")
    check(not np.array_equal(references[""]["output_time"], references["ontime"]["output_time"]),
          "the program's own time is read from the CSV")
    # meshio writes no field data: its files are written on the output times.
    for mode, exact in (("meshio-vtu-binary", True), ("meshio-vtu-ascii", False), ("meshio-vtk-binary", True),
                        ("meshio-vtk-ascii", True), ("vtp", True), ("vtu-base64", True), ("legacy-ascii", True)):
        when = "ontime" if mode.startswith("meshio") else ""
        reference = references[when]
        r, path = run(tmp, mode, "vtk", mode, when)
        if r.returncode != 0:
            check(False, f"{mode}: exit {r.returncode}: {r.stdout}{r.stderr}")
            continue
        got = datasets(path)
        # How finely the numbers were written: doubles, or meshio's 12 ascii digits.
        with h5py.File(path) as f:
            spacing = f["external"].attrs.get("output_spacing")
        want_spacing = 1e-11 if mode == "meshio-vtu-ascii" else np.finfo(float).eps
        check(spacing is not None and np.isclose(spacing, want_spacing, rtol=1e-12, atol=0),
              f"{mode}: /external output_spacing {spacing}, not {want_spacing}")
        check(sorted(got) == sorted(reference), f"{mode}: datasets {sorted(got)} against {sorted(reference)}")
        for name, want in reference.items():
            if name not in got:
                continue
            have = got[name]
            if isinstance(want, np.ndarray):
                same = (np.array_equal(have, want, equal_nan=True) if exact
                        else np.allclose(have, want, rtol=1e-9, atol=1e-12, equal_nan=True))
                check(same, f"{mode}: {name} differs from the CSV's: {have} against {want}")
            else:
                check(have == want, f"{mode}: {name} {have} against {want}")

    # What goes wrong is named.
    r, path = run(tmp, "missing", "vtk", "meshio-vtu-binary", "ontime", "missing")
    check(r.returncode == 1 and "malformed output" in r.stdout and "particles_1.vtu" in r.stdout
          and "no point array 'reference_volume'" in r.stdout, f"a missing reference_volume: {r.stdout}")
    if path.exists():
        with h5py.File(path) as f:
            check(len(f["errors"]["time"]) == 1, "the output read before the malformed one is kept")
    # A code's own array names, mapped by external_names: the same results.
    def same_as_csv(r, path, what, attribute, value):
        """The run read the CSV's results bit for bit, and /external records `attribute`."""
        check(r.returncode == 0, f"{what}: exit {r.returncode}: {r.stdout}{r.stderr}")
        if r.returncode != 0:
            return
        got, want = datasets(path), references[""]
        check(sorted(got) == sorted(want) and all(np.array_equal(got[n], want[n], equal_nan=True)
                                                  if isinstance(want[n], np.ndarray) else got[n] == want[n]
                                                  for n in want),
              f"{what}: the results differ from the CSV's")
        with h5py.File(path) as f:
            check(f["external"].attrs[attribute].startswith(value), f"/external {attribute}")

    r, path = run(tmp, "renamed", "vtk", "vtp", "renamed",
                  names="reference_volume=vol0, velocity=velocities,stress = stresses")
    same_as_csv(r, path, "renamed arrays", "names", "reference_volume=vol0")
    # A stress in Voigt's order, read where external_stress_order puts it: the same results.
    r, path = run(tmp, "voigt", "vtk", "vtp", "voigt", order="xx, yy, zz, yz, xz, xy")
    same_as_csv(r, path, "a Voigt-ordered stress", "stress_order", "xx, yy, zz, yz, xz, xy")
    r, _ = run(tmp, "voigt-unordered", "vtk", "vtp", "voigt")
    check(r.returncode == 1 and "stress is not plane strain: sigma_xz" in r.stdout,
          f"a Voigt-ordered stress read in VTK's order: {r.stdout}")
    r, _ = run(tmp, "voigt-csv", "csv", "csv", order="xx, yy, zz, yz, xz, xy")
    check(r.returncode == 2 and "external_stress_order" in r.stderr and "external_format is csv" in r.stderr,
          f"a stress order for CSV files: {r.returncode}: {r.stderr}")
    r, _ = run(tmp, "voigt-twice", "vtk", "vtp", order="xx, yy, zz, yz, xz, yz")
    check(r.returncode == 2 and "external_stress_order" in r.stderr and "yz is given twice" in r.stderr,
          f"a stress order naming a component twice: {r.returncode}: {r.stderr}")
    r, _ = run(tmp, "unmapped", "vtk", "vtp", "renamed")
    check(r.returncode == 1 and "no point array 'vol0'" not in r.stdout and "no point array 'reference_volume'" in r.stdout,
          f"renamed arrays without the map: {r.stdout}")
    r, _ = run(tmp, "nonsense", "vtk", "vtp", names="volume0=vol0")
    check(r.returncode == 2 and "external_names" in r.stderr and "'volume0' is not an item of the vtk layout" in r.stderr,
          f"a name the layout does not have: {r.returncode}: {r.stderr}")
    r, _ = run(tmp, "twice-named", "vtk", "vtp", names="volume=v, mass=v")
    check(r.returncode == 2 and "'v' is the file's name of both volume and mass" in r.stderr,
          f"one file name for two items: {r.stderr}")
    # Names without a program to name the files of: refused, not ignored.
    for key, value in (("external_names", "volume=vol0"), ("external_stress_order", "xx,yy,zz,yz,xz,xy")):
        output = tmp / f"{key}-without-command.h5"
        r = subprocess.run([MPMVV, "run", str(USER), "--threads", "1", "--quiet", "-o", str(output),
                            "--set", SETS[0], "--set", SETS[1], "--set", f"{key}={value}"],
                           capture_output=True, text=True, timeout=120)
        check(r.returncode == 2 and key in r.stderr and "no external_command" in r.stderr and not output.exists(),
              f"{key} without external_command: {r.returncode}: {r.stderr}")
    # VTK's own order, however spelled, is the default and no name of another program's files.
    r = subprocess.run([MPMVV, "run", str(USER), "--threads", "1", "--quiet", "-o", str(tmp / "vtk-order.h5"),
                        "--set", SETS[0], "--set", SETS[1], "--set", "external_stress_order=XX,yy,zz,yx,yz,xz"],
                       capture_output=True, text=True, timeout=120)
    check(r.returncode == 0, f"VTK's order spelled otherwise, without external_command: {r.returncode}: {r.stderr}")
    r, _ = run(tmp, "bent", "vtk", "vtp", "bent")
    check(r.returncode == 1 and "malformed output" in r.stdout and "the points is not plane strain: z - Z" in r.stdout,
          f"particles moved out of the plane: {r.stdout}")
    r, _ = run(tmp, "twice", "vtk", "meshio-vtu-binary", "ontime", "twice")
    check(r.returncode == 1 and "particles_0.vtu and" in r.stdout and "one file per output time" in r.stdout,
          f"two files for one output: {r.stdout}")

for f in failures:
    print("FAILED:", f)
sys.exit(1 if failures else 0)
