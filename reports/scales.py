"""The scales an error is judged against: the exact signal a norm measures
(how much motion there is to get wrong), the size an error of that norm is
relative to (round-off floors, series.py), and how far a static scene's end
still is from its static state in each norm (settling)."""
import math

import h5py
import numpy as np

from .probes import read_probe_lines
from .results import TIME_MATCH_TOLERANCE, plain


# Norms of the displacement error, measured against exact_displacement_L2.
DISPLACEMENT_NORMS = ("particle_L1", "particle_L2", "particle_Linf")
# /errors columns that are already relative to the exact value they measure
# (results-format.md): their exact signal is 1, in their own unit.
RELATIVE_NORMS = ("particle_relative_L2_integrated",)
# The deformation gradient's error, against the size of F's own entries.
DEFORMATION_NORM = "particle_deformation_L2"
RELATIVE_NORM_PREFIX = "error_"


def _exact_signal_series(case, norm):
    """(output times, the exact signal the norm measures at each): the mean |exact|
    on the line of an L1_<line> norm (eq. 3.1's exact values), the RMS exact
    displacement for the particle displacement norms; None for other norms, an
    unreadable file or a missing line."""
    if norm.startswith("L1_"):
        try:
            line = next((l for l in read_probe_lines(case.results_path) if l.name == norm[3:]), None)
        except (OSError, KeyError, ValueError, TypeError):
            return None
        return None if line is None else (line.time, np.mean(np.abs(line.exact), axis=1))
    if norm in DISPLACEMENT_NORMS and "exact_displacement_L2" in case.results.errors:
        return case.results.error_times, case.results.errors["exact_displacement_L2"]
    return None


def _output_index(times, time, count):
    """The index of output time `time` among `times` (and below `count`), or None."""
    hits = np.nonzero(np.abs(times - time) <= TIME_MATCH_TOLERANCE * max(1.0, abs(time)))[0]
    return int(hits[0]) if hits.size and hits[0] < count else None


def exact_signal_fraction(case, norm, time):
    """What the exact solution gives the norm to measure at output time `time`, as
    a fraction of its largest over the run's output times: the mean |exact| on the
    line of an L1_<line> norm (eq. 3.1's exact values), the RMS exact displacement
    for the particle displacement norms. None where it is not known (other norms,
    no such output, an unreadable file). A read where the fraction is small
    measures little: a run without the motion scores nearly the same there."""
    series = _exact_signal_series(case, norm) if case.results is not None else None
    if series is None:
        return None
    times, signal = series
    index = _output_index(times, time, len(signal))
    largest = float(np.max(signal)) if len(signal) else 0.0
    if index is None or not largest > 0.0:
        return None
    return float(signal[index]) / largest


def _end_deformation(case):
    """The particles' in-plane F at the end of the run (N x 2 x 2), None where the
    file does not hold it."""
    try:
        with h5py.File(case.results_path, "r") as f:
            F = f.get("particles/deformation_gradient")
            if not isinstance(F, h5py.Dataset) or F.size == 0:
                return None
            return np.asarray(F[:], float).reshape(-1, 2, 2)
    except (OSError, KeyError, ValueError, TypeError):
        return None


def _strain_size(case):
    """The largest in-plane |F - I| entry over the particles at the end of the run:
    a strain, and a stress E (F - I), is formed from entries of F near 1, so its
    rounding is ulps of 1, not of the strain. None where the file does not hold F."""
    F = _end_deformation(case)
    if F is None:
        return None
    strain = float(np.max(np.abs(F - np.eye(2))))
    return strain if math.isfinite(strain) and strain > 0.0 else None


def _deformation_size(case):
    """The largest |F| entry at the end of the run, F_33 = 1 included: the size
    of the numbers particle_deformation_L2 is a difference of."""
    F = _end_deformation(case)
    if F is None:
        return None
    size = max(1.0, float(np.max(np.abs(F))))
    return size if math.isfinite(size) else None


def _coordinate_size(case, norm):
    """The size of the numbers the norm's error is a difference of: for a length
    read off material points (x - X, |x| - |X|), the largest |X| of those points
    (the line's, or every particle's); pi for an angle (atan2's largest value).
    None where the file does not hold them."""
    try:
        with h5py.File(case.results_path, "r") as f:
            if norm.startswith("L1_"):
                group = f.get(f"probes/{norm[3:]}")
                if not isinstance(group, h5py.Group):
                    return None
                if plain(group.attrs.get("quantity", "")) == "angular_displacement":
                    return math.pi
                positions = group.get("reference_position")
            else:
                positions = f.get("particles/reference_position")
            if not isinstance(positions, h5py.Dataset) or positions.size == 0:
                return None
            positions = np.asarray(positions[:], float).reshape(-1, 2)
    except (OSError, KeyError, ValueError, TypeError):
        return None
    size = float(np.max(np.hypot(positions[:, 0], positions[:, 1])))
    return size if math.isfinite(size) else None


