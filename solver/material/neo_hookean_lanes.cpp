// The lane kernel of neo_hookean_lanes.hpp (lane_vectors.hpp says how it is
// built). Each line is the scalar line it repeats: particle_healthy and
// signal_speed (stages.hpp), NeoHookean::wave_modulus_bound (neo_hookean.hpp),
// in plane strain (F_33 = 1); std::max(a, b) is a < b ? b : a.
#include "neo_hookean_lanes.hpp"

#include "../lane_log.hpp"
#include "../lane_vectors.hpp"

namespace mpmvv {

namespace {

using namespace lanes::MPMVV_LANE_BUILD_NS;

struct NeoHookeanScanKernel {
  using Grid = NeoHookeanScanLaneParams;
  using In = NeoHookeanScanLaneInput;
  using Out = NeoHookeanScanLaneVerdict;

  template <int W>
  MPMVV_LANE_INLINE static void body(const Grid& g, const In& in, Out& out, int l0);
};

template <class V>
MPMVV_LANE_INLINE V larger(const V& a, const V& b) {  // std::max
  return a < b ? b : a;
}

template <int W>
void NeoHookeanScanKernel::body(const Grid& g, const In& in, Out& out, int l0) {
  using Lanes = typename Width<W>::Lanes;
  using Mask = typename Width<W>::Mask;
  using Ints = typename Width<W>::Ints;
  const Lanes zero = {};
  Lanes x[2], velocity[2], F[4], sigma[4];
  load_interleaved(in.position + 2 * l0, x);
  load_interleaved(in.velocity + 2 * l0, velocity);
  load_interleaved(in.deformation_gradient + 4 * l0, F);
  load_interleaved(in.stress + 4 * l0, sigma);
  const Lanes vx = velocity[0], vy = velocity[1];
  const Lanes f00 = F[0], f10 = F[1], f01 = F[2], f11 = F[3];
  const Lanes s00 = sigma[0], s10 = sigma[1], s01 = sigma[2], s11 = sigma[3];
  // particle_healthy: 0 x is +-0 for a finite x and NaN otherwise.
  const Lanes finite = ((0.0 * x[0] + 0.0 * x[1]) + (0.0 * vx + 0.0 * vy)) +
                       ((0.0 * f00 + 0.0 * f10 + 0.0 * f01 + 0.0 * f11) + (0.0 * s00 + 0.0 * s10 + 0.0 * s01 + 0.0 * s11));
  const Lanes J = f00 * f11 - f01 * f10;  // determinant(F) F_33
  const Mask sound = (finite == zero) & (J > zero);
  // signal_speed's test.
  const Lanes density = load<Lanes>(in.mass + l0) / load<Lanes>(in.volume + l0);
  const Lanes v = lane_sqrt(vx * vx + vy * vy);
  const Lanes room = g.largest * (1.0 - 1e-9) - v;
  // wave_modulus_bound
  const Lanes shear = larger(lane_abs(g.mu - g.lambda * (J - 1.0)), lane_abs(g.mu - g.lambda * (1.0 - 1.0 / J)));
  Lanes modulus = ((g.lambda < 0.0 ? -g.lambda : g.lambda) + 2.0 * shear) / J +
                  larger(larger(s00, s11) + lane_abs(s01), zero);
  Mask must_form = {};
  if (g.stiffens) {
    const Lanes bound = load<Lanes>(in.gradient_bound + l0);
    const Lanes most = larger(zero + 1.0, g.h * bound * g.inverse_basis_bound * (1.0 + 1e-12));
    modulus = larger(modulus, most * most * g.p_wave_modulus);
    must_form = bound < zero;
  }
  const Mask ruled_out = sound & (room > zero) & (modulus <= density * room * room) & ~must_form;
  store(out.sound + l0, to_ints<Ints>(sound));
  store(out.may_set_speed + l0, to_ints<Ints>(~ruled_out));
}

// NeoHookean::stress with F_33 = 1, line by line:
//   J = (F00 F11 - F01 F10) 1, p = lambda ln J / J, shear = mu / J,
//   B = F F^T, sigma = p I + shear (B - I) entry by entry.
struct NeoHookeanStressKernel {
  using Grid = NeoHookeanStressLaneParams;
  struct In {
    const double* deformation_gradient;
  };
  struct Out {
    double* stress;
    double outside[kLanes];  // per lane, how many J were not positive, finite and normal
  };

