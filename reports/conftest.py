"""Shared pytest fixtures: synthetic ring results files with the layout of
reports/results-format.md, so the report scripts are tested on data whose
answer is known."""
import h5py
import numpy as np
import pytest


def write_ring_results(path, cells, l1_at_times, times, method="cpdi", amplitude=0.5,
                       status="completed", failure_reason="", failure_time=float("nan")):
    h = 3.0 / cells
    with h5py.File(path, "w") as f:
        f.attrs["h"] = h
        f.attrs["cells"] = np.int64(cells)
        f.attrs["scene"] = "ring"
        f.attrs["particles_per_direction"] = np.int64(2)
        f.attrs["forcing_time_s"] = 0.1
        f.attrs["method"] = method
        f.attrs["amplitude"] = amplitude
        f.attrs["status"] = status
        f.attrs["failure_reason"] = failure_reason
        f.attrs["failure_time"] = failure_time
        f.attrs["time_reached"] = times[-1] if status == "completed" else failure_time
        f.attrs["wall_time_s"] = 1.0
        f.attrs["end_time"] = times[-1]
        f.attrs["steps"] = np.int64(10)
        f.attrs["particle_steps_per_second"] = 1e6
        e = f.create_group("errors")
        e["time"] = np.asarray(times, dtype=float)
        for name in ("L1_theta0", "L1_theta_plus45", "L1_theta_minus45", "particle_L1"):
            e[name] = np.asarray(l1_at_times, dtype=float)


@pytest.fixture
def second_order_series(tmp_path):
    """Three meshes whose error is exactly 0.7 h^2 at every output time."""
    times = [0.25, 1.0]
    paths = []
    for cells in (32, 64, 128):
        h = 3.0 / cells
        path = tmp_path / f"ring-{cells}.h5"
        write_ring_results(path, cells, [0.7 * h * h, 0.7 * h * h], times)
        paths.append(str(path))
    return paths
