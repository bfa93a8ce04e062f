"""The gate's JUnit and JSON files (reports/gate_files.py) say what its table
says: one test case per expectation and series, failed with the reasons, the
numbers of each row; read back by a JUnit consumer's parse (xml.etree) and by
json with no NaN."""
import json
import math
import xml.etree.ElementTree as ET

from . import gate
from .conftest import SYNTHETIC_SUITE, synthetic_ring_cases, write_suite_directory
from .results import read_suite
from .test_gate import MORE_EXPECTATIONS


def test_junit_and_json_hold_every_verdict_with_its_numbers(tmp_path, capsys):
    """Requirement: `mpmvv gate DIR --junit F --json G` writes one <testcase>
    per (expectation, series), a <failure> for each that fell short with the
    table's reasons, counts that match, and JSON with every level's h and
    error and the fitted order, non-finite numbers as null; the exit status
    and table are those of the gate without the files."""
    directory = write_suite_directory(tmp_path / "suite", SYNTHETIC_SUITE + MORE_EXPECTATIONS, synthetic_ring_cases())
    junit, record = tmp_path / "gate.xml", tmp_path / "gate.json"
    plain = gate.main([str(directory)])
    table = capsys.readouterr().out
    status = gate.main([str(directory), "--junit", str(junit), "--json", str(record)])
    assert (status, capsys.readouterr().out) == (plain, table) == (1, table)
    verdicts = gate.gate(read_suite(directory))

    root = ET.parse(junit).getroot()
    assert root.tag == "testsuites"
    (suite,) = root.findall("testsuite")
    cases = suite.findall("testcase")
    assert len(cases) == len(verdicts) == int(suite.get("tests")) == 5
    failed = [c for c in cases if c.find("failure") is not None]
    assert len(failed) == sum(not v.passed for v in verdicts) == int(suite.get("failures")) == 3
    for case, verdict in zip(cases, verdicts):
        assert case.get("name").startswith(f"#{verdict.number} {verdict.expectation['norm']}")
        failure = case.find("failure")
        assert (failure is None) == verdict.passed
        if failure is not None:
            assert failure.get("message") == "; ".join(verdict.reasons)
        properties = {p.get("name"): p.get("value") for p in case.find("properties")}
        assert properties["observed order [95% CI]"] == gate.verdict_row(verdict)[6]

    data = json.loads(record.read_text(), parse_constant=lambda c: pytest_fail(f"non-JSON number {c}"))
    assert data["holds"] is False and data["expectations"] == 4 and len(data["verdicts"]) == 5
    for entry, verdict in zip(data["verdicts"], verdicts):
        assert entry["status"] == ("pass" if verdict.passed else "fail")
        assert entry["reasons"] == list(verdict.reasons)
        for level, kept in zip(entry["levels"], verdict.levels):
            assert level["h"] == finite_or_none(kept.h)
            assert level["error"] == finite_or_none(kept.error)
            assert level["used"] == (not kept.reason)
        fit = verdict.fit.order
        if entry["observed"]["order"] is not None:
            assert entry["observed"]["order"] == fit
    single = next(e for e in data["verdicts"] if "1 usable level(s), need 2" in "; ".join(e["reasons"]))
    assert single["observed"]["order"] is None and single["observed"]["ci_low"] is None


def test_an_unwritable_file_is_exit_2_with_one_line(tmp_path, capsys):
    directory = write_suite_directory(tmp_path / "suite", SYNTHETIC_SUITE, synthetic_ring_cases())
    status = gate.main([str(directory), "--junit", str(tmp_path / "missing" / "gate.xml")])
    err = capsys.readouterr().err
    assert status == 2 and err.count("\n") == 1 and "cannot write" in err and "gate.xml" in err


def finite_or_none(x):
    return x if math.isfinite(x) else None


def pytest_fail(message):
    raise AssertionError(message)


def test_a_failed_write_is_exit_2_naming_the_file(tmp_path, capsys, monkeypatch):
    """Requirement: a --json or --junit file the disk refuses (ENOSPC, as
    /dev/full gives) is exit 2 with one line naming it, never exit 0; an empty
    file name is refused."""
    import errno

    from . import gate_files
    directory = write_suite_directory(tmp_path / "suite", SYNTHETIC_SUITE, synthetic_ring_cases())

    def full(*_):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(gate_files, "write_atomically", full)
    for option in ("--json", "--junit"):
        status = gate.main([str(directory), option, str(tmp_path / "verdicts")])
        err = capsys.readouterr().err
        assert status == 2 and err.count("\n") == 1, err
        assert f"cannot write {tmp_path / 'verdicts'}: No space left on device" in err
        status = gate.main([str(directory), option, ""])
        err = capsys.readouterr().err
        assert status == 2 and f"{option} '': an empty file name" in err


def test_a_device_or_fifo_is_written_to_not_replaced(tmp_path):
    """Requirement: a --json path that is not a regular file (a FIFO, /dev/stdout,
    /dev/full) is written to in place: it is never replaced by a regular file (the
    atomic rename would have turned /dev/full into one), and its write error is
    raised."""
    import os
    import stat
    import threading

    from .gate_files import write_atomically
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    received = []
    reader = threading.Thread(target=lambda: received.append(fifo.read_text()))
    reader.start()
    write_atomically(fifo, "{}\n")
    reader.join(10)
    assert received == ["{}\n"] and stat.S_ISFIFO(fifo.stat().st_mode)
    full = "/dev/full"
    if os.path.exists(full) and stat.S_ISCHR(os.stat(full).st_mode):
        try:
            write_atomically(full, "x" * 10000)
        except OSError as error:
            assert error.errno == 28
        else:
            raise AssertionError("a write to /dev/full raised nothing")
        assert stat.S_ISCHR(os.stat(full).st_mode)
