"""ParaView opens a run through its .xmf sidecar: `mpmvv run` with
particle_fields = "outputs" writes FILE.h5 and FILE.xmf; ParaView's Python
(python3-paraview) reads FILE.xmf as one time step per output time, each a
point set of every particle with its displacement, velocity, J, stress, F and
displacement error, whose J equals the results file's; a run without
particle_fields opens at its end time. Exit 77 (ctest: skipped), saying so,
where ParaView's Python is not installed (it is not a dependency:
`apt-get install python3-paraview`).

    /usr/bin/python3 tests/paraview_sidecar.py MPMVV
"""
import sys
import tempfile
from pathlib import Path

try:
    from paraview import servermanager
    from paraview.simple import OpenDataFile, UpdatePipeline
except ImportError:
    print("SKIP: ParaView's Python (python3-paraview) is not installed")
    sys.exit(77)
import h5py
import numpy as np

from sidecar_runs import TIMES, sidecar_runs

MPMVV = sys.argv[1]
failures = []


def check(condition, what):
    if not condition:
        failures.append(what)


def points_at(reader, time):
    UpdatePipeline(time=time, proxy=reader)
    data = servermanager.Fetch(reader)
    if data.IsA("vtkCompositeDataSet"):
        iterator = data.NewIterator()
        iterator.InitTraversal()
        data = iterator.GetCurrentDataObject()
    arrays = {}
    point_data = data.GetPointData()
    for i in range(point_data.GetNumberOfArrays()):
        a = point_data.GetArray(i)
        arrays[a.GetName()] = np.array([a.GetTuple(k) for k in range(a.GetNumberOfTuples())])
    return data.GetNumberOfPoints(), data.GetNumberOfCells(), arrays


with tempfile.TemporaryDirectory() as tmp:
    tmp = Path(tmp)
    for name, out in sidecar_runs(MPMVV, tmp):
        reader = OpenDataFile(str(out.with_suffix(".xmf").resolve()))
        steps = list(reader.TimestepValues) if hasattr(reader.TimestepValues, "__len__") else [reader.TimestepValues]
        with h5py.File(out, "r") as f:
            n = f["particles/J"].shape[0]
            if name == "series":
                check(steps == TIMES, f"{name}: ParaView's time steps {steps}, not the output times {TIMES}")
                for k, t in enumerate(TIMES):
                    points, cells, arrays = points_at(reader, t)
                    check(points == cells == n, f"{name} t = {t}: {points} points and {cells} cells, not {n}")
                    for field, width in (("displacement", 2), ("velocity", 2), ("J", 1), ("stress", 4),
                                         ("deformation_gradient", 4), ("displacement_error", 2)):
                        check(field in arrays and arrays[field].shape == (n, width),
                              f"{name} t = {t}: {field} {arrays.get(field, np.empty(0)).shape}, not ({n}, {width})")
                    J = f[f"snapshots/{k}/J"][...]
                    check("J" in arrays and np.array_equal(arrays["J"][:, 0], J), f"{name} t = {t}: J differs from the file's")
                    print(f"{name} t = {t}: {points} points, arrays {sorted(arrays)}")
            else:
                check(len(steps) == 1 and abs(steps[0] - 0.2) < 1e-12, f"{name}: time steps {steps}, not the end 0.2")
                points, cells, arrays = points_at(reader, steps[0])
                check(points == cells == n and "J" in arrays and np.array_equal(arrays["J"][:, 0], f["particles/J"][...]),
                      f"{name}: {points} points, {cells} cells, arrays {sorted(arrays)}")
                print(f"{name} t = {steps[0]}: {points} points, arrays {sorted(arrays)}")

for f in failures:
    print("FAIL", f)
sys.exit(1 if failures else 0)
