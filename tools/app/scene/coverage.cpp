#include "coverage.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include "solver/io/state_archive.hpp"

namespace mpmvv::app {

namespace {

// The crossing number of a ray from x towards +x through the outline's sides.
bool contains(const Vec2* v, std::size_t count, const Vec2& x) {
  bool in = false;
  for (std::size_t i = 0, j = count - 1; i < count; j = i++) {
    const Vec2& a = v[i];
    const Vec2& b = v[j];
    if ((a.y() > x.y()) != (b.y() > x.y()) && x.x() < a.x() + (b.x() - a.x()) * (x.y() - a.y()) / (b.y() - a.y()))
      in = !in;
  }
  return in;
}

struct Box {
  Vec2 low, high;
  bool finite() const { return low.allFinite() && high.allFinite(); }
};

Box box_of(const DomainPolygons& d, std::size_t p) {
  Box b{Vec2::Constant(std::numeric_limits<double>::infinity()),
        Vec2::Constant(-std::numeric_limits<double>::infinity())};
  for (std::size_t k = d.first[p]; k < d.first[p + 1]; ++k) {
    b.low = b.low.cwiseMin(d.vertex[k]);
    b.high = b.high.cwiseMax(d.vertex[k]);
  }
  return b;
}

// Lattice point k's place within its square of the lattice, (u, v) in
// [0, 1)^2, from a hash of k (splitmix64): jittered rather than at the
// square's centre, so that a lattice aligned with the seeding's rows does
// not alias with the thin gaps that open along the domains' sides (centred,
// 2 samples gave 3.4 % of the ring in holes at t = 0.1 s where 16 gave 1.5 %).
Vec2 jitter(std::uint64_t k) {
  auto next = [&k]() {
    std::uint64_t z = (k += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return double((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
  };
  const double u = next();
  return {u, next()};
}

// Union-find over the hole points, by index into the sorted list.
std::size_t root(std::vector<std::size_t>& parent, std::size_t k) {
  while (parent[k] != k) k = parent[k] = parent[parent[k]];
  return k;
}

// The particles' displacement errors e_q = x_q - x_exact(X_q, t) as a field
// over the reference body: at X the mean of the e_q of the particles within
// one particle spacing l along each axis, weighted by the tent
// (1 - |X - X_q|_x / l)(1 - |X - X_q|_y / l) (bilinear interpolation where
// the particles sit on the seeding's rows, Shepard's normalisation at the
// sides and between cut pieces).
class ErrorField {
 public:
  ErrorField(const Particles& P, const mms::ExactSolution& solution, double t, double l) : P_(P), l_(l) {
    const std::size_t n = P.size();
    error_.resize(n);
#pragma omp parallel for schedule(static)
    for (std::size_t q = 0; q < n; ++q) error_[q] = P.position[q] - solution.position(P.reference_position[q], t);
    if (n == 0 || !(l > 0.0)) return;
    low_ = P.reference_position[0];
    Vec2 high = low_;
    for (const Vec2& X : P.reference_position) {
      low_ = low_.cwiseMin(X);
      high = high.cwiseMax(X);
    }
    nx_ = std::int64_t((high.x() - low_.x()) / l) + 1;
    ny_ = std::int64_t((high.y() - low_.y()) / l) + 1;
    start_.assign(std::size_t(nx_ * ny_) + 1, 0);
    for (const Vec2& X : P.reference_position) ++start_[bucket(X) + 1];
    std::partial_sum(start_.begin(), start_.end(), start_.begin());
    entry_.resize(n);
    std::vector<std::size_t> fill(start_.begin(), start_.end() - 1);
    for (std::size_t q = 0; q < n; ++q) entry_[fill[bucket(P.reference_position[q])]++] = q;
  }
  // The interpolated error at X, or `fallback` where no particle is near.
  Vec2 at(const Vec2& X, const Vec2& fallback) const {
    if (start_.empty()) return fallback;
    const std::int64_t i = std::int64_t(std::floor((X.x() - low_.x()) / l_));
    const std::int64_t j = std::int64_t(std::floor((X.y() - low_.y()) / l_));
    Vec2 sum = Vec2::Zero();
    double weight = 0.0;
    for (std::int64_t b = std::max<std::int64_t>(0, j - 1); b <= std::min(ny_ - 1, j + 1); ++b)
      for (std::int64_t a = std::max<std::int64_t>(0, i - 1); a <= std::min(nx_ - 1, i + 1); ++a) {
        const std::size_t k = std::size_t(b * nx_ + a);
        for (std::size_t e = start_[k]; e < start_[k + 1]; ++e) {
          const std::size_t q = entry_[e];
          const Vec2 d = (X - P_.reference_position[q]).cwiseAbs() / l_;
          const double w = std::max(0.0, 1.0 - d.x()) * std::max(0.0, 1.0 - d.y());
          if (w > 0.0 && error_[q].allFinite()) {
            sum += w * error_[q];
            weight += w;
          }
        }
      }
    return weight > 0.0 ? Vec2(sum / weight) : fallback;
  }
  const Vec2& of(std::size_t q) const { return error_[q]; }

 private:
  std::size_t bucket(const Vec2& X) const {
    const std::int64_t i = std::min(nx_ - 1, std::int64_t((X.x() - low_.x()) / l_));
    const std::int64_t j = std::min(ny_ - 1, std::int64_t((X.y() - low_.y()) / l_));
    return std::size_t(j * nx_ + i);
  }
  const Particles& P_;
  double l_;
  std::vector<Vec2> error_;
  Vec2 low_ = Vec2::Zero();
  std::int64_t nx_ = 0, ny_ = 0;
  std::vector<std::size_t> start_, entry_;
};

}  // namespace

DomainIndex::DomainIndex(const DomainPolygons& domains) : domains_(&domains) {
  const std::size_t n = domains.size();
  if (n == 0) return;
  if (n >= std::numeric_limits<std::uint32_t>::max()) throw std::length_error("too many domains to index");
  std::vector<Box> boxes(n);
  Vec2 low = Vec2::Constant(std::numeric_limits<double>::infinity()), high = -low;
  double width = 0.0;
  std::size_t kept = 0;
  for (std::size_t p = 0; p < n; ++p) {
    boxes[p] = box_of(domains, p);
    if (!boxes[p].finite()) continue;  // a domain gone to NaN contains no point
    low = low.cwiseMin(boxes[p].low);
    high = high.cwiseMax(boxes[p].high);
    width += (boxes[p].high - boxes[p].low).maxCoeff();
    ++kept;
  }
  if (kept == 0) return;
  low_ = low;
  // Buckets about a domain across (at most 4096 along a side); doubled while
  // stretched domains would list more than 16 entries a domain.
  bucket_ = std::max({width / double(kept), (high - low).maxCoeff() / 4096.0, 1e-300});
  for (;;) {
    nx_ = int(std::floor((high.x() - low.x()) / bucket_)) + 1;
    ny_ = int(std::floor((high.y() - low.y()) / bucket_)) + 1;
    std::size_t entries = 0;
    for (const Box& b : boxes)
      if (b.finite())
        entries += std::size_t(int((b.high.x() - low.x()) / bucket_) - int((b.low.x() - low.x()) / bucket_) + 1) *
                   std::size_t(int((b.high.y() - low.y()) / bucket_) - int((b.low.y() - low.y()) / bucket_) + 1);
    if (entries <= 16 * kept + std::size_t(nx_) * std::size_t(ny_) || (nx_ == 1 && ny_ == 1)) break;
    bucket_ *= 2.0;
  }
  start_.assign(std::size_t(nx_) * std::size_t(ny_) + 1, 0);
  auto range = [&](const Box& b, int& i0, int& i1, int& j0, int& j1) {
    i0 = int((b.low.x() - low_.x()) / bucket_);
    i1 = std::min(nx_ - 1, int((b.high.x() - low_.x()) / bucket_));
    j0 = int((b.low.y() - low_.y()) / bucket_);
    j1 = std::min(ny_ - 1, int((b.high.y() - low_.y()) / bucket_));
  };
  int i0, i1, j0, j1;
  for (const Box& b : boxes) {
    if (!b.finite()) continue;
    range(b, i0, i1, j0, j1);
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) ++start_[std::size_t(j) * nx_ + i + 1];
  }
  std::partial_sum(start_.begin(), start_.end(), start_.begin());
  entry_.resize(start_.back());
  std::vector<std::uint32_t> fill(start_.begin(), start_.end() - 1);
  for (std::size_t p = 0; p < n; ++p) {
    if (!boxes[p].finite()) continue;
    range(boxes[p], i0, i1, j0, j1);
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) entry_[fill[std::size_t(j) * nx_ + i]++] = std::uint32_t(p);
  }
}

std::uint32_t DomainIndex::holder(const Vec2& x) const {
  if (start_.empty() || !x.allFinite()) return kNone;
  const double u = (x.x() - low_.x()) / bucket_, v = (x.y() - low_.y()) / bucket_;
  if (!(u >= 0.0 && v >= 0.0 && u < nx_ && v < ny_)) return kNone;
  const std::size_t b = std::size_t(int(v)) * nx_ + std::size_t(int(u));
  const DomainPolygons& d = *domains_;
  for (std::uint32_t k = start_[b]; k < start_[b + 1]; ++k) {
    const std::size_t p = entry_[k];
    if (contains(&d.vertex[d.first[p]], d.first[p + 1] - d.first[p], x)) return std::uint32_t(p);
  }
  return kNone;
}

Vec2 DomainCoverage::point(std::int64_t i, std::int64_t j) const {
  return origin_ + spacing_ * (Vec2(double(i), double(j)) + jitter(std::uint64_t(j * nx_ + i)));
}

void DomainCoverage::start(const DomainPolygons& domains, double spacing, double particle_spacing) {
  rows_.clear();
  owner_.clear();
  at_side_.clear();
  body_points_ = 0;
  spacing_ = spacing;
  particle_spacing_ = particle_spacing;
  if (domains.size() == 0 || !(spacing > 0.0)) return;
  Vec2 low = Vec2::Constant(std::numeric_limits<double>::infinity()), high = -low;
  for (const Vec2& v : domains.vertex)
    if (v.allFinite()) {
      low = low.cwiseMin(v);
      high = high.cwiseMax(v);
    }
  if (!low.allFinite()) return;
  origin_ = low;
  nx_ = std::int64_t(std::ceil((high.x() - low.x()) / spacing));
  ny_ = std::int64_t(std::ceil((high.y() - low.y()) / spacing));
  owner_.assign(std::size_t(nx_ * ny_), DomainIndex::kNone);
  const DomainIndex index(domains);
  std::size_t count = 0;
#pragma omp parallel for schedule(static) reduction(+ : count)
  for (std::int64_t j = 0; j < ny_; ++j)
    for (std::int64_t i = 0; i < nx_; ++i) {
      const std::uint32_t p = index.holder(point(i, j));
      owner_[std::size_t(j * nx_ + i)] = p;
      if (p != DomainIndex::kNone) ++count;
    }
  body_points_ = count;
  // The particles whose domains hold a point of the body's edge on the lattice.
  at_side_.assign(domains.size(), 0);
  for (std::int64_t j = 0; j < ny_; ++j)
    for (std::int64_t i = 0; i < nx_; ++i) {
      const std::uint32_t p = owner_[std::size_t(j * nx_ + i)];
      if (p == DomainIndex::kNone) continue;
      auto outside = [&](std::int64_t a, std::int64_t b) {
        return a < 0 || b < 0 || a >= nx_ || b >= ny_ || owner_[std::size_t(b * nx_ + a)] == DomainIndex::kNone;
      };
      if (outside(i - 1, j) || outside(i + 1, j) || outside(i, j - 1) || outside(i, j + 1)) at_side_[p] = 1;
    }
}

void DomainCoverage::record(double t, const DomainPolygons& domains, const Particles& P,
                            const mms::ExactSolution& solution) {
  if (!on()) return;
  const DomainIndex index(domains);
  const std::size_t n = P.size();
  const ErrorField error(P, solution, t, particle_spacing_);
  // The uncovered points of each lattice row, in order: the same list for
  // any thread count.
  std::vector<std::vector<std::int64_t>> uncovered(static_cast<std::size_t>(ny_));
#pragma omp parallel for schedule(dynamic, 8)
  for (std::int64_t j = 0; j < ny_; ++j)
    for (std::int64_t i = 0; i < nx_; ++i) {
      const std::int64_t k = j * nx_ + i;
      const std::uint32_t owner = owner_[std::size_t(k)];
      if (owner == DomainIndex::kNone) continue;
      const Vec2 X = point(i, j);
      const Vec2 x = solution.position(X, t) + error.at(X, owner < n ? error.of(owner) : Vec2::Zero());
      if (index.holder(x) == DomainIndex::kNone) uncovered[std::size_t(j)].push_back(k);
    }
  std::vector<std::int64_t> hole;
  for (const auto& row : uncovered) hole.insert(hole.end(), row.begin(), row.end());
  const std::size_t m = hole.size();
  // Current area of each point, d^2 J_exact (the in-plane J: an area of the
  // plane, in r-z of the r-z plane).
  std::vector<double> area(m);
#pragma omp parallel for schedule(static)
  for (std::size_t k = 0; k < m; ++k) {
    const Vec2 X = point(hole[k] % nx_, hole[k] / nx_);
    area[k] = spacing_ * spacing_ * determinant(solution.state(X, t).deformation_gradient);
  }
  std::vector<std::size_t> parent(m);
  std::iota(parent.begin(), parent.end(), std::size_t(0));
  auto find = [&](std::int64_t k) {  // position of lattice point k in the sorted list, or m
    const auto it = std::lower_bound(hole.begin(), hole.end(), k);
    return it != hole.end() && *it == k ? std::size_t(it - hole.begin()) : m;
  };
  for (std::size_t k = 0; k < m; ++k) {
    const std::int64_t i = hole[k] % nx_;
    for (const std::size_t other : {i > 0 ? find(hole[k] - 1) : m, hole[k] >= nx_ ? find(hole[k] - nx_) : m})
      if (other < m) parent[root(parent, k)] = root(parent, other);
  }
  std::vector<double> hole_area(m, 0.0);
  std::size_t inside = 0;
  for (std::size_t k = 0; k < m; ++k) {
    hole_area[root(parent, k)] += area[k];
    const std::uint32_t owner = owner_[std::size_t(hole[k])];
    if (!(owner < at_side_.size() && at_side_[owner])) ++inside;
  }
  const double largest = m ? *std::max_element(hole_area.begin(), hole_area.end()) : 0.0;
  rows_.push_back({t, double(m) / double(body_points_), double(inside) / double(body_points_), largest});
}

void DomainCoverage::persist(StateArchive& a) {
  a.field("coverage_origin", origin_);
  a.field("coverage_spacing", spacing_);
  a.field("coverage_particle_spacing", particle_spacing_);
  a.field("coverage_nx", nx_);
  a.field("coverage_ny", ny_);
  a.field("coverage_owner", owner_);
  a.field("coverage_at_side", at_side_);
  a.field("coverage_points", body_points_);
  a.field("coverage_rows", rows_);
}

}  // namespace mpmvv::app
