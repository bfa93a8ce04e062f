"""The arrays under /probes of a results file (reports/results-format.md),
read on demand for the cases a report plots: probe lines (eq. 3.1's material
points), the first probe point's history, the circle's error spectrum, Hertz's
contact pressure, a scene's scalar histories, and the run's monitors."""
from dataclasses import dataclass

import h5py
import numpy as np

from .results import plain


@dataclass(frozen=True)
class ProbeLine:
    name: str
    quantity: str
    parameter: str                # e.g. reference_radius
    positions: np.ndarray         # P values of the parameter [m]
    time: np.ndarray              # T output times
    simulated: np.ndarray         # T x P
    exact: np.ndarray             # T x P


@dataclass(frozen=True)
class PointHistory:
    name: str
    quantity: str
    reference_position: np.ndarray
    time: np.ndarray              # S step times
    simulated: np.ndarray
    exact: np.ndarray


@dataclass(frozen=True)
class ErrorSpectrum:
    quantity: str
    reference_radius: float
    time: np.ndarray              # T output times
    amplitude: np.ndarray         # T x (M/2 + 1): one-sided amplitude of mode m of the error


def read_probe_lines(path):
    """Every probe line of a results file, in the file's group order."""
    lines = []
    with h5py.File(path, "r") as f:
        for name, group in f.get("probes", {}).items():
            quantity = plain(group.attrs.get("quantity", ""))
            if name == "circle" or quantity not in group or group[quantity].ndim != 2:
                continue
            parameter = next((p for p in group if p.startswith("reference_") and p != "reference_position"),
                             "reference_position")
            positions = np.asarray(group[parameter][:], float)
            if positions.ndim == 2:
                positions = np.hypot(positions[:, 0], positions[:, 1])
            lines.append(ProbeLine(name, quantity, parameter, positions, np.asarray(group["time"][:], float),
                                   np.asarray(group[quantity][:], float),
                                   np.asarray(group["exact_" + quantity][:], float)))
    return lines


def read_point_history(path):
    """The first probe point's history (time after every step), or None."""
    with h5py.File(path, "r") as f:
        for name, group in f.get("probes", {}).items():
            quantity = plain(group.attrs.get("quantity", ""))
            if name != "circle" and quantity in group and group[quantity].ndim == 1:
                return PointHistory(name, quantity, np.asarray(group.attrs.get("reference_position", [])),
                                    np.asarray(group["time"][:], float), np.asarray(group[quantity][:], float),
                                    np.asarray(group["exact_" + quantity][:], float))
    return None


def read_error_spectrum(path):
    """/probes/circle/error_spectrum with its times, or None when absent or empty."""
    with h5py.File(path, "r") as f:
        circle = f.get("probes/circle")
        if circle is None or "error_spectrum" not in circle or circle["error_spectrum"].shape[0] == 0:
            return None
        return ErrorSpectrum(plain(circle.attrs.get("quantity", "")),
                             float(circle.attrs.get("reference_radius", float("nan"))),
                             np.asarray(circle["time"][:], float), np.asarray(circle["error_spectrum"][:], float))


@dataclass(frozen=True)
class ContactPressure:
    x: np.ndarray                 # n cell midpoints [m]
    time: np.ndarray              # T output times
    pressure: np.ndarray          # T x n simulated contact pressure [Pa]
    exact: np.ndarray             # T x n Hertz's pressure at the load the run measured [Pa]
    peak_pressure: np.ndarray = None  # T: Hertz's p0 at that load [Pa] (None in files written before it)
    half_width: np.ndarray = None     # T: Hertz's a at that load [m]


@dataclass(frozen=True)
class SceneHistory:
    time: np.ndarray              # S step times
    values: dict                  # name -> S values of a scalar recorded after every step


def read_contact_pressure(path):
    """/probes/contact_pressure (hertz-cylinder), or None when absent or without an output."""
    with h5py.File(path, "r") as f:
        group = f.get("probes/contact_pressure")
        if not isinstance(group, h5py.Group) or any(n not in group for n in ("x", "time", "pressure",
                                                                              "exact_pressure")):
            return None
        x = np.asarray(group["x"][:], float)
        time = np.asarray(group["time"][:], float)
        if time.size == 0 or x.size == 0:
            return None
        shape = (time.size, x.size)
        exact = {name: np.asarray(group[f"exact_{name}"][:], float) for name in ("peak_pressure", "half_width")
                 if f"exact_{name}" in group and group[f"exact_{name}"].shape == (time.size,)}
        return ContactPressure(x, time, np.asarray(group["pressure"][:], float).reshape(shape),
                               np.asarray(group["exact_pressure"][:], float).reshape(shape),
                               exact.get("peak_pressure"), exact.get("half_width"))


def read_scene_history(path):
    """/probes/history: its time and every scalar recorded with it, or None when absent or empty."""
    with h5py.File(path, "r") as f:
        group = f.get("probes/history")
        if isinstance(group, h5py.Group) and "quantity" in group.attrs:
            return None
        read = _time_columns(group)
        return None if read is None else SceneHistory(*read)


def _time_columns(group):
    """A probe group's `time` and every other dataset shaped like it, or None when
    the group is absent, has no `time` or no time in it."""
    if not isinstance(group, h5py.Group) or "time" not in group:
        return None
    time = np.asarray(group["time"][:], float)
    if time.size == 0:
        return None
    columns = {name: np.asarray(group[name][:], float) for name in group
               if name != "time" and isinstance(group[name], h5py.Dataset) and group[name].shape == time.shape}
    return time, columns


@dataclass(frozen=True)
class RunMonitors:
    initial_energy: float         # attribute initial_energy [J per unit depth; per radian in r-z]
    time: np.ndarray              # T output times
    columns: dict                 # dataset name -> T values, for the datasets shaped like time

    def column(self, name):
        """The dataset `name`, or NaN at every output time when the file does not have it."""
        return self.columns.get(name, np.full(self.time.shape, np.nan))


def read_monitors(path):
    """/probes/monitors, or None when absent (results files written before the
    monitors existed) or without an output time; with the columns of
    /probes/coverage (the holes between the domains: uncovered_fraction,
    inside_fraction, largest_hole_cells ...) beside them where the run has it,
    at the same output times."""
    with h5py.File(path, "r") as f:
        group = f.get("probes/monitors")
        read = _time_columns(group)
        if read is None:
            return None
        time, columns = read
        coverage = _time_columns(f.get("probes/coverage"))
        if coverage is not None and np.array_equal(coverage[0], time):
            columns.update({name: values for name, values in coverage[1].items() if name not in columns})
        return RunMonitors(float(group.attrs.get("initial_energy", float("nan"))), time, columns)


def relative_energy_created(monitors):
    """abs(energy_created) over the solver's energy_scale at each output time of a
    RunMonitors (results-format.md): NaN where the file has no energy_scale (written
    before it) or the scale is not positive."""
    scale = monitors.column("energy_scale")
    scale = np.where(scale > 0, scale, np.nan)
    return np.abs(monitors.column("energy_created")) / scale
