// Spectra with FFTW (real-to-complex): the amplitude spectrum of a periodic
// sample, used to measure lost axisymmetry (the error around a material circle
// of an axisymmetric solution should hold no angular mode but m = 0), and the
// dominant frequency of a history, used to time a vibration.
#pragma once

#include <vector>

namespace mpmvv::analytic {

// For M equally spaced samples f_j, returns the one-sided amplitudes A_m,
// m = 0 .. M/2, with f_j = sum_m A_m cos(2 pi m j / M + phi_m).
std::vector<double> amplitude_spectrum(const std::vector<double>& samples);

// The dominant frequency [Hz] of a history sampled at times t (any spacing):
// resampled linearly onto a uniform grid, Hann-windowed, transformed, and the
// peak refined by a parabola through the logarithms of its bin and the two
// beside it (exact for a Gaussian peak; for a pure tone over several periods
// the error is a small fraction of a bin, 1 / duration).
double dominant_frequency(const std::vector<double>& t, const std::vector<double>& value);

// The period of a history that oscillates about zero, from its zero crossings
// (linear interpolation between samples: for a sine the curvature vanishes at
// a crossing, so the error is of third order in the sample spacing), fitted by
// least squares as t_n = t_0 + n T / 2. `estimate` (from the spectrum) sets
// which crossings count: those at least a quarter of it apart. NaN with fewer
// than three crossings.
double crossing_period(const std::vector<double>& t, const std::vector<double>& value, double estimate);

}  // namespace mpmvv::analytic
