#include "model.hpp"

#include <variant>

namespace mpmvv {

const char* to_string(Method m) {
  switch (m) {
    case Method::linear: return "linear";
    case Method::gimp: return "gimp";
    case Method::cpdi: return "cpdi";
    case Method::cpdi_exact: return "cpdi-exact";
    case Method::bspline: return "bspline";
    case Method::bspline_cubic: return "bspline-cubic";
  }
  return "?";
}

const char* to_string(Scheme s) {
  switch (s) {
    case Scheme::usl: return "usl";
    case Scheme::usf: return "usf";
    case Scheme::musl: return "musl";
  }
  return "?";
}

double p_wave_modulus(const MaterialModel& m) {
  return std::visit([](const auto& material) { return material.p_wave_modulus(); }, m);
}

}  // namespace mpmvv
