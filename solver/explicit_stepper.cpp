// The one dispatch of the explicit step: make_stepper checks the options
// (explicit/options.cpp) and instantiates the stepper (explicit/schemes.hpp)
// for the run's geometry, shape and material.
#include "explicit_stepper.hpp"

#include <optional>
#include <stdexcept>

#include "explicit/options.hpp"
#include "explicit/schemes.hpp"
#include "explicit/settings.hpp"
#include "shape/bspline.hpp"
#include "shape/cpdi.hpp"
#include "shape/cpdi_exact.hpp"
#include "shape/gimp.hpp"
#include "shape/linear.hpp"
#include "shape/total_lagrangian.hpp"

namespace mpmvv {

namespace {

template <class Shape>
std::unique_ptr<Stepper> make_for_shape(Model model, const SolverOptions& o, const MaterialModel& material,
                                        SceneStages stages) {
  return std::visit(
      [&](const auto& m) -> std::unique_ptr<Stepper> {
        using Material = std::decay_t<decltype(m)>;
        std::optional<Material> second;
        if (stages.second_material) {
          const Material* same = std::get_if<Material>(&*stages.second_material);
          if (!same) throw std::invalid_argument("the second material must be a model of the same kind as the first");
          second = *same;
        }
        const StepSettings settings = step_settings(o, model.grid.h);
        return std::make_unique<ExplicitStepper<Shape, Material>>(std::move(model), settings, m, std::move(second),
                                                                 std::move(stages));
      },
      material);
}

template <Geometry G>
std::unique_ptr<Stepper> make_for_geometry(Model model, const SolverOptions& o, const MaterialModel& material,
                                           SceneStages stages) {
  if constexpr (G == Geometry::plane_strain)
    if (o.formulation == Formulation::total) switch (o.method) {
        case Method::gimp: return make_for_shape<TotalLagrangianGimpShape>(std::move(model), o, material, std::move(stages));
        case Method::cpdi: return make_for_shape<TotalLagrangianCpdiShape>(std::move(model), o, material, std::move(stages));
        case Method::cpdi_exact:
          return make_for_shape<TotalLagrangianCpdiExactShape>(std::move(model), o, material, std::move(stages));
        case Method::linear:
          return make_for_shape<TotalLagrangianLinearShape>(std::move(model), o, material, std::move(stages));
        case Method::bspline:
          return make_for_shape<TotalLagrangianShapeT<BsplineShape>>(std::move(model), o, material, std::move(stages));
        case Method::bspline_cubic:
          return make_for_shape<TotalLagrangianShapeT<CubicBsplineShape>>(std::move(model), o, material,
                                                                          std::move(stages));
      }
  switch (o.method) {
    case Method::linear: return make_for_shape<LinearShapeT<G>>(std::move(model), o, material, std::move(stages));
    case Method::gimp: return make_for_shape<GimpShapeT<G>>(std::move(model), o, material, std::move(stages));
    case Method::cpdi:
      if constexpr (G == Geometry::plane_strain) {
        if (o.min_domain_angle > 0.0)
          return make_for_shape<CpdiShapeT<G, CpdiForm::turned>>(std::move(model), o, material, std::move(stages));
        if (o.cpdi_domain == CpdiDomain::corners)
          return make_for_shape<CpdiShapeT<G, CpdiForm::corners>>(std::move(model), o, material, std::move(stages));
      }
      return make_for_shape<CpdiShapeT<G>>(std::move(model), o, material, std::move(stages));
    case Method::cpdi_exact:
      if constexpr (G == Geometry::plane_strain)
        if (o.cpdi_domain == CpdiDomain::corners)
          return make_for_shape<CpdiExactShapeT<G, true>>(std::move(model), o, material, std::move(stages));
      return make_for_shape<CpdiExactShapeT<G>>(std::move(model), o, material, std::move(stages));
    case Method::bspline:
    case Method::bspline_cubic:
      if constexpr (G == Geometry::plane_strain) {
        if (o.method == Method::bspline)
          return make_for_shape<BsplineShape>(std::move(model), o, material, std::move(stages));
        return make_for_shape<CubicBsplineShape>(std::move(model), o, material, std::move(stages));
      } else {
        throw std::logic_error("B-splines in r-z (make_stepper refuses them)");
      }
  }
  throw std::logic_error("unknown method");
}

}  // namespace

std::unique_ptr<Stepper> make_stepper(Model model, const SolverOptions& options,
                                      const MaterialModel& material,
                                      std::shared_ptr<BodyForce> body_force) {
  SceneStages stages;
  stages.body_force = std::move(body_force);
  return make_stepper(std::move(model), options, material, std::move(stages));
}

std::unique_ptr<Stepper> make_stepper(Model model, const SolverOptions& options,
                                      const MaterialModel& material, SceneStages stages) {
  check_explicit_options(model, options, stages);
  if (options.geometry == Geometry::axisymmetric)
    return make_for_geometry<Geometry::axisymmetric>(std::move(model), options, material, std::move(stages));
  return make_for_geometry<Geometry::plane_strain>(std::move(model), options, material, std::move(stages));
}

}  // namespace mpmvv
