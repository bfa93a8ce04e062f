"""Requirements of the checks the gate and the report make before they judge
(reports/consistency.py): a suite directory whose results are not their cases'
(a file's status, its keys, a case twice, its time axis, its norms' values,
a path outside the directory, another suite's suite.toml) never gives PASS:
`mpmvv gate` exits 1 and `mpmvv report` exits 1, each naming the case and
what is wrong; a manifest whose expectations cannot be read exits 2 with one
line. The synthetic suite without a fault passes (exit 0 from both)."""
import json
import os

import h5py
import numpy as np
import pytest

from . import gate
from . import report
from .conftest import SYNTHETIC_SUITE, synthetic_ring_cases, write_suite_directory

CASE = "ring-method=cpdi-cells=64"          # a case the gate's expectation reads
OTHER = "ring-method=cpdi-cells=32"


def manifest_of(directory):
    return json.loads((directory / "manifest.json").read_text())


def rewrite_manifest(directory, change):
    manifest = manifest_of(directory)
    change(manifest)
    (directory / "manifest.json").write_text(json.dumps(manifest))


def entry(manifest, case_id=CASE):
    return next(e for e in manifest["cases"] if e["id"] == case_id)


def set_entry(key, value, case_id=CASE):
    return lambda d: rewrite_manifest(d, lambda m: entry(m, case_id).__setitem__(key, value))


def with_results(change, case_id=CASE):
    def apply(directory):
        with h5py.File(directory / "cases" / f"{case_id}.h5", "a") as f:
            change(f)
    return apply


def replace_column(name, values, dtype=float):
    def change(f):
        del f["errors"][name]
        f["errors"][name] = np.asarray(values, dtype=dtype)
    return with_results(change)


def configuration_with(key, value):
    def change(f):
        text = f.attrs["configuration"]
        f.attrs["configuration"] = "\n".join(f"{key} = {value}" if line.startswith(f"{key} =") else line
                                            for line in text.splitlines()) + "\n"
    return with_results(change)


def duplicate_case(directory):
    rewrite_manifest(directory, lambda m: m["cases"].append(dict(entry(m))))


def a_fifo(directory):
    path = directory / "cases" / f"{CASE}.h5"
    path.unlink()
    os.mkfifo(path)


def a_directory(directory):
    path = directory / "cases" / f"{CASE}.h5"
    path.unlink()
    path.mkdir()


def a_symlink_loop(directory):
    path = directory / "cases" / f"{CASE}.h5"
    path.unlink()
    path.symlink_to(path.name)


def a_link_outside(directory):
    outside = directory.parent / "outside.h5"
    path = directory / "cases" / f"{CASE}.h5"
    path.rename(outside)
    path.symlink_to(outside)


def another_suite_file(directory):
    (directory / "suite.toml").write_text(SYNTHETIC_SUITE.replace('name = "ring"', 'name = "bar"'))


def another_suite_text(directory):
    rewrite_manifest(directory, lambda m: m.__setitem__("suite_text", "description = 'another'\n"))


def drop_key(key, case_id=CASE):
    return lambda d: rewrite_manifest(d, lambda m: entry(m, case_id)["keys"].pop(key))


