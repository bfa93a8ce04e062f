"""Read a suite output directory (suites/README.md, "The output directory") and
the results files in it (reports/results-format.md).

    DIR/manifest.json        every case: id, study, resolved keys, status, results path
    DIR/suite.toml           the suite as run: [[study]] and [[reference]] tables (its [[expect]]
                             as the manifest records them, checked)
    DIR/cases/<id>.h5        one results file per case that ran

A case's status is the manifest's (completed, lost, failed, crashed, timeout,
error, pending); "lost" is a run that reached its end time with its solution
lost (the results file's health verdict, reports/results-format.md), and it
counts as not completed everywhere. A case without a readable results file (pending, crashed, timeout,
error, or a damaged file) is kept with ``results = None`` and a note saying why,
so that every report and the gate can show it instead of stopping on it.
Only root attributes, /errors and the /measurements and /settling scalars are read up front;
probe arrays (lines, points, the circle, /probes/contact_pressure,
/probes/history, /probes/monitors) are read on demand for the cases that are
plotted.
"""
import json
import math
import tomllib
from dataclasses import dataclass, field
from datetime import datetime
from pathlib import Path

import h5py
import numpy as np

CASE_STATUSES = ("completed", "lost", "failed", "crashed", "timeout", "error", "pending")
TIME_MATCH_TOLERANCE = 1e-9   # relative; output times are written from the same decimal values


class SuiteDirectoryError(Exception):
    """A directory that is not a readable suite output directory; the message is one line."""


@dataclass(frozen=True)
class CaseResults:
    """What a results file holds besides its probe and particle arrays."""
    attributes: dict
    error_times: np.ndarray
    errors: dict                  # /errors column name -> values at error_times
    line_quantities: dict         # probe line name -> its 'quantity' attribute
    measurements: dict = field(default_factory=dict)   # /measurements attributes: name -> value
    settling: dict = field(default_factory=dict)       # /settling attributes, its norms under "norms"


@dataclass(frozen=True)
class Case:
    id: str
    study: str
    keys: dict
    status: str
    detail: str
    results_path: Path
    manifest_wall_time_s: float = float("nan")
    results: CaseResults = None
    note: str = ""                # why there are no results, when there are none

    def attribute(self, name, default=float("nan")):
        if self.results is not None and name in self.results.attributes:
            return self.results.attributes[name]
        return default

    @property
    def h(self):
        return float(self.attribute("h"))

    @property
    def end_time(self):
        return float(self.keys.get("end_time", self.attribute("end_time")))

    @property
    def time_reached(self):
        return float(self.attribute("time_reached"))

    @property
    def failure_reason(self):
        if self.status == "lost":
            return (f"solution lost at t = {float(self.attribute('health_time')):.4g} s: "
                    f"{self.attribute('health_reason', '')}")
        reason = self.attribute("failure_reason", "")
        return reason or self.detail or self.note

    @property
    def wall_time_s(self):
        """The time loop's wall time from the results file; else the process's from the manifest."""
        return float(self.attribute("wall_time_s", self.manifest_wall_time_s))

    @property
    def completed(self):
        return self.status == "completed" and self.results is not None


@dataclass(frozen=True)
class Suite:
    directory: Path
    name: str
    description: str
    written: datetime
    has_suite_file: bool
    studies: list = field(default_factory=list)        # [[study]] tables of suite.toml
    expectations: list = field(default_factory=list)   # [[expect]] tables, as the manifest records them checked
    expectations_recorded: bool = True                 # False: a manifest written before it recorded them
    references: list = field(default_factory=list)     # [[reference]] tables of suite.toml (references.py)
    cases: list = field(default_factory=list)

    def study_names(self):
        names = [s.get("name") for s in self.studies if isinstance(s.get("name"), str)]
        return names + sorted({c.study for c in self.cases} - set(names), key=[c.study for c in self.cases].index)

    def cases_of(self, study):
        return [c for c in self.cases if c.study == study]

    def varied_keys(self, study):
        """The keys the study's [[study]] table sweeps and zips, in file order."""
        table = next((s for s in self.studies if s.get("name") == study), {})
        return [key for part in ("sweep", "zip") if isinstance(table.get(part), dict) for key in table[part]]


