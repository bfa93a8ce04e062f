"""What the gate and the report check before they judge a suite output directory:
that each result is the result of its case (issue: a verdict must never rest on
data nobody checked).

A suite directory is written by `mpmvv suite`, but anything can have happened
to it since: a file copied in from another run, a manifest edited by hand, a
suite.toml of another suite. Every check here names the case (or file) and
what is wrong, in one line; read_suite (results.py) keeps those lines in
Suite.problems, drops the results of a case that has one (its numbers are
not used), and `mpmvv gate` and `mpmvv report` then give FAIL / exit 1 with
the lines, never a PASS.

Checked per case (manifest entry and results file):
  * the id is a name (no '/', '\\', control character, '.' or '..'), it
    begins with its study's name, and each of its "-key=value" parts that
    names a key of the case gives that key's value (tools/app/suite/study.cpp
    makes the id from the study name and the swept and zipped keys);
  * the exit code agrees with the status (completed: 0; failed, lost: 0 or 1)
    and the wall time is a finite number >= 0;
  * the results path is relative and resolves inside the directory, and
    what it names is a regular file (not a FIFO, device or directory);
  * the manifest's status is one of results.CASE_STATUSES; the file's is one
    of a results file's (completed, lost, failed, interrupted) and, for a
    case that ended (completed, failed, lost), the manifest's;
  * every manifest key has the same value in the file's configuration
    (numbers to RELATIVE_TOLERANCE), and every key of the configuration is
    one of the manifest's;
  * /errors: time strictly increasing; no error negative or infinite, and
    none NaN after a value in a completed healthy run (norm_problems).
Checked per suite: no suite still writing it, no id and no results file twice, no two cases of one
study with the same keys, suite.toml the suite the manifest ran, the suite's
name the stem of its suite_file, the ci tier only on studies that have one.
The manifest's expectations are checked by results.read_suite against the
[[expect]] tables suite.toml gives for the tier (suite_expectations).
"""
import fcntl
import math
import os
import re
import stat
import tomllib
from pathlib import Path

import numpy as np

RESULT_STATUSES = ("completed", "lost", "failed", "interrupted")
ENDED = ("completed", "failed", "lost")         # a manifest status read from the results file itself
NOT_KEYS = ("scene",)                            # in a configuration, not a key (the manifest's entry names it)
RELATIVE_TOLERANCE = 1e-12                       # keys are written from the same doubles
_NOT_A_NAME = re.compile(r"[/\\\x00-\x1f\x7f]")
_CONTROL = re.compile(r"[\x00-\x1f\x7f]")


def id_problem(case_id):
    """Why `case_id` is not a case name, or ''."""
    if not case_id or case_id in (".", "..") or _NOT_A_NAME.search(case_id):
        return f"case id {case_id!r} is not a name (no '/', '\\', control characters, '.' or '..')"
    return ""


def id_key_problems(entry, overridden=()):
    """Why the case id is not what its study and keys give, or []: it begins with
    the study's name, and each "-key=value" part naming a key of the case holds
    that key's value (as tools/app/suite/study.cpp writes it: the value's text,
    ' ' and '/' as '_'). A key a [[study.override]] sets (`overridden`) may differ
    from the id's value, which is the sweep's."""
    case_id, study, keys = entry["id"], entry["study"], entry.get("keys", {})
    if case_id != study and not case_id.startswith(study + "-"):
        return [f"case id {case_id!r} does not begin with its study's name '{study}'"]
    rest = case_id[len(study):]
    markers = sorted((m.start(), key) for key in keys
                     for m in re.finditer(re.escape(f"-{key}="), rest))
    problems = []
    for index, (start, key) in enumerate(markers):
        end = markers[index + 1][0] if index + 1 < len(markers) else len(rest)
        text = rest[start + len(key) + 2:end]
        if key not in overridden and not _id_value_is(text, keys[key]):
            problems.append(f"case id {case_id!r} says {key}={text}, its keys {key} = {keys[key]!r}")
    return problems


