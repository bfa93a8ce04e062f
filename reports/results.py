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
Only root attributes, /errors and the /measurements, /settling and /external scalars are read up front;
probe arrays (lines, points, the circle, /probes/contact_pressure,
/probes/history, /probes/monitors) are read on demand for the cases that are
plotted (probes.py), and the scales an error is judged against are in
scales.py.
"""
import json
import math
import stat
import tomllib
from dataclasses import dataclass, field
from datetime import datetime
from pathlib import Path

import h5py
import numpy as np

from . import consistency

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
    external: dict = field(default_factory=dict)       # /external attributes (another program's run)
    error_units: dict = field(default_factory=dict)    # /errors column name -> the unit the run stored (its `units`)


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
    problems: tuple = ()          # why its results are not its case's (consistency.py); results then None

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
    tier: str = "full"                                 # the tier that ran (suites/README.md, "Tiers")
    problems: list = field(default_factory=list)       # results not checked to be their cases' (consistency.py)

    def study_names(self):
        names = [s.get("name") for s in self.studies if isinstance(s.get("name"), str)]
        return names + sorted({c.study for c in self.cases} - set(names), key=[c.study for c in self.cases].index)

    def cases_of(self, study):
        return [c for c in self.cases if c.study == study]

    def varied_keys(self, study):
        """The keys the study's [[study]] table sweeps and zips in the tier that
        ran, in file order (a `ci` table's keys take the place of the study's own)."""
        table = next((s for s in self.studies if s.get("name") == study), {})
        parts = {part: list(table[part]) if isinstance(table.get(part), dict) else [] for part in ("sweep", "zip")}
        ci = table.get("ci")
        if self.tier == "ci" and isinstance(ci, dict):
            tables = {part: ci[part] if isinstance(ci.get(part), dict) else {} for part in ("set", "sweep", "zip")}
            fixed = set(tables["set"])
            parts["sweep"] = [k for k in parts["sweep"] if k not in fixed] + \
                [k for k in tables["sweep"] if k not in parts["sweep"]]
            if tables["zip"]:
                parts["zip"] = list(tables["zip"])
        return parts["sweep"] + parts["zip"]


def read_suite(directory):
    """Read DIR/manifest.json, DIR/suite.toml (optional here) and every case's results."""
    directory = Path(directory)
    if not directory.is_dir():
        raise SuiteDirectoryError(f"{directory}: no such directory")
    manifest_path = directory / "manifest.json"
    _confine(directory, manifest_path)
    manifest = _read_manifest(manifest_path)
    suite_path = directory / "suite.toml"
    _confine(directory, suite_path)
    suite_text = _read_text(suite_path) if suite_path.exists() else None
    suite_file = _parse_suite_file(suite_path, suite_text) if suite_text is not None else {}
    studies = suite_file.get("study", [])
    references = suite_file.get("reference", [])
    tier = manifest.get("tier", "full")
    if tier not in ("full", "ci"):
        raise SuiteDirectoryError(f"{manifest_path}: 'tier' is {tier!r}; a suite's tiers are 'full' and 'ci'")
    if not all(isinstance(tables, list) for tables in (studies, references)):
        raise SuiteDirectoryError(f"{suite_path}: 'study' and 'reference' must be arrays of tables "
                                  "([[study]], [[reference]])")
    # The expectations as mpmvv suite checked them (its loader is their one
    # check: suites/README.md), not as suite.toml holds them.
    expectations = manifest.get("expectations", [])
    if not isinstance(expectations, list) or not all(isinstance(e, dict) for e in expectations):
        raise SuiteDirectoryError(f"{manifest_path}: 'expectations' must be an array of objects")
    for number, expect in enumerate(expectations, start=1):
        problem = _expectation_problem(expect)
        if problem:
            raise SuiteDirectoryError(f"{manifest_path}: expectation {number}: {problem}")
    # ... and they are the ones suite.toml states (a band widened in the
    # manifest alone, an expectation added or dropped, is refused).
    if suite_text is not None and "expectations" in manifest:
        problem = consistency.expectation_problem(expectations, consistency.suite_expectations(suite_file, tier), tier)
        if problem:
            raise SuiteDirectoryError(f"{manifest_path}: {problem}")
    overridden = {s.get("name"): _overridden_keys(s) for s in studies if isinstance(s, dict)}
    cases = [_read_case(directory, entry, overridden.get(entry["study"], ())) for entry in manifest["cases"]]
    problems = [f"case '{c.id}': {p}" for c in cases for p in c.problems]
    problems += consistency.suite_problems(manifest, suite_text, suite_file, cases, directory)
    return Suite(
        directory=directory,
        name=str(manifest.get("suite", directory.name)),
        description=str(suite_file.get("description", manifest.get("description", ""))),
        written=datetime.fromtimestamp(manifest_path.stat().st_mtime),
        has_suite_file=suite_path.is_file(),
        studies=studies,
        expectations=expectations,
        expectations_recorded="expectations" in manifest,
        # Published numbers sit beside the full study's levels, which the
        # ci tier does not run (mpmvv suite checks them in the full tier).
        references=references if tier == "full" else [],
        cases=cases,
        tier=tier,
        problems=problems,
    )


