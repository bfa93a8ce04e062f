"""Observed order of accuracy from errors on a sequence of meshes.

An error that behaves as E(h) = C h^p on meshes of cell size h has

* the pairwise order between consecutive levels i (coarser) and i + 1 (finer)
      p_i = ln(E_i / E_{i+1}) / ln(h_i / h_{i+1});
* the least-squares order: the slope p of the straight line
      ln E = ln C + p ln h
  fitted to all levels of the chosen range, with a two-sided confidence interval
      p +- t(1 - (1 - c)/2, n - 2) * s / sqrt(sum (ln h_i - mean ln h)^2),
  s^2 = (sum of squared residuals) / (n - 2), where t(q, nu) is the quantile of
  Student's t distribution with nu degrees of freedom. The fit and the standard
  error s / sqrt(...) are scipy.stats.linregress's, the quantile
  scipy.stats.t.ppf.

Classification of a range (the rule, applied in this order):

* ``too few levels``: fewer than two usable levels;
* ``round-off``: the error of some usable level is positive and at most its
  round-off floor (below): rounding alone can explain it, so the levels' ratios
  measure the rounding, not the method, and no order is given;
* ``settling``: the run settles to a static state (dynamic relaxation, implicit
  load steps), and the error of some usable level is positive and at most what
  the run's distance from that state at the end could leave in the norm
  (scales.py: settling_scale, from the results file's /settling group): the
  solver's stopping point can explain it, and no order is given;
* ``stalled``: the last pairwise order (between the two finest levels) is below
  STALLED_BELOW = 0.5: the error no longer falls with h;
* ``non-asymptotic``: the pairwise orders span more than ASYMPTOTIC_SPREAD = 0.5
  (max - min), so the range is not yet in the asymptotic regime where one
  C h^p describes every level;
* ``unchecked (2 levels)``: one pairwise order only, not stalled; nothing to
  compare it with;
* ``asymptotic`` otherwise.

The round-off floor of an error that is a difference of numbers of size M
(a displacement error x_p - x_exact(X_p, t) is one of positions, so M is the
largest |X| of the points it is read at, the body's size, not the displacement's;
pi for an angle; 1 for an error relative to its exact value) after a run of n
steps is

    (ROUNDOFF_ULPS + n) eps M,      eps = 2.2e-16, the spacing of doubles at 1:

each step rounds the positions again (x <- x + dt v), by up to one ulp of M, and
in the worst case the roundings add up, n eps M; ROUNDOFF_ULPS = 256 more ulps
cover what does not accumulate: forming the exact solution at the point (a few
elementary functions, each good to an ulp or two), the difference and the norm.
Divided by the exact signal S the norm measures at the read time (the mean
|exact| on a probe line, the RMS exact displacement, 1 for a relative error), it
is the smallest relative error E / S an order can be observed from. It is a
worst case (independent roundings mostly cancel, leaving nearer sqrt(n) ulps
than n): an error above it is not this rounding; one at or below it may be, and an
order fitted through it is no evidence of how the method converges. A run by another
program (external_command) is read from the numbers it wrote, each rounded to the
spacing s of how it wrote them (the /external attribute output_spacing: 2.2e-16
for doubles, 1.2e-7 for floats, 10^(1-d) for text of d significant digits; the
coarsest of the arrays the norms difference). Its floor adds

    OUTPUT_SPACING_UNITS s M,     OUTPUT_SPACING_UNITS = 4:

a displacement error x - phi(X, t) of a written x and a written X is off by half a
spacing of |x| and |F| half spacings of |X|, at most 2 s M for |F| <= 3; 4 doubles
that, and F - I of an F written near 1 is off by half a spacing of 1, within it. For a
relative error M = 1, but a strain formed as F - I near F = I (and a stress
formed from it) is rounded to ulps of 1, not of the strain: for the error_*
columns of a strain or stress M = 1 / |strain|, the largest |F - I| entry
of the particles (scales.py: error_scale).

Richardson extrapolation and the grid convergence index (Roache, *Verification
and Validation in Computational Science and Engineering*, 1998, ch. 5; Roache,
"Perspective: a method for uniform reporting of grid refinement studies",
J. Fluids Eng. 116 (1994) 405-413) for a quantity f without an exact value,
from three levels with a constant refinement ratio r = h_coarse/h_medium =
h_medium/h_fine, values f_3 (coarse), f_2 (medium), f_1 (fine):

* convergence ratio   R = (f_2 - f_1) / (f_3 - f_2): ``monotone`` convergence
  when 0 < R < 1, ``oscillatory`` when -1 < R < 0, ``divergent`` when |R| >= 1
  (no order, extrapolation or GCI then), ``converged`` when f_2 = f_1;
* observed order      p = ln(|f_3 - f_2| / |f_2 - f_1|) / ln r = -ln|R| / ln r;
* extrapolated value  f_h=0 = f_1 + (f_1 - f_2) / (r^p - 1);
* relative change     eps_21 = (f_2 - f_1) / f_1,  eps_32 = (f_3 - f_2) / f_2;
* grid convergence index on the fine and medium levels, safety factor
  F_s = 1.25 for three or more levels:
      GCI_fine = F_s |eps_21| / (r^p - 1),   GCI_medium = F_s |eps_32| / (r^p - 1);
* asymptotic-range check GCI_medium / (r^p GCI_fine), close to 1 in the
  asymptotic range.
"""
import math
import sys
from dataclasses import dataclass

from scipy import stats

