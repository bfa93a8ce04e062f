#include "number_spacing.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>

namespace mpmvv::app {

int significant_digits(std::string_view text) {
  int digits = 0;
  bool leading = true;
  for (const char c : text) {
    if (c == 'e' || c == 'E') break;
    if (!std::isdigit(static_cast<unsigned char>(c))) continue;  // sign, point
    if (leading && c == '0') continue;
    leading = false;
    ++digits;
  }
  return digits;
}

double digits_spacing(int digits) {
  return digits <= 0 ? kDoubleSpacing : std::max(std::pow(10.0, 1 - digits), kDoubleSpacing);
}

double binary_spacing(bool floating, std::size_t bytes, const std::vector<double>& values) {
  if (floating) return bytes == 4 ? double(std::numeric_limits<float>::epsilon()) : kDoubleSpacing;
  double largest = 0.0;
  for (const double v : values) largest = std::max(largest, std::abs(v));
  return largest > 1.0 ? 1.0 / largest : 1.0;
}

}  // namespace mpmvv::app