def error_scale(case, norm, time):
    """(S, M) for the error `norm` at output time `time`: S the exact signal it
    measures there (the mean |exact| on an L1_<line> norm's line, the RMS exact
    displacement for particle_L1, _L2, _Linf; 1 for an error already relative to
    its exact value: error_* and particle_relative_L2_integrated; F's largest
    entry for particle_deformation_L2), M the size of the numbers the error is a
    difference of (_coordinate_size; 1 for a relative error, 1 / strain for a
    relative error of a strain or stress, _strain_size; F's largest entry,
    _deformation_size), in the norm's unit. The round-off floor of reports/orders.py is
    measured with them. None where either is not known."""
    if case.results is None:
        return None
    if norm.startswith(RELATIVE_NORM_PREFIX) or norm in RELATIVE_NORMS:
        if norm not in case.results.errors:
            return None
        # A strain or stress relative to its exact value is rounded to ulps of
        # F's entries (near 1) over the strain: M = 1 / strain where it is small.
        # (Without F in the file, 1: the floor of the ratio itself.)
        if norm.endswith(("_strain", "_stress")):
            strain = _strain_size(case)
            return 1.0, 1.0 / min(strain, 1.0) if strain is not None else 1.0
        return 1.0, 1.0
    if norm == DEFORMATION_NORM:
        # F's error against F's own size: the signal and the numbers are F's entries.
        if norm not in case.results.errors:
            return None
        size = _deformation_size(case)
        return (size, size) if size is not None else None
    series = _exact_signal_series(case, norm)
    if series is None:
        return None
    times, signal = series
    index = _output_index(times, time, len(signal))
    size = _coordinate_size(case, norm) if index is not None else None
    if size is None or not math.isfinite(signal[index]):
        return None
    return float(signal[index]), size


# A mean over a region of at least a quarter of the body is at most twice the
# body's RMS (settling_scale).
SETTLING_REGION_FACTOR = 2.0


def settling_scale(case, norm, time):
    """The largest error in `norm` that the run's stopping short of its static
    state could leave at output time `time`, in the norm's unit, from the
    results file's /settling group (results-format.md); None for a run that
    does not settle, a read before the end (settling is the end's) or a norm it
    does not translate to.

    A damped run that relaxes (method "relaxation") gives each norm read at the
    end its own: how much it would still change. Load steps that each end in
    equilibrium (method "newton") give the Newton correction left, delta
    (displacement: mass-weighted RMS over the grid) and the RMS of its strain
    over the body; a particle's displacement is a convex combination of the
    nodes', so over the N particles its RMS, and its mean, is at most delta
    (particle_L2, particle_L1); over k of them (a probe line's points, counted
    as particles of the mean mass; the one of particle_Linf) at most delta
    sqrt(N / k); an error_* column of a strain, stretch or stress (relative to
    its exact value, a mean over a region of the body) at most
    SETTLING_REGION_FACTOR x the strain's RMS over the strain's size, the
    largest |F - I| entry of the particles."""
    if case.results is None or not case.results.settling:
        return None
    if _output_index(np.asarray([case.end_time]), float(time), 1) is None:
        return None
    settling = case.results.settling

    def finite(value):
        return float(value) if isinstance(value, (int, float)) and math.isfinite(value) and value >= 0.0 else None

    if settling.get("method") == "relaxation":
        return finite(settling.get("norms", {}).get(norm))
    delta, strain_error = finite(settling.get("displacement")), finite(settling.get("strain"))
    particles = case.attribute("particle_count")
    counted = isinstance(particles, (int, float)) and particles >= 1
    if norm in ("particle_L1", "particle_L2"):
        return delta
    if delta is not None and counted and norm == "particle_Linf":
        return delta * math.sqrt(particles)
    if delta is not None and counted and norm.startswith("L1_"):
        try:
            line = next((l for l in read_probe_lines(case.results_path) if l.name == norm[3:]), None)
        except (OSError, KeyError, ValueError, TypeError):
            return None
        # A length: the displacements' components, not an angle or a pressure.
        if line is None or "displacement" not in line.quantity or "angular" in line.quantity \
                or line.exact.shape[-1] == 0:
            return None
        return delta * math.sqrt(particles / line.exact.shape[-1])
    if strain_error is not None and norm.startswith(RELATIVE_NORM_PREFIX) \
            and norm.endswith(("_strain", "_stretch", "_stress")):
        strain = _strain_size(case)
        return None if strain is None else SETTLING_REGION_FACTOR * strain_error / strain
    return None