STALLED_BELOW = 0.5
ASYMPTOTIC_SPREAD = 0.5
GCI_SAFETY_FACTOR = 1.25
# Ulps of the numbers an error is a difference of that do not accumulate with
# the steps (the exact solution's elementary functions, the difference, the
# norm): "a few hundred", generous, so that the floor is a worst case.
ROUNDOFF_ULPS = 256
# Spacings of an external program's written numbers its rounding may leave in an
# error (module docstring): a worst case, like ROUNDOFF_ULPS.
OUTPUT_SPACING_UNITS = 4


def pairwise_orders(h, error):
    """p_i = ln(E_i/E_{i+1}) / ln(h_i/h_{i+1}) for consecutive levels, coarse first.
    NaN where an error is not positive or two cell sizes are equal."""
    orders = []
    for (h_coarse, e_coarse), (h_fine, e_fine) in zip(zip(h, error), zip(h[1:], error[1:])):
        if e_coarse > 0 and e_fine > 0 and h_coarse > 0 and h_fine > 0 and h_coarse != h_fine:
            orders.append(math.log(e_coarse / e_fine) / math.log(h_coarse / h_fine))
        else:
            orders.append(float("nan"))
    return orders


@dataclass(frozen=True)
class OrderFit:
    """Least-squares fit ln E = ln C + p ln h over n levels."""
    order: float
    error_constant: float      # C
    ci_low: float              # confidence interval of p; NaN when n < 3
    ci_high: float
    confidence: float
    levels: int


def least_squares_order(h, error, confidence=0.95):
    """Slope of ln E against ln h with its Student-t confidence interval.
    Levels with a non-positive or non-finite error or h are left out."""
    points = [(math.log(x), math.log(e)) for x, e in zip(h, error)
              if x > 0 and e > 0 and math.isfinite(x) and math.isfinite(e)]
    n = len(points)
    nan = float("nan")
    if n < 2:
        return OrderFit(nan, nan, nan, nan, confidence, n)
    x, y = zip(*points)
    if min(x) == max(x):
        return OrderFit(nan, nan, nan, nan, confidence, n)
    fit = stats.linregress(x, y)
    if n == 2:
        return OrderFit(float(fit.slope), math.exp(fit.intercept), nan, nan, confidence, n)
    slope = float(fit.slope)
    half_width = float(stats.t.ppf(0.5 + confidence / 2.0, n - 2) * fit.stderr)
    return OrderFit(slope, math.exp(fit.intercept), slope - half_width, slope + half_width, confidence, n)


def roundoff_floor(steps, size, output_spacing=0.0):
    """(ROUNDOFF_ULPS + steps) eps size + OUTPUT_SPACING_UNITS output_spacing size:
    the largest error rounding alone can leave in a difference of numbers of the
    given size after that many steps, read from numbers written to the relative
    spacing output_spacing (0 for mpmvv's own run; module docstring)."""
    return ((ROUNDOFF_ULPS + max(steps, 0)) * sys.float_info.epsilon
            + OUTPUT_SPACING_UNITS * max(output_spacing, 0.0)) * size


def classify(pairwise, floor=None):
    """The class of a refinement range from its pairwise orders and what may
    explain some level's error other than the method, "round-off" or
    "settling" (series.floor_kind; None: nothing), rule in the module docstring."""
    finite = [p for p in pairwise if math.isfinite(p)]
    if not pairwise or not finite:
        return "too few levels"
    if floor:
        return floor
    if not math.isfinite(pairwise[-1]) or pairwise[-1] < STALLED_BELOW:
        return "stalled"
    if len(finite) < 2:
        return "unchecked (2 levels)"
    if max(finite) - min(finite) > ASYMPTOTIC_SPREAD:
        return "non-asymptotic"
    return "asymptotic"


def richardson_extrapolate(fine, coarse, ratio, order):
    """f_h=0 = f_fine + (f_fine - f_coarse) / (r^p - 1)."""
    return fine + (fine - coarse) / (ratio ** order - 1.0)


@dataclass(frozen=True)
class GridConvergence:
    """Roache's three-level study of a quantity (definitions in the module docstring)."""
    observed_order: float
    convergence: str           # monotone | oscillatory | divergent | converged (report.py: or round-off)
    extrapolated: float
    gci_fine: float            # relative: multiply by |f_fine| for a band in the quantity's unit
    gci_medium: float
    asymptotic_ratio: float


def grid_convergence(coarse, medium, fine, ratio, safety_factor=GCI_SAFETY_FACTOR):
    """Observed order, Richardson extrapolation and GCI from three levels with a
    constant refinement ratio r > 1."""
    nan = float("nan")
    change_fine, change_coarse = medium - fine, coarse - medium
    if change_fine == 0.0:
        return GridConvergence(nan, "converged", fine, 0.0, nan, nan)
    if change_coarse == 0.0 or abs(change_fine / change_coarse) >= 1.0:
        order = math.log(abs(change_coarse / change_fine)) / math.log(ratio) if change_coarse else nan
        return GridConvergence(order, "divergent", nan, nan, nan, nan)
    convergence = "monotone" if change_fine * change_coarse > 0 else "oscillatory"
    order = math.log(abs(change_coarse / change_fine)) / math.log(ratio)
    growth = ratio ** order - 1.0
    gci_fine = safety_factor * abs(change_fine / fine) / growth if fine != 0.0 else nan
    gci_medium = safety_factor * abs(change_coarse / medium) / growth if medium != 0.0 else nan
    return GridConvergence(order, convergence, richardson_extrapolate(fine, medium, ratio, order),
                           gci_fine, gci_medium, gci_medium / (ratio ** order * gci_fine))
