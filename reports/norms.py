"""The error norms of mpmvv, each defined once (reports/results-format.md, /errors).

Probe-line norm, eq. 3.1 of 000_1dbcb8acb6dddab9.txt (Sandia SAND2015-7448):

    L1 = sum_{i=1}^{N} |q_sim,i - q_exact,i| / N

over the N material points of a probe line, for the line's quantity q (its
``quantity`` attribute: angular displacement [rad], radial displacement or a
displacement component [m]). The solver stores it as the column ``L1_<line>``
of /errors; ``probe_line_l1`` recomputes it from the line's arrays <q> and
exact_<q> (T x P), and ``stored_l1_discrepancy`` checks the two agree. A tracer
that left the grid is NaN and makes the norm NaN at that time, as in the solver.

Particle norms of the displacement error e_p = |x_p - x_exact(X_p, t)| [m],
weighted by the reference volume V_p0 of each particle:

    particle_L1   = sum_p V_p0 e_p / sum_p V_p0
    particle_L2   = sqrt(sum_p V_p0 e_p^2 / sum_p V_p0)
    particle_Linf = max_p e_p

and, over the run so far, the time-integrated relative L2 error (the norm the
total Lagrangian MPM literature reports for the ring, its "vortex"):

    particle_relative_L2_integrated
        = sqrt( int_0^t sum_p V_p0 e_p^2 dt / int_0^t sum_p V_p0 |x_exact - X_p|^2 dt )

(trapezoid rule over t = 0 and the output times; exact_displacement_L2 is the
RMS of |x_exact - X_p| at each output time).

They need the exact motion at every particle, which only the solver evaluates,
so the report reads them from /errors; ``volume_weighted_norms`` states the
same definitions as code (and is tested on arrays whose norms are known).
"""
import numpy as np

PARTICLE_NORMS = ("particle_L1", "particle_L2", "particle_Linf", "exact_displacement_L2")
RELATIVE_NORMS = ("particle_relative_L2_integrated",)
# Dimensionless, per particle like the displacement norms:
#     particle_deformation_L2 = sqrt(sum_p V_p0 |F_p - F_exact(X_p, t)|^2 / sum_p V_p0)
# (Frobenius, the out-of-plane stretch included).
DEFORMATION_NORMS = ("particle_deformation_L2",)
# In m/s:
#     particle_velocity_L2 = sqrt(sum_p V_p0 |v_p - v_exact(X_p, t)|^2 / sum_p V_p0)
VELOCITY_NORMS = ("particle_velocity_L2",)
# In Pa: the RMS error of the in-plane mean stress -(sigma_xx + sigma_yy) / 2.
PRESSURE_NORMS = ("particle_pressure_L2",)

QUANTITY_UNITS = {
    "angular_displacement": "rad",
    "radial_displacement": "m",
    "displacement_x": "m",
    "displacement_y": "m",
}

QUANTITY_LABELS = {
    "angular_displacement": "angular displacement",
    "radial_displacement": "radial displacement",
    "displacement_x": "x (or r) displacement",
    "displacement_y": "y (or z) displacement",
}


# The same in the scene's own coordinates (the results file's `geometry`).
GEOMETRY_QUANTITY_LABELS = {
    ("plane-strain", "displacement_x"): "x displacement",
    ("plane-strain", "displacement_y"): "y displacement",
    ("axisymmetric", "displacement_x"): "radial displacement u_r",
    ("axisymmetric", "displacement_y"): "axial displacement u_z",
}


def quantity_label(quantity, geometry=None):
    """What a probe quantity is called in a scene of the given geometry
    ("plane-strain" or "axisymmetric"; None: either, QUANTITY_LABELS)."""
    return GEOMETRY_QUANTITY_LABELS.get((geometry, quantity), QUANTITY_LABELS.get(quantity, quantity))