# (name, how the directory is damaged, what the problem line must say)
INCONSISTENT = [
    ("file-without-status", with_results(lambda f: f.attrs.__delitem__("status")), "status is None"),
    ("file-status-bogus", with_results(lambda f: f.attrs.__setitem__("status", "bogus")), "'bogus'"),
    ("manifest-status-bogus", set_entry("status", "bogus"), "status 'bogus'"),
    ("statuses-disagree", with_results(lambda f: f.attrs.__setitem__("status", "failed")),
     "manifest says completed, the results file failed"),
    ("cells-differ", configuration_with("cells", "16"), "key 'cells' is 64 in the manifest, 16"),
    ("cells-as-text", configuration_with("cells", '"64"'), "key 'cells'"),
    ("key-missing", with_results(lambda f: f.attrs.__setitem__("configuration", "cells = 64\n")), "key 'method'"),
    ("configuration-not-toml", with_results(lambda f: f.attrs.__setitem__("configuration", "= =")), "not TOML"),
    ("case-listed-twice", duplicate_case, "listed twice"),
    ("another-case-file", set_entry("results", f"cases/{OTHER}.h5"), "64 in the manifest, 32 in the results file"),
    ("time-decreasing", replace_column("time", [1.0, 0.5, 0.25]), "does not increase"),
    ("negative-error", replace_column("L1_theta0", [-1e-3, 1e-3, 1e-3]), "is -0.001"),
    ("infinite-error", replace_column("L1_theta0", [1e-3, np.inf, 1e-3]), "is inf"),
    ("nan-after-a-value", replace_column("L1_theta0", [1e-3, np.nan, 1e-3]), "is nan"),
    ("text-error-column", replace_column("L1_theta0", [b"1e-3"] * 3, dtype="S8"), "unreadable"),
    ("two-dimensional-column", replace_column("L1_theta0", np.ones((3, 2))), "unreadable"),
    ("results-absolute", set_entry("results", "/etc/passwd"), "absolute path"),
    ("results-outside", set_entry("results", "../../../../etc/passwd"), "outside the suite directory"),
    ("results-null", set_entry("results", None), "'results' is None"),
    ("results-a-fifo", a_fifo, "not a regular file"),
    ("results-a-directory", a_directory, "not a regular file"),
    ("results-a-symlink-loop", a_symlink_loop, "cannot be resolved"),
    ("results-linked-outside", a_link_outside, "outside the suite directory"),
    ("id-a-path", set_entry("id", "../../../x"), "is not a name"),
    ("completed-without-file", lambda d: (d / "cases" / f"{CASE}.h5").unlink(), "no results file"),
    ("another-suite-toml", another_suite_file, "another suite's"),
    ("suite-text-differs", another_suite_text, "not the suite file the manifest ran"),
    # A hostile-user corpus (#431, #378, #384, #385, #396, #429):
    ("results-with-nul", set_entry("results", "cases/x.h5\u0000junk"), "holds a control character"),
    ("id-not-its-keys", set_entry("id", "ring-method=cpdi-cells=99"), "says cells=99, its keys cells = 64"),
    ("id-not-its-study", set_entry("id", "bar-method=cpdi-cells=64"), "does not begin with its study's name"),
    ("completed-with-a-crash-exit", set_entry("exit_code", 139), "completed with exit code 139"),
    ("exit-code-not-a-number", set_entry("exit_code", "0"), "exit_code is '0', not an integer"),
    ("wall-time-negative", set_entry("wall_time_s", -1.0), "wall_time_s is -1.0, not a time"),
    ("wall-time-text", set_entry("wall_time_s", "1"), "wall_time_s is '1', not a time"),
    ("key-dropped-from-manifest", drop_key("amplitude"),
     "key 'amplitude' is 0.5 in the results file's configuration, absent from the manifest's keys"),
    ("errors-not-its-probes", with_results(lambda f: f["errors"]["L1_theta0"].__setitem__(
        slice(None), 0.9 * f["errors"]["L1_theta0"][...])), "/errors/L1_theta0 is not eq. 3.1 of /probes/theta0 (at row 0"),
    ("suite-named-otherwise", lambda d: rewrite_manifest(d, lambda m: m.__setitem__("suite", "other")),
     "the manifest's suite is 'other', and its suite_file 'suites/synthetic.toml' names the suite 'synthetic'"),
]
NOT_A_CASE = ("another-suite-toml", "suite-text-differs", "suite-named-otherwise")


@pytest.fixture
def suite_directory(tmp_path):
    return write_suite_directory(tmp_path / "suite", SYNTHETIC_SUITE, synthetic_ring_cases())


def outcome(main, arguments, capsys):
    status = main(arguments)
    captured = capsys.readouterr()
    return status, captured.out + captured.err


def test_the_undamaged_suite_passes(suite_directory, tmp_path, capsys):
    """Requirement: the checks find nothing in a directory as mpmvv suite writes it."""
    assert outcome(gate.main, [str(suite_directory)], capsys)[0] == 0
    assert outcome(report.main, [str(suite_directory), "-q", "-o", str(tmp_path / "r")], capsys)[0] == 0