def _id_value_is(text, value):
    if isinstance(value, bool):
        return text == ("true" if value else "false")
    if isinstance(value, (int, float)):
        try:
            return math.isclose(float(text), float(value), rel_tol=1e-9, abs_tol=0.0)
        except ValueError:
            return False
    if isinstance(value, list):
        numbers = re.findall(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|nan|inf", text)
        return len(numbers) == len(value) and all(_id_value_is(n, v) for n, v in zip(numbers, value))
    return text == str(value).replace(" ", "_").replace("/", "_")


def run_problems(entry):
    """Why the manifest's record of how the case's process ended cannot be, or []:
    a completed case exited 0, a failed or lost one 0 or 1 (tools/app/suite/
    case_process.cpp); a wall time is a finite number >= 0."""
    problems = []
    status, code = entry.get("status"), entry.get("exit_code")
    if "exit_code" in entry:
        if not isinstance(code, int) or isinstance(code, bool):
            problems.append(f"exit_code is {code!r}, not an integer")
        elif status == "completed" and code != 0:
            problems.append(f"the manifest says completed with exit code {code} (a completed run exits 0)")
        elif status in ("failed", "lost") and code not in (0, 1):
            problems.append(f"the manifest says {status} with exit code {code} (a run that ended exits 0 or 1)")
    if "wall_time_s" in entry:
        wall = entry["wall_time_s"]
        if not isinstance(wall, (int, float)) or isinstance(wall, bool) or not math.isfinite(wall) or wall < 0:
            problems.append(f"wall_time_s is {wall!r}, not a time (a finite number >= 0)")
    return problems


def results_path(directory, entry):
    """(path, problem): where the case's results file is, confined to `directory`;
    path is None with a one-line problem when the manifest's entry points elsewhere."""
    relative = entry.get("results", f"cases/{entry['id']}.h5")
    if not isinstance(relative, str) or not relative:
        return None, f"'results' is {relative!r}, not a path inside the directory"
    if _CONTROL.search(relative):
        return None, f"'results' {relative!r} holds a control character (a NUL byte or line break): not a path"
    if Path(relative).is_absolute():
        return None, f"'results' is the absolute path {relative!r}; a case's file is inside the suite directory"
    path = Path(directory) / relative
    try:
        inside = path.resolve().is_relative_to(Path(directory).resolve())
    except (OSError, RuntimeError, ValueError) as error:   # a symlink loop
        return None, f"'results' {relative!r} cannot be resolved ({error})"
    if not inside:
        return None, f"'results' {relative!r} resolves outside the suite directory"
    try:
        mode = path.stat().st_mode
    except FileNotFoundError:
        return path, ""
    except (OSError, ValueError) as error:
        return None, f"'results' {relative!r}: {getattr(error, 'strerror', None) or error}"
    if not stat.S_ISREG(mode):
        return None, f"'results' {relative!r} is not a regular file"
    return path, ""


def _same(recorded, expected):
    if isinstance(expected, bool) or isinstance(recorded, (bool, np.bool_)):
        return bool(recorded) == expected if isinstance(expected, bool) else False
    if isinstance(expected, (int, float)):
        try:
            value = float(recorded)
        except (TypeError, ValueError):
            return False
        if isinstance(recorded, (str, bytes)):
            return False                       # a number stored as text is not the number
        return math.isclose(value, float(expected), rel_tol=RELATIVE_TOLERANCE, abs_tol=0.0) or value == expected
    if isinstance(expected, list):
        values = np.atleast_1d(np.asarray(recorded, dtype=object))
        return len(values) == len(expected) and all(_same(v, e) for v, e in zip(values, expected))
    return str(recorded) == str(expected)


def key_problems(entry, attributes):
    """The manifest keys whose value the results file's configuration (the
    resolved keys the run used, TOML in its `configuration` attribute) records
    differently or not at all. A key the runner found missing and took at its
    default ("written before K existed" in the manifest's detail) is not one."""
    keys = entry.get("keys", {})
    try:
        configuration = tomllib.loads(str(attributes.get("configuration", "")))
    except tomllib.TOMLDecodeError as error:
        return [f"the results file's configuration is not TOML ({error})"]
    added = str(entry.get("detail", "")).partition("written before ")[2]
    problems = [f"key '{key}' is {value!r} in the results file's configuration, absent from the manifest's keys"
                for key, value in configuration.items() if key not in keys and key not in NOT_KEYS]
    for key, value in keys.items():
        if key not in configuration:
            if not re.search(rf"\b{re.escape(key)}\b", added):
                problems.append(f"key '{key}' is {value!r} in the manifest, absent from the results file")
        elif not _same(configuration[key], value):
            problems.append(f"key '{key}' is {value!r} in the manifest, {configuration[key]!r} in the results file")
    return problems


def norm_problems(name, times, values, completed_healthy):
    """Why a column of /errors is not a norm's record, or '': negative or
    infinite values never are; NaN is the record of no measure (before a
    quantity can be measured, as a period before its first crossing, or after
    a run stopped or lost its solution), so in a completed healthy run a NaN
    after a finite value is damage."""
    bad = (values < 0.0) | np.isinf(values)
    if completed_healthy:
        measured = np.isfinite(values)
        bad |= np.isnan(values) & (np.cumsum(measured) > 0)
    if not np.any(bad):
        return ""
    first = int(np.argmax(bad))
    return (f"/errors/{name} is {values[first]:g} at t = {times[first]:g}, not a norm "
            f"(finite and >= 0{', no NaN after a value in a completed run' if completed_healthy else ''})")


def error_problems(results, status):
    """Problems of /errors: a time axis that does not increase, values that are no norm's."""
    times = results.error_times
    problems = []
    if np.any(~np.isfinite(times)) or np.any(np.diff(times) <= 0):
        problems.append("/errors/time does not increase strictly")
    healthy = status == "completed" and results.attributes.get("health") != "solution lost"
    problems += [p for p in (norm_problems(n, times, v, healthy) for n, v in results.errors.items()) if p]
    return problems


# How far a stored L1_<line> column may lie from eq. 3.1 recomputed here from
# the line's own arrays: the two are one sum in another order (measured
# agreement about 1e-16), so anything wider is an edited file; below that,
# the differences q_sim - q_exact themselves carry the round-off of the
# values they are taken from (a few spacings of the largest |q|, as an error
# at round-off is: conftest.roundoff_cases).
STORED_NORM_TOLERANCE = 1e-9
ROUNDOFF_SPACINGS = 4


def probe_norm_problems(path, results):
    """The L1_<line> columns of /errors that eq. 3.1 on /probes/<line> does not give."""
    from . import norms, probes  # probes reads results, which imports this module
    try:
        lines = probes.read_probe_lines(path)
    except (OSError, KeyError, ValueError, TypeError):
        return []  # a damaged probe group: the figures say why; the norms are checked above
    problems = []
    for line in lines:
        stored = results.errors.get("L1_" + line.name)
        if stored is None:
            continue
        stored = np.asarray(stored, float)
        simulated, exact = np.atleast_2d(line.simulated)[: stored.size], np.atleast_2d(line.exact)[: stored.size]
        recomputed = norms.probe_line_l1(simulated, exact)
        if recomputed.shape != stored.shape:
            problems.append(f"/errors/L1_{line.name} has {stored.size} rows, /probes/{line.name} {recomputed.size}")
            continue
        with np.errstate(invalid="ignore"):
            size = np.fmax(np.nanmax(np.abs(simulated), axis=-1, initial=0.0),
                           np.nanmax(np.abs(exact), axis=-1, initial=0.0))
        allowed = (STORED_NORM_TOLERANCE * np.fmax(np.abs(stored), np.abs(recomputed)) +
                   ROUNDOFF_SPACINGS * np.finfo(float).eps * size)
        difference = np.abs(stored - recomputed)
        both_nan = np.isnan(stored) & np.isnan(recomputed)
        bad = ~both_nan & ~(difference <= allowed)
        if np.any(bad):
            k = int(np.argmax(bad))
            problems.append(f"/errors/L1_{line.name} is not eq. 3.1 of /probes/{line.name} (at row {k}: "
                            f"{stored[k]:.6g} stored, {recomputed[k]:.6g} from the probes)")
    return problems


def case_problems(entry, status, results):
    """One-line problems of a case whose file was read (`results`, results.CaseResults)."""
    file_status = results.attributes.get("status")
    if file_status not in RESULT_STATUSES:
        return [f"the results file's status is {file_status!r}, none of {', '.join(RESULT_STATUSES)}"]
    problems = []
    manifest_status = entry.get("status")
    if manifest_status in ENDED and file_status != manifest_status and \
            not (manifest_status == "completed" and file_status == "lost"):
        problems.append(f"the manifest says {manifest_status}, the results file {file_status}")
    problems += key_problems(entry, results.attributes)
    problems += error_problems(results, status)
    return problems


def being_written(directory):
    """Whether `mpmvv suite` is writing `directory` now: it holds an exclusive
    flock on DIR/.lock while it runs (tools/app/suite/run.cpp)."""
    lock = Path(directory) / ".lock"
    try:
        descriptor = os.open(lock, os.O_RDONLY | os.O_NONBLOCK)
    except OSError:
        return False
    try:
        fcntl.flock(descriptor, fcntl.LOCK_SH | fcntl.LOCK_NB)
        return False
    except BlockingIOError:
        return True
    except OSError:
        return False
    finally:
        os.close(descriptor)


def suite_problems(manifest, suite_text, suite_file, cases, directory):
    """Problems of the directory as a whole: a suite still writing it, cases
    twice, suite.toml another suite's."""
    problems = []
    if being_written(directory):
        problems.append("mpmvv suite is still writing this directory (it holds .lock): its cases may change; "
                        "judge it when the suite has ended")
    seen_ids, seen_paths, seen_keys = set(), {}, {}
    for case in cases:
        if case.id in seen_ids:
            problems.append(f"case '{case.id}' is listed twice in the manifest")
        seen_ids.add(case.id)
        try:
            # (A case whose path was refused has none to share.)
            where = case.results_path.resolve() if not case.problems else None
        except (OSError, RuntimeError):
            where = None
        if where is not None and where in seen_paths:
            problems.append(f"cases '{seen_paths[where]}' and '{case.id}' name one results file")
        elif where is not None:
            seen_paths[where] = case.id
        signature = (case.study, repr(sorted(case.keys.items())))
        if case.keys and signature in seen_keys:
            problems.append(f"cases '{seen_keys[signature]}' and '{case.id}' of study '{case.study}' have the "
                            "same keys")
        seen_keys.setdefault(signature, case.id)
    name, suite_path = manifest.get("suite"), manifest.get("suite_file")
    if isinstance(suite_path, str) and suite_path and name is not None and name != Path(suite_path).stem:
        problems.append(f"the manifest's suite is {name!r}, and its suite_file {suite_path!r} names the suite "
                        f"'{Path(suite_path).stem}' (mpmvv suite names a suite by its file)")
    if manifest.get("tier") == "ci":
        problems += _ci_tier_problems(suite_file, cases)
    recorded = manifest.get("suite_text")
    if suite_text is not None and isinstance(recorded, str) and recorded != suite_text:
        problems.append("suite.toml is not the suite file the manifest ran (its text differs from the "
                        "manifest's 'suite_text')")
    elif suite_text is not None and recorded is None:
        # A manifest written before it recorded the suite's text: the studies must at least agree.
        names = {s.get("name") for s in suite_file.get("study", []) if isinstance(s, dict)}
        strangers = sorted({c.study for c in cases} - names)
        if strangers:
            problems.append(f"suite.toml has no study {', '.join(repr(s) for s in strangers)} of the manifest's "
                            "cases: it is another suite's")
    return problems


def _ci_tier_problems(suite_file, cases):
    """Why a manifest of the ci tier is not one suite.toml can run: the suite
    says it has none ([ci] skip), or a case's study has no `ci` table (such a
    study does not run in that tier, tools/app/suite/study.cpp)."""
    ci = suite_file.get("ci")
    if isinstance(ci, dict) and "skip" in ci:
        return [f"the manifest's tier is 'ci', and suite.toml has no ci tier ([ci] skip = {ci['skip']!r})"]
    tables = {s.get("name"): s for s in suite_file.get("study", []) if isinstance(s, dict)}
    without = [s for s in dict.fromkeys(c.study for c in cases) if s in tables and "ci" not in tables[s]]
    if without:
        return [f"the manifest's tier is 'ci', and study {', '.join(repr(s) for s in without)} of suite.toml has "
                "no `ci` table: it does not run in the ci tier"]
    return []


def suite_expectations(suite_file, tier):
    """The [[expect]] tables suite.toml gives in `tier`, as mpmvv suite records
    them in the manifest (tools/app/suite/expectations.cpp: an expectation
    without `tier` is the full study's; `tier` names a tier or lists them)."""
    chosen = []
    for expect in suite_file.get("expect", []):
        if not isinstance(expect, dict):
            continue
        tiers = expect.get("tier", "full")
        tiers = [tiers] if isinstance(tiers, str) else tiers if isinstance(tiers, list) else []
        if tier in tiers:
            chosen.append(expect)
    return chosen


def _equal(a, b):
    if isinstance(a, bool) or isinstance(b, bool):
        return type(a) is type(b) and a == b
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        # (the manifest's numbers are toml++'s JSON text of the same doubles)
        return a == b or math.isclose(a, b, rel_tol=1e-12, abs_tol=0.0)
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_equal(a[k], b[k]) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_equal(x, y) for x, y in zip(a, b))
    return type(a) is type(b) and a == b


def expectation_problem(recorded, stated, tier):
    """Why the manifest's expectations (`recorded`) are not the [[expect]]
    tables suite.toml states for the tier (`stated`, suite_expectations), or ''."""
    if len(recorded) != len(stated):
        return (f"records {len(recorded)} expectation(s), and suite.toml's [[expect]] tables give {len(stated)} "
                f"in the {tier} tier: the expectations are not the suite's")
    for number, (mine, theirs) in enumerate(zip(recorded, stated), start=1):
        if _equal(mine, theirs):
            continue
        differ = sorted(k for k in set(mine) | set(theirs)
                        if k not in mine or k not in theirs or not _equal(mine[k], theirs[k]))
        shown = lambda table, k: repr(table[k]) if k in table else "absent"  # noqa: E731
        parts = [f"'{k}' is {shown(mine, k)} in the manifest, {shown(theirs, k)} in suite.toml" for k in differ]
        return f"expectation {number} is not suite.toml's [[expect]] {number}: " + "; ".join(parts)
    return ""