def probe_line_l1(simulated, exact):
    """Eq. 3.1 at every output time: mean over the line's points of |q_sim - q_exact|.
    simulated, exact: arrays T x P (or P); returns T values (or one)."""
    return np.mean(np.abs(np.asarray(simulated, float) - np.asarray(exact, float)), axis=-1)


def volume_weighted_norms(error, reference_volume):
    """particle_L1, particle_L2, particle_Linf of the per-particle errors e_p
    weighted by V_p0 (definitions in the module docstring)."""
    e = np.asarray(error, float)
    w = np.asarray(reference_volume, float)
    total = w.sum()
    return {
        "particle_L1": float((w * e).sum() / total),
        "particle_L2": float(np.sqrt((w * e * e).sum() / total)),
        "particle_Linf": float(e.max()),
    }


def stored_l1_discrepancy(stored, recomputed):
    """Largest relative difference between the stored /errors column and eq. 3.1
    recomputed from the probe arrays; rows where both are NaN agree; 0 when empty."""
    a = np.asarray(stored, float)
    b = np.asarray(recomputed, float)
    if a.shape != b.shape:
        return float("inf")
    both_nan = np.isnan(a) & np.isnan(b)
    scale = np.maximum(np.abs(a), np.abs(b))
    scale[scale == 0.0] = 1.0
    difference = np.abs(a - b) / scale
    difference[both_nan] = 0.0
    return float(np.nan_to_num(difference, nan=np.inf).max()) if difference.size else 0.0


class LineQuantities(dict):
    """Probe line name -> its quantity, and in .units the unit of each /errors
    column as the results files stored it (the solver's norms.hpp: error_unit)."""
    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.units = {}


def norm_unit(norm, line_quantities):
    """Unit of an /errors column: m for particle displacement norms, Pa for the
    pressure, m/s for the velocity, 1 for F and for relative errors (the
    time-integrated relative norm and a scene's error_* columns, results-format.md),
    the line's quantity unit for L1_<line>. The unit the results files stored
    comes first; the rules below serve files written before they stored one."""
    stored = getattr(line_quantities, "units", {})
    if norm in stored:
        return stored[norm]
    if norm in PARTICLE_NORMS:
        return "m"
    if norm in RELATIVE_NORMS or norm in DEFORMATION_NORMS or norm.startswith("error_"):
        return "1"
    if norm in VELOCITY_NORMS:
        return "m/s"
    if norm in PRESSURE_NORMS:
        return "Pa"
    quantity = line_quantities.get(norm[len("L1_"):]) if norm.startswith("L1_") else None
    return QUANTITY_UNITS.get(quantity, "")


def describe_norm(norm, line_quantities):
    """One line saying what an /errors column measures."""
    if norm == "particle_L1":
        return "volume-weighted mean particle displacement error"
    if norm == "particle_L2":
        return "volume-weighted RMS particle displacement error"
    if norm == "particle_Linf":
        return "largest particle displacement error"
    if norm == "exact_displacement_L2":
        return "volume-weighted RMS exact displacement (the scale of the particle errors)"
    if norm == "particle_deformation_L2":
        return "volume-weighted RMS error of each particle's deformation gradient F (Frobenius)"
    if norm == "particle_velocity_L2":
        return "volume-weighted RMS particle velocity error"
    if norm == "particle_pressure_L2":
        return "volume-weighted RMS error of the particle pressure (in-plane mean stress)"
    if norm.startswith("error_"):
        return f"relative error of the scene's {norm[len('error_'):].replace('_', ' ')}, |measured / exact - 1|"
    if norm == "particle_relative_L2_integrated":
        return "time-integrated relative L2 particle displacement error, from t = 0"
    if norm.startswith("L1_"):
        line = norm[len("L1_"):]
        quantity = QUANTITY_LABELS.get(line_quantities.get(line), "probe quantity")
        return f"eq. 3.1 L1 of the {quantity} on probe line {line}"
    return norm
