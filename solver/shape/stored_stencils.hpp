// A step's stencils evaluated once. Under USL the particle-to-grid map and the
// grid-to-particle update weigh the particles at the same positions, domains
// and deformation gradients (nothing moves a particle between them), so their
// stencils are the same. For a shape whose evaluation is costly (exact CPDI,
// cpdi_exact.hpp: a polygon clipped against every cell its domain meets, half
// of its step's instructions when evaluated twice) the map records each
// particle's stencil and the update reads it back, bit for bit what it would
// have evaluated. Two types, so that the choice is made once per stage and
// each loop stays free of a branch per particle.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

#include "../geometry.hpp"

#include "stencil.hpp"

namespace mpmvv {

// Whether a shape asks for its stencils to be stored between the map and the
// update (its `stores_stencils` trait).
template <class Shape>
inline constexpr bool kStoresStencils = [] {
  if constexpr (requires { Shape::stores_stencils; }) return Shape::stores_stencils;
  return false;
}();

// Copies the entries of a stencil that are in use (its first `count`; the
// hoop weights only in r-z, where a shape sets them).
template <class Shape>
void copy_stencil(const Stencil<Shape::stencil_size>& from, Stencil<Shape::stencil_size>& to) {
  const int n = from.count;
  to.count = n;
  std::copy_n(from.node, n, to.node);
  std::copy_n(from.weight, n, to.weight);
  std::copy_n(from.gradient, n, to.gradient);
  if constexpr (Shape::geometry == Geometry::axisymmetric) std::copy_n(from.hoop, n, to.hoop);
}

// Evaluates as Shape does and keeps each stencil in `store` (one per particle).
template <class Shape>
struct StencilRecorder : Shape {
  Stencil<Shape::stencil_size>* store;
  void evaluate(std::size_t p, Stencil<Shape::stencil_size>& s) const {
    Shape::evaluate(p, s);
    copy_stencil<Shape>(s, store[p]);
  }
};

// Reads back what a StencilRecorder of the same step kept.
template <class Shape>
struct StencilReader : Shape {
  const Stencil<Shape::stencil_size>* store;
  void evaluate(std::size_t p, Stencil<Shape::stencil_size>& s) const { copy_stencil<Shape>(store[p], s); }
};

}  // namespace mpmvv
