"""Requirements of reports/norms.py: eq. 3.1 of 000_1dbcb8acb6dddab9.txt and
the volume-weighted particle norms give known values on known arrays, and the
L1 recomputed from a results file's probe arrays matches its /errors column."""
import math

import numpy as np

from . import norms
from .conftest import write_case_results
from .probes import read_probe_lines
from .results import read_case_results


def test_eq_3_1_is_the_mean_absolute_difference_at_each_time():
    """Requirement: L1 = sum |x_sim - x_exact| / N per output time (eq. 3.1)."""
    exact = np.array([[0.0, 1.0, 2.0], [1.0, 1.0, 1.0]])
    simulated = exact + np.array([[1.0, -2.0, 3.0], [0.5, 0.5, -0.5]])
    assert np.allclose(norms.probe_line_l1(simulated, exact), [2.0, 0.5], rtol=0, atol=1e-15)


def test_a_tracer_that_left_the_grid_makes_the_norm_nan():
    """Requirement: a NaN tracer gives a NaN norm, as in the solver, not a smaller mean."""
    assert math.isnan(norms.probe_line_l1([1.0, float("nan")], [0.0, 0.0]))


def test_volume_weighted_particle_norms():
    """Requirement: particle_L1 = sum V e / sum V, particle_L2 = sqrt(sum V e^2 / sum V),
    particle_Linf = max e."""
    result = norms.volume_weighted_norms([1.0, 2.0], [3.0, 1.0])
    assert math.isclose(result["particle_L1"], 1.25, rel_tol=1e-15)
    assert math.isclose(result["particle_L2"], math.sqrt(1.75), rel_tol=1e-15)
    assert result["particle_Linf"] == 2.0


def test_recomputed_l1_matches_the_stored_column(tmp_path):
    """Requirement: eq. 3.1 recomputed from a results file's probe arrays agrees with
    its stored L1_<line> column, and a wrong column is detected."""
    path = tmp_path / "case.h5"
    write_case_results(path, {"method": "cpdi", "cells": 32, "end_time": 1.0}, 0.1,
                       {"L1_theta0": [1e-3, 2e-3, float("nan")]}, [0.25, 0.5, 1.0])
    stored = read_case_results(path).errors["L1_theta0"]
    line = read_probe_lines(path)[0]
    recomputed = norms.probe_line_l1(line.simulated, line.exact)
    assert norms.stored_l1_discrepancy(stored, recomputed) < 1e-12
    assert norms.stored_l1_discrepancy(stored * 1.01, recomputed) > 5e-3


def test_units_and_descriptions_follow_the_line_quantity():
    """Requirement: a probe-line norm carries its quantity's unit; particle norms are in m."""
    quantities = {"theta0": "angular_displacement", "line_y_mid": "displacement_x"}
    assert norms.norm_unit("L1_theta0", quantities) == "rad"
    assert norms.norm_unit("L1_line_y_mid", quantities) == "m"
    assert norms.norm_unit("particle_L2", quantities) == "m"
    assert norms.norm_unit("particle_velocity_L2", quantities) == "m/s"
    assert norms.norm_unit("particle_deformation_L2", quantities) == "1"
    assert norms.norm_unit("particle_pressure_L2", quantities) == "Pa"
    assert norms.norm_unit("error_axial_stress", quantities) == "1"
    assert "relative error" in norms.describe_norm("error_axial_stress", quantities)
    assert "pressure" in norms.describe_norm("particle_pressure_L2", quantities)
    # scene-aware names: r and z in r-z scenes
    assert norms.quantity_label("displacement_x", "axisymmetric") == "radial displacement u_r"
    assert norms.quantity_label("displacement_y", "plane-strain") == "y displacement"
    assert norms.quantity_label("displacement_x") == "x (or r) displacement"
    assert "eq. 3.1" in norms.describe_norm("L1_theta0", quantities)


def test_the_unit_a_results_file_stored_comes_first(tmp_path):
    """Requirement: a column's unit is the one the run stored in /errors' units
    attribute (the solver's rule, written once there); the report's own rule
    serves files written before it stored one."""
    import h5py
    from .conftest import write_case_results
    from .results import read_case_results
    path = tmp_path / "case.h5"
    write_case_results(path, {"cells": 8}, 0.1, {"L1_theta0": [1e-3], "error_custom": [1e-2]}, [1.0])
    assert read_case_results(path).error_units == {}                     # written before units were stored
    with h5py.File(path, "a") as f:
        f["errors"].attrs["units"] = "L1_theta0 rad\nerror_custom 1\nweird -\n"
    stored = read_case_results(path).error_units
    assert stored == {"L1_theta0": "rad", "error_custom": "1", "weird": ""}
    quantities = norms.LineQuantities({"theta0": "radial_displacement"})
    quantities.units.update(stored)
    assert norms.norm_unit("L1_theta0", quantities) == "rad"            # stored, over the line's quantity (m)
    assert norms.norm_unit("L1_theta0", {"theta0": "radial_displacement"}) == "m"
