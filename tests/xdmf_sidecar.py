"""The .xmf sidecar read by a reader that is not mpmvv's: `mpmvv run` with
particle_fields = "outputs" writes FILE.h5 and FILE.xmf, a temporal
collection of one grid per output time; each grid, read by meshio (Debian's
python3-meshio, which reads XDMF's HDF data items through h5py), must give
the particles' positions and every field of the results file's
/snapshots/<k> at that output time, and the grid's time must be the output
time. A run without particle_fields gives one grid at its end time, with the
results file's /particles. meshio reads one grid at a time and knows neither
<Time> nor the hyperslab through which the topology takes every particle of
/particle_index: the test takes each grid out of the collection with its
time, and replaces that whole-array slab by the array it slices (its start,
stride and count are checked first), so that what meshio reads is the
sidecar's own data items. ParaView's own reading is paraview_sidecar.py's,
where ParaView is installed.

    /usr/bin/python3 tests/xdmf_sidecar.py MPMVV   (ctest runs it; exit 1 names what failed)
"""
import copy
import sys
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

import h5py
import meshio
import numpy as np

from sidecar_runs import TIMES, sidecar_runs

MPMVV = sys.argv[1]
failures = []


def check(condition, what):
    if not condition:
        failures.append(what)


def grids(xmf):
    """(time, one-grid XDMF document) for each grid of the temporal collection."""
    collection = ET.parse(xmf).getroot().find("Domain").find("Grid")
    for grid in collection.findall("Grid"):
        grid = copy.deepcopy(grid)
        time = grid.find("Time")
        grid.remove(time)
        topology = grid.find("Topology")
        slab = topology.find("DataItem")
        if slab.get("ItemType") == "HyperSlab":
            start_stride_count, array = slab.findall("DataItem")
            count = int(topology.get("NumberOfElements"))
            check(start_stride_count.text.split() == ["0", "1", str(count)],
                  f"{xmf.name}: the topology's slab is {start_stride_count.text!r}, not every one of {count} particles")
            topology.remove(slab)
            topology.append(array)
        document = ET.Element("Xdmf", Version="3.0")
        ET.SubElement(document, "Domain").append(grid)
        yield float(time.get("Value")), document


def read_grid(document, path):
    ET.ElementTree(document).write(path)
    return meshio.read(path)


with tempfile.TemporaryDirectory() as tmp:
    tmp = Path(tmp)
    for name, out in sidecar_runs(MPMVV, tmp):
        read = list(grids(out.with_suffix(".xmf")))
        with h5py.File(out, "r") as f:
            index = f["particle_index"][...]
            if name == "series":
                expected = [(t, f[f"snapshots/{k}"]) for k, t in enumerate(TIMES)]
                fields = ("displacement", "velocity", "J", "stress", "deformation_gradient", "displacement_error")
            else:
                expected = [(TIMES[-1], f["particles"])]
                fields = ("velocity", "J", "deformation_gradient")
            check([t for t, _ in read] == [t for t, _ in expected],
                  f"{name}: the sidecar's times {[t for t, _ in read]}, not {[t for t, _ in expected]}")
            for (t, document), (_, group) in zip(read, expected):
                mesh = read_grid(document, tmp / f"{name}-step.xmf")
                n = group["J"].shape[0]
                check(np.array_equal(mesh.points, group["position"][...]),
                      f"{name} t = {t}: meshio's points are not the file's positions")
                vertices = np.concatenate([c.data.reshape(-1) for c in mesh.cells if c.type == "vertex"] or [[]])
                check(np.array_equal(vertices, index), f"{name} t = {t}: the vertices are not /particle_index")
                for field in fields:
                    got = mesh.point_data.get(field)
                    check(got is not None and got.shape[0] == n and np.array_equal(got.reshape(group[field].shape),
                                                                                    group[field][...]),
                          f"{name} t = {t}: {field} read by meshio differs from the results file's "
                          f"({None if got is None else got.shape} against {group[field].shape})")
                print(f"{name} t = {t}: {n} particles, {sorted(mesh.point_data)} equal to the results file's")

for f in failures:
    print("FAIL", f)
sys.exit(1 if failures else 0)
