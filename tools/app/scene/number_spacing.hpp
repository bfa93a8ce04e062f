// How finely an external program wrote its numbers: the relative spacing of
// the values as stored (a double's 2.2e-16, a float's 1.2e-7, 1e-5 for text
// of 6 significant digits). Rounding to that spacing is an error the program's
// method did not make, and mpmvv cannot tell it from one: the report's
// round-off floor of an external run counts it (reports/orders.py,
// OUTPUT_SPACING_UNITS), and the out-of-plane components dropped from a 3-D
// tuple must vanish to it (particle_output.cpp).
#pragma once

#include <cstddef>
#include <limits>
#include <string_view>
#include <vector>

namespace mpmvv::app {

constexpr double kDoubleSpacing = std::numeric_limits<double>::epsilon();

// The significant digits of a number written as text: those of its mantissa
// from the first non-zero digit on, trailing zeros counted (they are written
// precision): "-1.25000e-3" 6, "0.000120" 3, "7" 1; "0" and "0.00" none (a
// zero tells nothing of the writer's precision).
int significant_digits(std::string_view text);

// The relative spacing of numbers written with at most `digits` significant
// digits: 10^(1 - digits), the spacing relative to a number of that decade's
// smallest leading digit; never below a double's, and a double's for none
// (every number written was zero).
double digits_spacing(int digits);

// The relative spacing of numbers stored in binary: a double's 2^-52, a
// float's 2^-23; of an integer type, 1 over the largest magnitude among
// `values` (a real quantity rounded to whole units).
double binary_spacing(bool floating, std::size_t bytes, const std::vector<double>& values);

}  // namespace mpmvv::app