def require_suite_file(suite, program):
    """Refuse (SuiteDirectoryError) a suite directory without its suite.toml:
    the gate and the report need its [[study]] tables and check the manifest's
    expectations against its [[expect]] tables."""
    if not suite.has_suite_file:
        raise SuiteDirectoryError(f"{suite.directory / 'suite.toml'}: missing; {program} needs the suite's "
                                  "[[study]] and [[expect]] tables")


def _confine(directory, path):
    """Refuse `path` (manifest.json, suite.toml) when it, or a symlink it is,
    resolves outside `directory`: as a case's results file, it is the directory's own."""
    if not path.is_symlink():
        return
    try:
        inside = path.resolve().is_relative_to(directory.resolve())
    except (OSError, RuntimeError) as error:
        raise SuiteDirectoryError(f"{path}: cannot be resolved ({error})") from None
    if not inside:
        raise SuiteDirectoryError(f"{path}: a symlink to {path.resolve()}, outside the suite directory; "
                                  "a suite directory's files are inside it")


def _overridden_keys(study):
    """The keys a study's [[study.override]] tables set (a case's id keeps the swept value)."""
    overrides = study.get("override", [])
    return {key for o in overrides if isinstance(o, dict) and isinstance(o.get("set"), dict) for key in o["set"]} \
        if isinstance(overrides, list) else set()


def _no_duplicate_keys(pairs):
    keys = [key for key, _ in pairs]
    twice = sorted({key for key in keys if keys.count(key) > 1})
    if twice:
        raise ValueError(f"the key {', '.join(repr(k) for k in twice)} is given twice in one object")
    return dict(pairs)


def _no_constant(name):
    raise ValueError(f"{name} is not JSON (a number there is finite)")


def _read_manifest(path):
    if not path.exists() and not path.is_symlink():
        raise SuiteDirectoryError(f"{path}: missing; not a suite output directory (mpmvv suite SUITE -o DIR writes it)")
    try:
        manifest = json.loads(_read_text(path), object_pairs_hook=_no_duplicate_keys, parse_constant=_no_constant)
    except json.JSONDecodeError as error:
        raise SuiteDirectoryError(f"{path}: not valid JSON ({error})") from None
    except (ValueError, RecursionError) as error:
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


def _read_text(path):
    """A regular file's text; a FIFO, device, directory or loop is refused at once, not read."""
    try:
        if not stat.S_ISREG(path.stat().st_mode):
            raise SuiteDirectoryError(f"{path}: not a regular file")
        return path.read_text()
    except UnicodeDecodeError:
        raise SuiteDirectoryError(f"{path}: not UTF-8 text") from None
    except (OSError, RuntimeError) as error:
        raise SuiteDirectoryError(f"{path}: cannot be read ({getattr(error, 'strerror', None) or error})") from None


