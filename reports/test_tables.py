"""Requirements of the convergence tables: an error that is exactly C h^2
gives observed order 2 between every pair of meshes, an error at round-off
gives none, and a stopped run is reported with its reason and time instead of
numbers."""
import math

from . import convergence_table
from . import study_table
from .orders import pairwise_orders
from .conftest import ROUNDOFF_SUITE, roundoff_cases, write_ring_results, write_suite_directory


def test_observed_order_of_c_h_squared_is_two():
    h = [0.1, 0.05, 0.025]
    e = [3.0 * x * x for x in h]
    for a, b in zip(range(2), range(1, 3)):
        assert math.isclose(pairwise_orders([h[a], h[b]], [e[a], e[b]])[0], 2.0, rel_tol=1e-12)


def test_convergence_table_prints_order_two(second_order_series, capsys):
    assert convergence_table.main(second_order_series) == 0
    out = capsys.readouterr().out
    assert out.count("  2.00") >= 4  # two pairs of meshes, two output times, on the Theta = 0 norm at least


def test_study_table_orders_and_failures(second_order_series, tmp_path, capsys):
    failed = tmp_path / "ring-256.h5"
    write_ring_results(failed, 256, [0.1], [0.25], status="failed", failure_reason="nan", failure_time=0.31)
    assert study_table.main(["--times", "0.25,1.0", "--norms", "L1_theta0"] + second_order_series + [str(failed)]) == 0
    out = capsys.readouterr().out
    assert "failed t=0.310 (nan)" in out
    rows = [line for line in out.splitlines() if line.strip().startswith(("64", "128"))]
    assert len(rows) == 2
    for row in rows:
        assert row.split()[-1] == "2.00" and row.split()[-3] == "2.00"


def test_study_table_prints_round_off_instead_of_an_order(tmp_path, capsys):
    """Requirement: between two meshes where either error is at round-off
    (conftest.roundoff_cases: the 64- and 128-cell L1 errors) the table prints
    "round-off" instead of an order; small errors far above the floor keep theirs."""
    cases = roundoff_cases()
    for case in cases:
        case["keys"].update(particles_per_direction=2)   # study_table groups by it (and by amplitude, absent here)
    directory = write_suite_directory(tmp_path / "suite", ROUNDOFF_SUITE, cases)
    files = sorted(str(p) for p in (directory / "cases").glob("*.h5"))
    roundoff = [f for f in files if "/roundoff-" in f]
    small = [f for f in files if "/small-" in f]
    assert study_table.main(["--times", "1.0", "--norms", "L1_theta0"] + roundoff) == 0
    rows = [line.split() for line in capsys.readouterr().out.splitlines() if line.strip().startswith(("64", "128"))]
    assert [row[-1] for row in rows] == ["round-off", "round-off"]
    assert study_table.main(["--times", "1.0", "--norms", "error_axial_stress"] + small) == 0
    rows = [line.split() for line in capsys.readouterr().out.splitlines() if line.strip().startswith(("64", "128"))]
    assert [row[-1] for row in rows] == ["2.00", "2.00"]