@pytest.mark.parametrize("name, damage, said", INCONSISTENT, ids=[c[0] for c in INCONSISTENT])
def test_results_not_their_cases_fail_the_gate_and_the_report(suite_directory, tmp_path, capsys, name, damage,
                                                             said):
    """Requirement: every damaged directory gives FAIL (gate exit 1), the report
    exits 1 and says so first, and the line names the case (or suite.toml) and
    what is wrong; nothing is read outside the directory."""
    damage(suite_directory)
    status, text = outcome(gate.main, [str(suite_directory)], capsys)
    assert status == 1, text
    assert said in text, text
    assert "Traceback" not in text
    if name not in NOT_A_CASE:
        assert "case '" in text
    if name != "completed-without-file":
        assert "has no results file" not in text   # a refused path is not also a missing file
    status, text = outcome(report.main, [str(suite_directory), "-q", "-o", str(tmp_path / "r")], capsys)
    assert status == 1, text
    assert said in text
    page = (tmp_path / "r" / "report.html").read_text()
    assert "Verdict: FAIL" in page and "not their cases&#x27;" in page
    summary = json.loads((tmp_path / "r" / "summary.json").read_text())
    assert summary["problems"] and summary["gate"]["holds"] is False


def test_a_damaged_case_gives_none_of_its_numbers(suite_directory):
    """Requirement: a case whose results are not its own is read as having none."""
    from .results import read_suite
    replace_column("L1_theta0", [-1e-3, 1e-3, 1e-3])(suite_directory)
    case = next(c for c in read_suite(suite_directory).cases if c.id == CASE)
    assert case.results is None and case.problems and not case.completed


def test_junit_and_json_carry_the_problems(suite_directory, tmp_path, capsys):
    """Requirement: the CI files fail too: JUnit a failing test case listing the
    problems, JSON holds = false with them."""
    set_entry("results", "/etc/passwd")(suite_directory)
    junit, record = tmp_path / "gate.xml", tmp_path / "gate.json"
    status, _ = outcome(gate.main, [str(suite_directory), "--junit", str(junit), "--json", str(record)], capsys)
    assert status == 1
    assert "results match their cases" in junit.read_text() and "absolute path" in junit.read_text()
    data = json.loads(record.read_text())
    assert data["holds"] is False and any("absolute path" in p for p in data["problems"])


BAD_EXPECTATIONS = [
    ({"order": "two"}, "'order' is 'two', not a number"),
    ({"tolerance": None}, "'tolerance' is null"),
    ({"where": ["method"]}, "'where' is ['method'], not a table"),
    ({"levels": 64}, "'levels' is 64, not an array"),
    ({"max_error": True}, "'max_error' is True, not a number"),
    ({"study": 5}, "'study' is 5, not text"),
]


@pytest.mark.parametrize("change, said", BAD_EXPECTATIONS, ids=[str(c[0]) for c in BAD_EXPECTATIONS])
def test_a_manifest_expectation_that_cannot_be_read_is_one_line(suite_directory, tmp_path, capsys, change, said):
    """Requirement: an expectation edited into something the gate cannot compute
    with is refused with one line (exit 2), by the gate and the report, never a traceback."""
    rewrite_manifest(suite_directory, lambda m: m["expectations"][0].update(change))
    for main, arguments in ((gate.main, [str(suite_directory)]),
                            (report.main, [str(suite_directory), "-q", "-o", str(tmp_path / "r")])):
        status, text = outcome(main, arguments, capsys)
        assert status == 2, text
        assert said in text and "expectation 1" in text
        assert len(text.strip().splitlines()) == 1