def _parse_suite_file(path, text):
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise SuiteDirectoryError(f"{path}: not valid TOML ({error})") from None


# What each recorded expectation's keys must hold (the loader wrote them; a
# manifest edited since must not reach the gate's arithmetic as text).
_EXPECTATION_KINDS = {"study": str, "norm": str, "refine": str, "order": (int, float), "tolerance": (int, float),
                      "max_error": (int, float), "max_error_constant": (int, float), "time": (int, float),
                      "where": dict, "levels": list, "must_complete": bool, "at_roundoff": bool,
                      "interval_within_band": bool}


def _expectation_problem(expect):
    for key in ("study", "norm"):
        if key not in expect:
            return f"no '{key}'"
    for key, kind in _EXPECTATION_KINDS.items():
        value = expect.get(key)
        if value is None:
            if key in expect:
                return f"'{key}' is null"
            continue
        numeric_bool = kind != bool and isinstance(value, bool)
        if not isinstance(value, kind) or numeric_bool:
            return f"'{key}' is {value!r}, not {_KIND_NAMES[kind]}"
        if isinstance(value, float) and not math.isfinite(value):
            return f"'{key}' is {value!r}, not a finite number"
    if "order" in expect and "tolerance" not in expect:
        return "'order' without 'tolerance'"
    return ""


_KIND_NAMES = {str: "text", (int, float): "a number", dict: "a table", list: "an array", bool: "true or false"}


def read_results_file(path):
    """A Case for a results file outside a suite directory: its id the file's name,
    its status the file's, no study or keys (the quick tables of loose files)."""
    path = Path(path)
    results = read_case_results(path)
    return Case(id=path.stem, study="", keys={}, status=str(results.attributes.get("status", "")), detail="",
                results_path=path, results=results)


def _read_case(directory, entry, overridden=()):
    """A manifest entry and its results file, checked against each other (consistency.py):
    a case with a problem keeps it in `problems`, its results None (`overridden`:
    the keys its study's overrides set)."""
    wall_time = entry.get("wall_time_s")
    problems = [p for p in (consistency.id_problem(entry["id"]),) if p]
    problems += consistency.id_key_problems(entry, overridden) if not problems else []
    problems += consistency.run_problems(entry)
    results_path, path_problem = consistency.results_path(directory, entry)
    problems += [path_problem] if path_problem else []
    results, note = None, ""
    status = entry.get("status")
    if status not in CASE_STATUSES:
        problems.append(f"the manifest's status {status!r} is none of {', '.join(CASE_STATUSES)}")
        status = "error"
    if problems:
        pass                                  # a path or name refused: its file is not read
    elif results_path.is_file():
        try:
            results = read_case_results(results_path)
        except (OSError, KeyError, ValueError, TypeError) as error:
            note = f"unreadable results file ({error})"
            if status in consistency.ENDED:
                problems.append(note)
        if results is not None:
            problems += consistency.case_problems(entry, status, results)
            problems += consistency.probe_norm_problems(results_path, results)
    elif status != "pending":
        note = "no results file"
        if status in consistency.ENDED:
            problems.append(f"the manifest says {status}, and it has no results file")
    # The results file's own verdict wins over a manifest that called the run completed.
    if status == "completed" and results is not None and results.attributes.get("status") == "lost":
        status = "lost"
    if problems:
        results, note = None, "; ".join(problems)
    return Case(id=entry["id"], study=entry["study"], keys=dict(entry.get("keys", {})), status=status,
                detail=str(entry.get("detail", "")), results_path=results_path or Path(directory),
                manifest_wall_time_s=float(wall_time) if isinstance(wall_time, (int, float)) else float("nan"),
                results=results, note=note, problems=tuple(problems))


def plain(value):
    if isinstance(value, bytes):
        return value.decode()
    if isinstance(value, np.generic):
        return value.item()
    return value


