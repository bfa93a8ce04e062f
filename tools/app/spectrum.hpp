// Amplitude spectrum of a periodic sample (FFTW, real-to-complex). Used to
// measure lost axisymmetry: the error around a material circle of an
// axisymmetric solution should hold no angular mode but m = 0.
#pragma once

#include <vector>

namespace mpmvv::app {

// For M equally spaced samples f_j, returns the one-sided amplitudes A_m,
// m = 0 .. M/2, with f_j = sum_m A_m cos(2 pi m j / M + phi_m).
std::vector<double> amplitude_spectrum(const std::vector<double>& samples);

}  // namespace mpmvv::app