  template <int W>
  MPMVV_LANE_INLINE static void body(const Grid& g, const In& in, Out& out, int l0) {
    using Lanes = typename Width<W>::Lanes;
    using Mask = typename Width<W>::Mask;
    Lanes F[4];
    load_interleaved(in.deformation_gradient + 4 * l0, F);
    const Lanes f00 = F[0], f10 = F[1], f01 = F[2], f11 = F[3];
    const Lanes J = (f00 * f11 - f01 * f10) * 1.0;
    const Mask normal = (J >= kLaneStressSmallestJ) & (J <= kLaneStressLargestJ);
    store(out.outside + l0, load<Lanes>(out.outside + l0) + (normal ? Lanes{} : Lanes{} + 1.0));
    const Lanes p = g.lambda * lane_log(J) / J;
    const Lanes shear = g.mu / J;
    const Lanes b00 = f00 * f00 + f01 * f01, b01 = f00 * f10 + f01 * f11, b11 = f10 * f10 + f11 * f11;
    const Lanes off = p * 0.0 + shear * (b01 - 0.0);
    const Lanes sigma[4] = {p * 1.0 + shear * (b00 - 1.0), off, off, p * 1.0 + shear * (b11 - 1.0)};
    store_interleaved(out.stress + 4 * l0, sigma);
  }
};

}  // namespace

namespace lanes::MPMVV_LANE_BUILD_NS {
void neo_hookean_scan_lanes(const NeoHookeanScanLaneParams& params, const NeoHookeanScanLaneInput& in,
                            NeoHookeanScanLaneVerdict& out) {
  run<NeoHookeanScanKernel>(params, in, out);
}

void neo_hookean_stress_array(const NeoHookeanStressLaneParams& params, std::size_t n,
                              const double* deformation_gradient, double* stress, std::size_t& outside) {
  NeoHookeanStressKernel::Out out{stress, {}};
  std::size_t k = 0;
  for (; k + kLanes <= n; k += kLanes) {
    out.stress = stress + 4 * k;
    run<NeoHookeanStressKernel>(params, {deformation_gradient + 4 * k}, out);
  }
  auto count = [&] {
    double sum = 0.0;
    for (double c : out.outside) sum += c;
    outside = std::size_t(sum);
  };
  if (k == n) return count();
  // The last few through whole lanes: the spare ones hold F = I.
  double F[4 * kLanes], sigma[4 * kLanes];
  for (std::size_t l = 0; l < std::size_t(kLanes); ++l)
    for (std::size_t c = 0; c < 4; ++c)
      F[4 * l + c] = k + l < n ? deformation_gradient[4 * (k + l) + c] : (c == 0 || c == 3 ? 1.0 : 0.0);
  out.stress = sigma;
  run<NeoHookeanStressKernel>(params, {F}, out);
  for (std::size_t v = 0; v < 4 * (n - k); ++v) stress[4 * k + v] = sigma[v];
  count();
}
}  // namespace lanes::MPMVV_LANE_BUILD_NS

#if defined(MPMVV_LANE_DISPATCH)
MPMVV_LANE_DISPATCH_OF(neo_hookean_scan_lanes,
                       (const NeoHookeanScanLaneParams& params, const NeoHookeanScanLaneInput& in,
                        NeoHookeanScanLaneVerdict& out),
                       (params, in, out))

std::size_t neo_hookean_lane_stress(LaneBuild build, const NeoHookeanStressLaneParams& params, std::size_t n,
                                    const double* deformation_gradient, double* stress) {
  std::size_t outside = 0;
  MPMVV_LANE_BUILD_CALL(build, neo_hookean_stress_array(params, n, deformation_gradient, stress, outside));
  return outside;
}

std::size_t neo_hookean_lane_stress(const NeoHookeanStressLaneParams& params, std::size_t n,
                                    const double* deformation_gradient, double* stress) {
  return neo_hookean_lane_stress(lane_build(), params, n, deformation_gradient, stress);
}
#endif

}  // namespace mpmvv