def read_suite(directory):
    """Read DIR/manifest.json, DIR/suite.toml (optional here) and every case's results."""
    directory = Path(directory)
    if not directory.is_dir():
        raise SuiteDirectoryError(f"{directory}: no such directory")
    manifest_path = directory / "manifest.json"
    manifest = _read_manifest(manifest_path)
    suite_path = directory / "suite.toml"
    suite_file = _read_suite_file(suite_path) if suite_path.is_file() else {}
    studies = suite_file.get("study", [])
    references = suite_file.get("reference", [])
    if not all(isinstance(tables, list) for tables in (studies, references)):
        raise SuiteDirectoryError(f"{suite_path}: 'study' and 'reference' must be arrays of tables "
                                  "([[study]], [[reference]])")
    # The expectations as mpmvv suite checked them (its loader is their one
    # check: suites/README.md), not as suite.toml holds them.
    expectations = manifest.get("expectations", [])
    if not isinstance(expectations, list) or not all(isinstance(e, dict) for e in expectations):
        raise SuiteDirectoryError(f"{manifest_path}: 'expectations' must be an array of objects")
    return Suite(
        directory=directory,
        name=str(manifest.get("suite", directory.name)),
        description=str(suite_file.get("description", manifest.get("description", ""))),
        written=datetime.fromtimestamp(manifest_path.stat().st_mtime),
        has_suite_file=suite_path.is_file(),
        studies=studies,
        expectations=expectations,
        expectations_recorded="expectations" in manifest,
        references=references,
        cases=[_read_case(directory, entry) for entry in manifest["cases"]],
    )


