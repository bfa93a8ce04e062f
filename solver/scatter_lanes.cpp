// The kernel of scatter_lanes.hpp (lane_vectors.hpp says how it is built).
// Each line is the scalar line of particles_to_grid's map it repeats.
#include "scatter_lanes.hpp"

#include <utility>

#include "lane_vectors.hpp"

namespace mpmvv {

namespace {

using namespace lanes::MPMVV_LANE_BUILD_NS;

// A block's row of nodes as one vector, whatever the build's width: three
// nodes and the node after, or a row of two.
template <int Rows>
using RowOf = typename Width<Rows == 2 ? 2 : 4>::Lanes;

template <int Rows>
MPMVV_LANE_INLINE RowOf<Rows> row_of(const double (*slot)[kLanes], int b, int l) {
  if constexpr (Rows == 2) return RowOf<Rows>{slot[3 * b][l], slot[3 * b + 1][l]};
  else return RowOf<Rows>{slot[3 * b][l], slot[3 * b + 1][l], slot[3 * b + 2][l], 0.0};
}

template <class Row>
MPMVV_LANE_INLINE void add_row(double* at, const Row& v) {
  store(at, load<Row>(at) + v);
}

template <int Rows, bool Mass, bool Momentum, bool Internal, bool Body>
void scatter(const ScatterParticles& P, const ScatterLaneBatch& in, const ScatterRows& out) {
  // Restricted copies: no store to a sum can change where the next goes.
  double* __restrict mass = out.mass;
  double* __restrict momentum_x = out.momentum_x;
  double* __restrict momentum_y = out.momentum_y;
  double* __restrict force_x = out.force_x;
  double* __restrict force_y = out.force_y;
  const std::ptrdiff_t row = out.row;
  // The particles' arrays and the batch's slots held in locals: read through
  // P and `in` they were loaded again after every store to a sum, which the
  // compiler cannot tell apart from them (14 instructions a particle,
  // callgrind).
  const double* const mass_of = P.mass;
  const double* const velocity = P.velocity;
  const double* const volume = P.volume;
  const double* const stress = P.stress;
  const double* const body_force = P.body_force;
  const double(*const weight)[kLanes] = in.weight;
  const double(*const gradient_x)[kLanes] = in.gradient_x;
  const double(*const gradient_y)[kLanes] = in.gradient_y;
  const double(*const corner_weight)[kLanes] = in.corner_weight;
  const double(*const corner_gradient_x)[kLanes] = in.corner_gradient_x;
  const double(*const corner_gradient_y)[kLanes] = in.corner_gradient_y;
  const int(*const corner_first)[kLanes] = in.corner_first;
  for (int l = 0; l < kLanes; ++l) {
    if (!((in.pending >> l) & 1u)) continue;
    const std::size_t p = in.first + std::size_t(l);
    // The particle's factors: m, m v_p, V_p sigma_p, m b_p.
    const double m = mass_of[p];
    double px = 0.0, py = 0.0, sxx = 0.0, syx = 0.0, sxy = 0.0, syy = 0.0, bx = 0.0, by = 0.0;
    if constexpr (Momentum) px = m * velocity[2 * p], py = m * velocity[2 * p + 1];
    if constexpr (Internal) {
      const double V = volume[p];
      sxx = V * stress[4 * p], syx = V * stress[4 * p + 1];
      sxy = V * stress[4 * p + 2], syy = V * stress[4 * p + 3];
    }
    if constexpr (Body) bx = m * body_force[2 * p], by = m * body_force[2 * p + 1];
    // A row of nodes from `at`, its weights w and its gradients' rows from
    // gradients() (read only where the internal force asks for them).
    auto add = [&]<class Row>(std::ptrdiff_t at, const Row& w, auto gradients) __attribute__((always_inline)) {
      if constexpr (Mass) add_row(mass + at, w * m);  // node.mass += w * m
      if constexpr (Momentum) {
        add_row(momentum_x + at, w * px);
        add_row(momentum_y + at, w * py);
      }
      if constexpr (Internal || Body) {
        // f = 0; f -= (V_p sigma_p) G_gp; f += w (m_p b_p); node.force += f.
        // With both terms, w (m_p b_p) - (V_p sigma_p) G_gp: (0 - a) + c is
        // c - a but for the sign of a zero result, which leaves a sum from +0
        // as it is (one instruction a row and component less).
        Row fx = {}, fy = {};
        if constexpr (Internal) {
          Row gx, gy;
          gradients(gx, gy);
          if constexpr (Body) {
            fx = w * bx - (sxx * gx + sxy * gy);
            fy = w * by - (syx * gx + syy * gy);
          } else {
            fx = fx - (sxx * gx + sxy * gy);
            fy = fy - (syx * gx + syy * gy);
          }
        } else if constexpr (Body) {
          fx = fx + w * bx;
          fy = fy + w * by;
        }
        add_row(force_x + at, fx);
        add_row(force_y + at, fy);
      }
    };
    const std::ptrdiff_t first_node = in.first_node[l];
    if (Rows == 2 || first_node != kByCorners) {
      for (int b = 0; b < Rows; ++b)
        add(first_node + b * row, row_of<Rows>(weight, b, l), [&](RowOf<Rows>& gx, RowOf<Rows>& gy) {
          gx = row_of<Rows>(gradient_x, b, l);
          gy = row_of<Rows>(gradient_y, b, l);
        });
    } else {
      // Corner by corner, each its cell's two rows of two nodes: slots
      // 4 c + 2 b and 4 c + 2 b + 1.
      using Pair = RowOf<2>;
      for (int c = 0; c < 4; ++c)
        for (int b = 0; b < 2; ++b) {
          const int s = 4 * c + 2 * b;
          add(corner_first[c][l] + b * row, Pair{corner_weight[s][l], corner_weight[s + 1][l]},
              [&](Pair& gx, Pair& gy) {
                gx = Pair{corner_gradient_x[s][l], corner_gradient_x[s + 1][l]};
                gy = Pair{corner_gradient_y[s][l], corner_gradient_y[s + 1][l]};
              });
        }
    }
  }
}

using Kernel = void (*)(const ScatterParticles&, const ScatterLaneBatch&, const ScatterRows&);

// Kernel k adds the fields of the bits of k (mass, momentum, internal force,
// body force) of blocks of 3 rows, and kernel 16 + k the same of 2 rows; a
// plain array, since this unit emits no library function
// (shape/lane_shared.hpp says why).
template <std::size_t... K>
struct Kernels {
  static constexpr Kernel table[] = {
      &scatter<(K & 16u) != 0 ? 2 : 3, (K & 1u) != 0, (K & 2u) != 0, (K & 4u) != 0, (K & 8u) != 0>...};
};
template <std::size_t... K>
Kernels<K...> kernels_of(std::index_sequence<K...>);

}  // namespace

namespace lanes::MPMVV_LANE_BUILD_NS {
void scatter_lanes(const ScatterFields& fields, const ScatterParticles& P, const ScatterLaneBatch& batch,
                   const ScatterRows& out) {
  // One kernel per choice of fields, chosen once per batch.
  using Table = decltype(kernels_of(std::make_index_sequence<32>{}));
  const unsigned k = (fields.mass ? 1u : 0u) | (fields.momentum ? 2u : 0u) | (fields.internal_force ? 4u : 0u) |
                     (fields.body_force ? 8u : 0u) | (batch.block == 2 ? 16u : 0u);
  Table::table[k](P, batch, out);
}
}  // namespace lanes::MPMVV_LANE_BUILD_NS

#if defined(MPMVV_LANE_DISPATCH)
void scatter_lanes(LaneBuild build, const ScatterFields& fields, const ScatterParticles& P, ScatterLaneBatch& batch,
                   const ScatterRows& out) {
  MPMVV_LANE_BUILD_CALL(build, scatter_lanes(fields, P, batch, out));
  batch.pending = 0;
}

void scatter_lanes(const ScatterFields& fields, const ScatterParticles& P, ScatterLaneBatch& batch,
                   const ScatterRows& out) {
  scatter_lanes(lane_build(), fields, P, batch, out);
}
#endif

}  // namespace mpmvv
