#include "spectrum.hpp"

#include <fftw3.h>

#include <complex>
#include <cstring>
#include <memory>
#include <stdexcept>

namespace mpmvv::app {

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

}  // namespace mpmvv::app