def _read_manifest(path):
    if not path.is_file():
        raise SuiteDirectoryError(f"{path}: missing; not a suite output directory (mpmvv suite SUITE -o DIR writes it)")
    try:
        manifest = json.loads(path.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as error:
        raise SuiteDirectoryError(f"{path}: not valid JSON ({error})") from None
    if not isinstance(manifest, dict) or not isinstance(manifest.get("cases"), list):
        raise SuiteDirectoryError(f"{path}: expected an object with a 'cases' array")
    for index, entry in enumerate(manifest["cases"]):
        named = isinstance(entry, dict) and isinstance(entry.get("id"), str) and isinstance(entry.get("study"), str)
        if not named:
            raise SuiteDirectoryError(f"{path}: case {index} needs string 'id' and 'study'")
        if not isinstance(entry.get("keys", {}), dict):
            raise SuiteDirectoryError(f"{path}: case '{entry['id']}': 'keys' must be an object")
    return manifest


def _read_suite_file(path):
    try:
        return tomllib.loads(path.read_text())
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as error:
        raise SuiteDirectoryError(f"{path}: not valid TOML ({error})") from None


def read_results_file(path):
    """A Case for a results file outside a suite directory: its id the file's name,
    its status the file's, no study or keys (the quick tables of loose files)."""
    path = Path(path)
    results = read_case_results(path)
    return Case(id=path.stem, study="", keys={}, status=str(results.attributes.get("status", "")), detail="",
                results_path=path, results=results)


def _read_case(directory, entry):
    results_path = directory / entry.get("results", f"cases/{entry['id']}.h5")
    wall_time = entry.get("wall_time_s")
    results, note = None, ""
    if results_path.is_file():
        try:
            results = read_case_results(results_path)
        except (OSError, KeyError, ValueError, TypeError) as error:
            note = f"unreadable results file ({error})"
    elif entry.get("status") not in ("pending", None):
        note = "no results file"
    status = entry.get("status")
    if status not in CASE_STATUSES:
        status = results.attributes.get("status", "pending") if results is not None else "pending"
    # The results file's own verdict wins over a manifest that called the run completed.
    if status == "completed" and results is not None and results.attributes.get("status") == "lost":
        status = "lost"
    return Case(id=entry["id"], study=entry["study"], keys=dict(entry.get("keys", {})), status=status,
                detail=str(entry.get("detail", "")), results_path=results_path,
                manifest_wall_time_s=float(wall_time) if isinstance(wall_time, (int, float)) else float("nan"),
                results=results, note=note)


def _plain(value):
    if isinstance(value, bytes):
        return value.decode()
    if isinstance(value, np.generic):
        return value.item()
    return value


def read_case_results(path):
    """Root attributes, /errors, the probe lines' quantities and the /measurements
    and /settling attributes of one results file."""
    with h5py.File(path, "r") as f:
        attributes = {name: _plain(value) for name, value in f.attrs.items()}
        errors_group = f.get("errors")
        errors, error_times = {}, np.zeros(0)
        if errors_group is not None:
            error_times = np.asarray(errors_group["time"][:], float) if "time" in errors_group else np.zeros(0)
            errors = {name: np.asarray(errors_group[name][:], float) for name in errors_group if name != "time"}
            # One value per output time (reports/results-format.md); anything else is a damaged file.
            for name, values in [("time", error_times)] + list(errors.items()):
                if values.ndim != 1 or values.shape != error_times.shape:
                    raise ValueError(f"/errors/{name} has shape {values.shape}, not one value per output time "
                                     f"{error_times.shape}")
        line_quantities = {}
        for name, group in f.get("probes", {}).items():
            quantity = _plain(group.attrs.get("quantity", ""))
            if name != "circle" and quantity in group and group[quantity].ndim == 2:
                line_quantities[name] = quantity
        measurements_group = f.get("measurements")
        measurements = ({name: _plain(value) for name, value in measurements_group.attrs.items()}
                        if isinstance(measurements_group, h5py.Group) else {})
        settling_group = f.get("settling")
        settling = {}
        if isinstance(settling_group, h5py.Group):
            settling = {name: _plain(value) for name, value in settling_group.attrs.items()}
            norms_group = settling_group.get("norms")
            settling["norms"] = ({name: _plain(value) for name, value in norms_group.attrs.items()}
                                 if isinstance(norms_group, h5py.Group) else {})
    return CaseResults(attributes, error_times, errors, line_quantities, measurements, settling)


def lookup_error(case, norm, time):
    """(E, "") for the error column `norm` at output time `time`, or (NaN, why not)."""
    nan = float("nan")
    if case.results is None:
        return nan, f"{case.status}" + (f": {case.failure_reason}" if case.failure_reason else "")
    if norm not in case.results.errors:
        return nan, f"no /errors column '{norm}'"
    times = case.results.error_times
    hits = np.nonzero(np.abs(times - time) <= TIME_MATCH_TOLERANCE * max(1.0, abs(time)))[0]
    column = case.results.errors[norm]
    if hits.size == 0 or hits[0] >= column.size:
        return nan, f"no output at t = {time:g} (reached {case.time_reached:.4g})"
    # From the output time at which the health verdict found the solution lost
    # on, the run's errors measure no solution (the outputs before stay usable,
    # as a failed run's do).
    lost_at = float(case.attribute("health_time"))
    if case.attribute("health", "") == "solution lost" and time >= lost_at * (1.0 - TIME_MATCH_TOLERANCE):
        return nan, f"solution lost at t = {lost_at:.4g} s ({case.attribute('health_reason', '')})"
    value = float(column[hits[0]])
    if not math.isfinite(value):
        return nan, f"{norm} is {value} at t = {time:g}"
    return value, ""


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
            quantity = _plain(group.attrs.get("quantity", ""))
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


# Norms of the displacement error, measured against exact_displacement_L2.
DISPLACEMENT_NORMS = ("particle_L1", "particle_L2", "particle_Linf")
# /errors columns that are already relative to the exact value they measure
# (results-format.md): their exact signal is 1, in their own unit.
RELATIVE_NORMS = ("particle_relative_L2_integrated",)
RELATIVE_NORM_PREFIX = "error_"


def _exact_signal_series(case, norm):
    """(output times, the exact signal the norm measures at each): the mean |exact|
    on the line of an L1_<line> norm (eq. 3.1's exact values), the RMS exact
    displacement for the particle displacement norms; None for other norms, an
    unreadable file or a missing line."""
    if norm.startswith("L1_"):
        try:
            line = next((l for l in read_probe_lines(case.results_path) if l.name == norm[3:]), None)
        except (OSError, KeyError, ValueError, TypeError):
            return None
        return None if line is None else (line.time, np.mean(np.abs(line.exact), axis=1))
    if norm in DISPLACEMENT_NORMS and "exact_displacement_L2" in case.results.errors:
        return case.results.error_times, case.results.errors["exact_displacement_L2"]
    return None


def _output_index(times, time, count):
    """The index of output time `time` among `times` (and below `count`), or None."""
    hits = np.nonzero(np.abs(times - time) <= TIME_MATCH_TOLERANCE * max(1.0, abs(time)))[0]
    return int(hits[0]) if hits.size and hits[0] < count else None


def exact_signal_fraction(case, norm, time):
    """What the exact solution gives the norm to measure at output time `time`, as
    a fraction of its largest over the run's output times: the mean |exact| on the
    line of an L1_<line> norm (eq. 3.1's exact values), the RMS exact displacement
    for the particle displacement norms. None where it is not known (other norms,
    no such output, an unreadable file). A read where the fraction is small
    measures little: a run without the motion scores nearly the same there."""
    series = _exact_signal_series(case, norm) if case.results is not None else None
    if series is None:
        return None
    times, signal = series
    index = _output_index(times, time, len(signal))
    largest = float(np.max(signal)) if len(signal) else 0.0
    if index is None or not largest > 0.0:
        return None
    return float(signal[index]) / largest


def _strain_size(case):
    """The largest in-plane |F - I| entry over the particles at the end of the run:
    a strain, and a stress E (F - I), is formed from entries of F near 1, so its
    rounding is ulps of 1, not of the strain. None where the file does not hold F."""
    try:
        with h5py.File(case.results_path, "r") as f:
            F = f.get("particles/deformation_gradient")
            if not isinstance(F, h5py.Dataset) or F.size == 0:
                return None
            F = np.asarray(F[:], float).reshape(-1, 2, 2)
    except (OSError, KeyError, ValueError, TypeError):
        return None
    strain = float(np.max(np.abs(F - np.eye(2))))
    return strain if math.isfinite(strain) and strain > 0.0 else None


def _coordinate_size(case, norm):
    """The size of the numbers the norm's error is a difference of: for a length
    read off material points (x - X, |x| - |X|), the largest |X| of those points
    (the line's, or every particle's); pi for an angle (atan2's largest value).
    None where the file does not hold them."""
    try:
        with h5py.File(case.results_path, "r") as f:
            if norm.startswith("L1_"):
                group = f.get(f"probes/{norm[3:]}")
                if not isinstance(group, h5py.Group):
                    return None
                if _plain(group.attrs.get("quantity", "")) == "angular_displacement":
                    return math.pi
                positions = group.get("reference_position")
            else:
                positions = f.get("particles/reference_position")
            if not isinstance(positions, h5py.Dataset) or positions.size == 0:
                return None
            positions = np.asarray(positions[:], float).reshape(-1, 2)
    except (OSError, KeyError, ValueError, TypeError):
        return None
    size = float(np.max(np.hypot(positions[:, 0], positions[:, 1])))
    return size if math.isfinite(size) else None


def error_scale(case, norm, time):
    """(S, M) for the error `norm` at output time `time`: S the exact signal it
    measures there (the mean |exact| on an L1_<line> norm's line, the RMS exact
    displacement for particle_L1, _L2, _Linf; 1 for an error already relative to
    its exact value: error_* and particle_relative_L2_integrated), M the size of
    the numbers the error is a difference of (_coordinate_size; 1 for a relative
    error, 1 / strain for a relative error of a strain or stress, _strain_size),
    in the norm's unit. The round-off floor of reports/orders.py is
    measured with them. None where either is not known."""
    if case.results is None:
        return None
    if norm.startswith(RELATIVE_NORM_PREFIX) or norm in RELATIVE_NORMS:
        if norm not in case.results.errors:
            return None
        # A strain or stress relative to its exact value is rounded to ulps of
        # F's entries (near 1) over the strain: M = 1 / strain where it is small.
        # (Without F in the file, 1: the floor of the ratio itself.)
        if norm.endswith(("_strain", "_stress")):
            strain = _strain_size(case)
            return 1.0, 1.0 / min(strain, 1.0) if strain is not None else 1.0
        return 1.0, 1.0
    series = _exact_signal_series(case, norm)
    if series is None:
        return None
    times, signal = series
    index = _output_index(times, time, len(signal))
    size = _coordinate_size(case, norm) if index is not None else None
    if size is None or not math.isfinite(signal[index]):
        return None
    return float(signal[index]), size


# A mean over a region of at least a quarter of the body is at most twice the
# body's RMS (settling_scale).
SETTLING_REGION_FACTOR = 2.0


def settling_scale(case, norm, time):
    """The largest error in `norm` that the run's stopping short of its static
    state could leave at output time `time`, in the norm's unit, from the
    results file's /settling group (results-format.md); None for a run that
    does not settle, a read before the end (settling is the end's) or a norm it
    does not translate to.

    A damped run that relaxes (method "relaxation") gives each norm read at the
    end its own: how much it would still change. Load steps that each end in
    equilibrium (method "newton") give the Newton correction left, delta
    (displacement: mass-weighted RMS over the grid) and the RMS of its strain
    over the body; a particle's displacement is a convex combination of the
    nodes', so over the N particles its RMS, and its mean, is at most delta
    (particle_L2, particle_L1); over k of them (a probe line's points, counted
    as particles of the mean mass; the one of particle_Linf) at most delta
    sqrt(N / k); an error_* column of a strain, stretch or stress (relative to
    its exact value, a mean over a region of the body) at most
    SETTLING_REGION_FACTOR x the strain's RMS over the strain's size, the
    largest |F - I| entry of the particles."""
    if case.results is None or not case.results.settling:
        return None
    if _output_index(np.asarray([case.end_time]), float(time), 1) is None:
        return None
    settling = case.results.settling

    def finite(value):
        return float(value) if isinstance(value, (int, float)) and math.isfinite(value) and value >= 0.0 else None

    if settling.get("method") == "relaxation":
        return finite(settling.get("norms", {}).get(norm))
    delta, strain_error = finite(settling.get("displacement")), finite(settling.get("strain"))
    particles = case.attribute("particle_count")
    counted = isinstance(particles, (int, float)) and particles >= 1
    if norm in ("particle_L1", "particle_L2"):
        return delta
    if delta is not None and counted and norm == "particle_Linf":
        return delta * math.sqrt(particles)
    if delta is not None and counted and norm.startswith("L1_"):
        try:
            line = next((l for l in read_probe_lines(case.results_path) if l.name == norm[3:]), None)
        except (OSError, KeyError, ValueError, TypeError):
            return None
        # A length: the displacements' components, not an angle or a pressure.
        if line is None or "displacement" not in line.quantity or "angular" in line.quantity \
                or line.exact.shape[-1] == 0:
            return None
        return delta * math.sqrt(particles / line.exact.shape[-1])
    if strain_error is not None and norm.startswith(RELATIVE_NORM_PREFIX) \
            and norm.endswith(("_strain", "_stretch", "_stress")):
        strain = _strain_size(case)
        return None if strain is None else SETTLING_REGION_FACTOR * strain_error / strain
    return None


def read_point_history(path):
    """The first probe point's history (time after every step), or None."""
    with h5py.File(path, "r") as f:
        for name, group in f.get("probes", {}).items():
            quantity = _plain(group.attrs.get("quantity", ""))
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
        return ErrorSpectrum(_plain(circle.attrs.get("quantity", "")),
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
    monitors existed) or without an output time."""
    with h5py.File(path, "r") as f:
        group = f.get("probes/monitors")
        read = _time_columns(group)
        return None if read is None else RunMonitors(float(group.attrs.get("initial_energy", float("nan"))), *read)


def relative_energy_created(monitors):
    """abs(energy_created) over the solver's energy_scale at each output time of a
    RunMonitors (results-format.md): NaN where the file has no energy_scale (written
    before it) or the scale is not positive."""
    scale = monitors.column("energy_scale")
    scale = np.where(scale > 0, scale, np.nan)
    return np.abs(monitors.column("energy_created")) / scale