def read_case_results(path):
    """Root attributes, /errors, the probe lines' quantities and the /measurements,
    /settling and /external attributes of one results file."""
    with h5py.File(path, "r") as f:
        attributes = {name: plain(value) for name, value in f.attrs.items()}
        errors_group = f.get("errors")
        errors, error_times = {}, np.zeros(0)
        if errors_group is not None:
            # Numbers stored as numbers: text that reads as one is still a damaged file.
            for name, item in errors_group.items():
                if not isinstance(item, h5py.Dataset) or item.dtype.kind not in "fiu":
                    raise ValueError(f"/errors/{name} holds {getattr(item, 'dtype', 'a group')}, not numbers")
            error_times = np.asarray(errors_group["time"][:], float) if "time" in errors_group else np.zeros(0)
            errors = {name: np.asarray(errors_group[name][:], float) for name in errors_group if name != "time"}
            # One value per output time (reports/results-format.md); anything else is a damaged file.
            for name, values in [("time", error_times)] + list(errors.items()):
                if values.ndim != 1 or values.shape != error_times.shape:
                    raise ValueError(f"/errors/{name} has shape {values.shape}, not one value per output time "
                                     f"{error_times.shape}")
        # "name unit" a line (results-format.md); "-" for a column without one; absent in older files.
        error_units = {}
        if errors_group is not None:
            for line in plain(errors_group.attrs.get("units", "")).splitlines():
                name, _, unit = line.rpartition(" ")
                if name:
                    error_units[name] = "" if unit == "-" else unit
        line_quantities = {}
        for name, group in f.get("probes", {}).items():
            quantity = plain(group.attrs.get("quantity", ""))
            if name != "circle" and quantity in group and group[quantity].ndim == 2:
                line_quantities[name] = quantity
        measurements_group = f.get("measurements")
        measurements = ({name: plain(value) for name, value in measurements_group.attrs.items()}
                        if isinstance(measurements_group, h5py.Group) else {})
        settling_group = f.get("settling")
        settling = {}
        if isinstance(settling_group, h5py.Group):
            settling = {name: plain(value) for name, value in settling_group.attrs.items()}
            norms_group = settling_group.get("norms")
            settling["norms"] = ({name: plain(value) for name, value in norms_group.attrs.items()}
                                 if isinstance(norms_group, h5py.Group) else {})
        external_group = f.get("external")
        external = ({name: plain(value) for name, value in external_group.attrs.items()}
                    if isinstance(external_group, h5py.Group) else {})
    return CaseResults(attributes, error_times, errors, line_quantities, measurements, settling, external, error_units)


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
class ParticleSnapshot:
    """One /snapshots/<k> group (particle_fields = "outputs"): the particles at an output time."""
    time: float
    position: np.ndarray            # N x 2 [m]
    velocity: np.ndarray            # N x 2 [m/s]
    displacement_error: np.ndarray  # N x 2 [m], x - x_exact(X, t); None without an exact motion


def read_snapshot_times(path):
    """The output times the file holds particle snapshots at, in order (empty without /snapshots)."""
    with h5py.File(path, "r") as f:
        group = f.get("snapshots")
        if not isinstance(group, h5py.Group):
            return []
        return sorted((float(g.attrs["time"]), name) for name, g in group.items() if "time" in g.attrs)


def read_snapshot(path, name, largest=None):
    """The snapshot /snapshots/<name>; with `largest`, every k-th particle so that at
    most that many are read (a figure needs no more)."""
    with h5py.File(path, "r") as f:
        g = f["snapshots"][name]
        n = g["position"].shape[0]
        stride = max(1, -(-n // largest)) if largest else 1
        error = g["displacement_error"][::stride] if "displacement_error" in g else None
        return ParticleSnapshot(float(g.attrs["time"]), g["position"][::stride], g["velocity"][::stride],
                                None if error is None else np.asarray(error))