def test_a_directory_a_suite_is_still_writing_is_not_judged(suite_directory, capsys):
    """Requirement: while mpmvv suite holds DIR/.lock the gate does not pass it."""
    import fcntl
    with open(suite_directory / ".lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        status, text = outcome(gate.main, [str(suite_directory)], capsys)
    assert status == 1 and "still writing this directory" in text
    assert outcome(gate.main, [str(suite_directory)], capsys)[0] == 0


def test_a_fifo_as_manifest_is_refused_at_once(suite_directory, capsys):
    """Requirement: a FIFO where the manifest should be is not opened (it would block)."""
    (suite_directory / "manifest.json").unlink()
    os.mkfifo(suite_directory / "manifest.json")
    status, text = outcome(gate.main, [str(suite_directory)], capsys)
    assert status == 2 and "not a regular file" in text


def raw_manifest(change):
    def apply(directory):
        path = directory / "manifest.json"
        path.write_text(change(path.read_text()))
    return apply


def expectations(change):
    return lambda d: rewrite_manifest(d, lambda m: change(m["expectations"]))


def linked_outside(name):
    def apply(directory):
        outside = directory.parent / f"outside-{name}"
        (directory / name).rename(outside)
        (directory / name).symlink_to(outside)
    return apply


def widened(expects):
    expects[0]["tolerance"] = 100


# (name, how the directory is damaged, what the one line must say): refused, exit 2.
REFUSED = [
    ("tolerance-widened-in-the-manifest", expectations(widened),
     "expectation 1 is not suite.toml's [[expect]] 1: 'tolerance' is 100 in the manifest, 0.1 in suite.toml"),
    ("bound-added-in-the-manifest", expectations(lambda e: e[0].update(max_error=1.0)),
     "'max_error' is 1.0 in the manifest, absent in suite.toml"),
    ("expectations-dropped", expectations(lambda e: e.clear()),
     "records 0 expectation(s), and suite.toml's [[expect]] tables give 1 in the full tier"),
    ("expectation-added", expectations(lambda e: e.append(dict(e[0]))),
     "records 2 expectation(s), and suite.toml's [[expect]] tables give 1"),
    ("ci-tier-of-a-suite-without-one", lambda d: rewrite_manifest(d, lambda m: m.__setitem__("tier", "ci")),
     "give 0 in the ci tier"),
    ("duplicate-json-key", raw_manifest(lambda t: t.replace('"suite": "synthetic"',
                                                            '"suite": "synthetic", "suite": "synthetic"')),
     "the key 'suite' is given twice"),
    ("nan-literal", raw_manifest(lambda t: t.replace('"wall_time_s": 1.0', '"wall_time_s": NaN', 1)),
     "NaN is not JSON"),
    ("infinity-literal", raw_manifest(lambda t: t.replace('"wall_time_s": 1.0', '"wall_time_s": -Infinity', 1)),
     "-Infinity is not JSON"),
    ("manifest-linked-outside", linked_outside("manifest.json"), "manifest.json: a symlink to"),
    ("suite-toml-linked-outside", linked_outside("suite.toml"), "suite.toml: a symlink to"),
    ("suite-toml-deleted", lambda d: (d / "suite.toml").unlink(), "suite.toml: missing"),
]


@pytest.mark.parametrize("name, damage, said", REFUSED, ids=[c[0] for c in REFUSED])
def test_a_manifest_that_is_not_its_suites_is_refused(suite_directory, tmp_path, capsys, name, damage, said):
    """Requirement: expectations that are not the [[expect]] tables suite.toml
    states for the tier (a band widened, a bound added, an expectation added or
    dropped), a manifest JSON reads two ways (a key twice, NaN or Infinity), and
    a manifest.json or suite.toml outside the directory (or none) are refused by
    the gate and the report alike, with one line naming the item (exit 2)."""
    damage(suite_directory)
    for main, arguments in ((gate.main, [str(suite_directory)]),
                            (report.main, [str(suite_directory), "-q", "-o", str(tmp_path / "r")])):
        status, text = outcome(main, arguments, capsys)
        assert status == 2, text
        assert said in text, text
        assert len(text.strip().splitlines()) == 1 and "Traceback" not in text
    assert not (tmp_path / "r" / "report.html").exists()


def test_expectations_of_the_tier_are_the_suites(suite_directory, capsys):
    """Requirement: the manifest's expectations are compared with those of its
    tier (an [[expect]] without `tier` is the full study's, one with `tier`
    lists its tiers), keys in any order, 2 and 2.0 the same number."""
    from .consistency import expectation_problem, suite_expectations
    suite_file = {"expect": [{"study": "a", "norm": "n", "order": 2, "tolerance": 0.5},
                             {"study": "a", "norm": "n", "max_error": 1.0, "tier": ["full", "ci"]},
                             {"study": "a", "norm": "n", "max_error": 2.0, "tier": "ci"}]}
    assert [e.get("max_error") for e in suite_expectations(suite_file, "full")] == [None, 1.0]
    assert [e.get("max_error") for e in suite_expectations(suite_file, "ci")] == [1.0, 2.0]
    recorded = [{"tolerance": 0.5, "order": 2.0, "norm": "n", "study": "a"},
                {"tier": ["full", "ci"], "max_error": 1, "norm": "n", "study": "a"}]
    assert expectation_problem(recorded, suite_expectations(suite_file, "full"), "full") == ""
    recorded[1]["must_complete"] = False
    assert "'must_complete' is False in the manifest, absent" in \
        expectation_problem(recorded, suite_expectations(suite_file, "full"), "full")
