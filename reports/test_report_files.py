"""Requirements of what `mpmvv report -o OUT` leaves on disk: it replaces the
figures an earlier report wrote in OUT/figures and nothing else there (a
user's own picture stays), its pages and JSON files are whole or absent, and
a report the disk stopped leaves no empty folder."""
from . import report
from .conftest import SYNTHETIC_SUITE, synthetic_ring_cases, write_suite_directory


def test_a_second_report_replaces_its_own_figures_and_keeps_the_users(tmp_path):
    directory = write_suite_directory(tmp_path / "suite", SYNTHETIC_SUITE, synthetic_ring_cases())
    out = tmp_path / "out"
    report.write_report(directory, out)
    figures = out / "figures"
    first = sorted(p.name for p in figures.glob("*.png"))
    assert first, "the report writes figures"
    listed = (figures / report.FIGURE_LIST).read_text().split()
    assert sorted(listed) == first
    (figures / "mine.png").write_bytes(b"\x89PNG a picture of the user's")
    stale = figures / first[0]
    stale.write_bytes(b"an earlier report's figure")
    report.write_report(directory, out)
    assert (figures / "mine.png").read_bytes() == b"\x89PNG a picture of the user's"
    assert stale.read_bytes() != b"an earlier report's figure"
    assert "mine.png" not in (figures / report.FIGURE_LIST).read_text().split()
    assert not list(figures.glob(".*.tmp")) and not list(out.glob(".*.tmp"))


def test_a_report_that_cannot_be_written_leaves_no_empty_folder(tmp_path, monkeypatch):
    """Requirement: a report stopped by the disk (here: ENOSPC while it builds)
    leaves no empty figures/ behind, and nothing under report.html's name."""
    import errno

    directory = write_suite_directory(tmp_path / "suite", SYNTHETIC_SUITE, synthetic_ring_cases())

    def full(*_):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(report, "build_report", full)
    out = tmp_path / "out"
    try:
        report.write_report(directory, out)
    except OSError:
        pass
    assert not (out / "figures").exists() and not (out / "report.html").exists()


def test_an_empty_output_or_no_suite_file_is_refused(tmp_path, capsys):
    """Requirement: `mpmvv report DIR -o ''` is refused (it would write into the
    current directory's place, or DIR/report, unasked), and a directory without
    suite.toml is refused as the gate refuses it: exit 2, one line, no report."""
    directory = write_suite_directory(tmp_path / "suite", SYNTHETIC_SUITE, synthetic_ring_cases())
    assert report.main([str(directory), "-q", "-o", ""]) == 2
    err = capsys.readouterr().err
    assert "-o '': an empty directory name" in err and err.count("\n") == 1
    assert not (directory / "report").exists()
    (directory / "suite.toml").unlink()
    assert report.main([str(directory), "-q", "-o", str(tmp_path / "r")]) == 2
    err = capsys.readouterr().err
    assert "suite.toml: missing" in err and err.count("\n") == 1
    assert not (tmp_path / "r" / "report.html").exists()
