#include "fft.hpp"

#include <fftw3.h>

#include <complex>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <stdexcept>

namespace mpmvv::analytic {

namespace {

struct FftwFree {
  void operator()(void* p) const { fftw_free(p); }
};
struct PlanDestroy {
  void operator()(fftw_plan_s* p) const { fftw_destroy_plan(p); }
};

}  // namespace

std::vector<double> amplitude_spectrum(const std::vector<double>& samples) {
  const int m = int(samples.size());
  if (m < 2) throw std::invalid_argument("amplitude_spectrum needs at least two samples");
  const int modes = m / 2 + 1;
  std::unique_ptr<double, FftwFree> in(static_cast<double*>(fftw_malloc(sizeof(double) * std::size_t(m))));
  std::unique_ptr<fftw_complex, FftwFree> out(
      static_cast<fftw_complex*>(fftw_malloc(sizeof(fftw_complex) * std::size_t(modes))));
  if (!in || !out) throw std::runtime_error("fftw_malloc failed");
  // FFTW_ESTIMATE leaves the input alone while planning.
  std::unique_ptr<fftw_plan_s, PlanDestroy> plan(fftw_plan_dft_r2c_1d(m, in.get(), out.get(), FFTW_ESTIMATE));
  if (!plan) throw std::runtime_error("fftw_plan_dft_r2c_1d failed");
  std::memcpy(in.get(), samples.data(), sizeof(double) * std::size_t(m));
  fftw_execute(plan.get());
  std::vector<double> amplitude(static_cast<std::size_t>(modes));
  for (int k = 0; k < modes; ++k) {
    const double magnitude = std::abs(std::complex<double>(out.get()[k][0], out.get()[k][1]));
    // The mean and (for even M) the Nyquist term appear once; the others twice.
    const bool single = k == 0 || (m % 2 == 0 && k == m / 2);
    amplitude[std::size_t(k)] = magnitude * (single ? 1.0 : 2.0) / m;
  }
  return amplitude;
}

double dominant_frequency(const std::vector<double>& t, const std::vector<double>& value) {
  if (t.size() != value.size() || t.size() < 8) throw std::invalid_argument("dominant_frequency needs 8 or more samples");
  const double duration = t.back() - t.front();
  if (!(duration > 0.0)) throw std::invalid_argument("dominant_frequency needs samples over a positive time");
  // Four times as many uniform samples as given, a power of two.
  std::size_t m = 1;
  while (m < 4 * t.size()) m *= 2;
  std::vector<double> uniform(m);
  double mean = 0.0;
  std::size_t j = 0;
  for (std::size_t i = 0; i < m; ++i) {
    const double s = t.front() + duration * double(i) / double(m - 1);
    while (j + 2 < t.size() && t[j + 1] < s) ++j;
    const double w = (s - t[j]) / (t[j + 1] - t[j]);
    uniform[i] = (1.0 - w) * value[j] + w * value[j + 1];
    mean += uniform[i] / double(m);
  }
  for (std::size_t i = 0; i < m; ++i) {
    const double hann = 0.5 - 0.5 * std::cos(2.0 * 3.14159265358979323846 * double(i) / double(m - 1));
    uniform[i] = (uniform[i] - mean) * hann;
  }
  const std::vector<double> a = amplitude_spectrum(uniform);
  std::size_t peak = 1;
  for (std::size_t k = 1; k + 1 < a.size(); ++k)
    if (a[k] > a[peak]) peak = k;
  double offset = 0.0;
  if (peak > 0 && peak + 1 < a.size() && a[peak - 1] > 0 && a[peak + 1] > 0) {
    const double l = std::log(a[peak - 1]), c = std::log(a[peak]), r = std::log(a[peak + 1]);
    const double denominator = l - 2.0 * c + r;
    if (denominator != 0.0) offset = 0.5 * (l - r) / denominator;
  }
  const double dt = duration / double(m - 1);
  return (double(peak) + offset) / (double(m) * dt);
}

double crossing_period(const std::vector<double>& t, const std::vector<double>& value, double estimate) {
  std::vector<double> crossings;
  for (std::size_t i = 1; i < t.size(); ++i) {
    const double a = value[i - 1], b = value[i];
    if (!((a < 0.0 && b >= 0.0) || (a > 0.0 && b <= 0.0))) continue;
    const double when = t[i - 1] + (t[i] - t[i - 1]) * a / (a - b);
    if (crossings.empty() || when - crossings.back() > 0.25 * estimate) crossings.push_back(when);
  }
  const std::size_t n = crossings.size();
  if (n < 3) return std::numeric_limits<double>::quiet_NaN();
  // Least-squares slope of crossing time against crossing number.
  double mean_k = 0.0, mean_t = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    mean_k += double(k) / double(n);
    mean_t += crossings[k] / double(n);
  }
  double sxy = 0.0, sxx = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    sxy += (double(k) - mean_k) * (crossings[k] - mean_t);
    sxx += (double(k) - mean_k) * (double(k) - mean_k);
  }
  return 2.0 * sxy / sxx;
}

}  // namespace mpmvv::analytic
