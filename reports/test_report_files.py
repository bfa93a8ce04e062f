"""Requirements of what `mpmvv report -o OUT` leaves on disk: it replaces the
figures an earlier report wrote in OUT/figures and nothing else there (a
user's own picture stays), and its JSON files are whole or absent."""
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
