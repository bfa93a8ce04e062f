"""Requirements of the report for a suite with an external program's study
(external_command): one work-precision figure sets every study's cases side by
side, and it is drawn only then; the case table says who took the steps and
which health rules judged the program's run."""
import h5py

from . import report
from .conftest import RING_TIMES, write_suite_directory
from .report_tables import case_table
from .results import read_suite

SUITE = """description = "an external program's study beside mpmvv's own"

[[study]]
name = "theirs"
scene = "scenes/ring.toml"
set = { external_command = "their-mpm {input}" }
sweep = { cells = [32, 64, 128] }

[[study]]
name = "ours"
scene = "scenes/ring.toml"
sweep = { cells = [32, 64, 128] }
"""


def cases(external=True):
    out = []
    for study, factor in (("theirs", 2.0), ("ours", 1.0)):
        for cells in (32, 64, 128):
            h = 3.0 / cells
            keys = {"method": "cpdi", "cells": cells, "end_time": 1.0, "output_times": RING_TIMES}
            if study == "theirs" and external:
                keys["external_command"] = "their-mpm {input}"
            errors = {n: [factor * h * h * t for t in RING_TIMES] for n in ("L1_theta0", "particle_L1", "particle_L2")}
            out.append({"id": f"{study}-cells={cells}", "study": study, "keys": keys, "status": "completed", "h": h,
                        "times": RING_TIMES, "errors": errors})
    return out


def test_one_figure_sets_the_external_study_beside_the_others(tmp_path):
    directory = write_suite_directory(tmp_path / "suite", SUITE, cases())
    written, _ = report.write_report(directory, tmp_path / "report")
    assert (tmp_path / "report" / "figures" / "suite-work-precision.png").is_file()
    markdown = written["markdown"].read_text()
    assert "the external program's (theirs" in markdown
    # The case table's steps column: "external program" for theirs, a count for ours.
    rows = [r for r in written["html"].read_text().split("<tr") if "-cells=" in r and "<td>completed</td>" in r]
    assert len(rows) == 6
    assert all(("<td>external program</td>" in r) == ("<td>theirs-" in r) for r in rows)


def test_no_comparison_figure_without_an_external_study(tmp_path):
    directory = write_suite_directory(tmp_path / "suite", SUITE.replace('set = { external_command = "their-mpm {input}" }\n', ""),
                                      cases(external=False))
    report.write_report(directory, tmp_path / "report")
    assert not (tmp_path / "report" / "figures" / "suite-work-precision.png").exists()


def test_the_case_table_says_which_health_rules_judged_an_external_run(tmp_path):
    """Requirement: the case table's health column gives every case's verdict and,
    for a run by another program, which rules its output let mpmvv judge (the J
    ratio only with F, J or volumes; never the energy balance) and whether mpmvv
    placed the probe lines' tracers."""
    directory = write_suite_directory(tmp_path / "suite", SUITE, cases())
    for cells, j_rule, tracers in ((32, "applied", "written by the program (tracer_position)"),
                                   (64, "not applied: the program gave no F, J or volume",
                                    "interpolated by mpmvv from the particles (...)")):
        with h5py.File(directory / "cases" / f"theirs-cells={cells}.h5", "a") as f:
            f.attrs["health"] = "healthy"
            g = f.create_group("external")
            g.attrs["J_rule"], g.attrs["tracers"] = j_rule, tracers
    with h5py.File(directory / "cases" / "ours-cells=32.h5", "a") as f:
        f.attrs["health"] = "healthy"
    table = case_table(read_suite(directory))
    health = {r[0]: r[table.headers.index("health")] for r in table.rows}
    assert health["theirs-cells=32"] == "healthy (judged: J ratio, norms; not judged: energy balance)"
    assert health["theirs-cells=64"] == ("healthy (judged: norms; not judged: energy balance, J ratio (no F, J or "
                                         "volume); tracers placed by mpmvv)")
    assert health["ours-cells=32"] == "healthy"
    assert health["theirs-cells=128"] == "-"  # no verdict in the file
