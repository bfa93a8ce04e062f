// The memory a stepper reports per particle (Stepper::bytes_per_particle):
// every array it holds, and what its body force keeps.
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "solver_models.hpp"

#include "solver/explicit_stepper.hpp"

namespace {

using namespace mpmvv::testing::solver_models;  // the models and the solver's names they use

// The memory a run holds per particle (Stepper::bytes_per_particle, the
// throughput benchmark's bytes column): linear MPM's eight arrays, x, v, F,
// V, sigma, m, V0 and X (16 + 16 + 32 + 8 + 32 + 8 + 8 + 16 = 136 bytes); GIMP
// adds its half sizes (16); MUSL's stepper its next positions (16).
TEST(Stepper, BytesPerParticleCountEveryArrayItHolds) {
  auto linear = mpmvv::make_stepper(disk_model(Method::linear), SolverOptions{Method::linear, Scheme::usl},
                                    MaterialModel{kSolid}, nullptr);
  EXPECT_EQ(linear->bytes_per_particle(), 136.0);
  auto gimp = mpmvv::make_stepper(disk_model(Method::gimp), SolverOptions{Method::gimp, Scheme::usl},
                                  MaterialModel{kSolid}, nullptr);
  EXPECT_EQ(gimp->bytes_per_particle(), 152.0);
  auto musl = mpmvv::make_stepper(disk_model(Method::gimp), SolverOptions{Method::gimp, Scheme::musl},
                                  MaterialModel{kSolid}, nullptr);
  EXPECT_EQ(musl->bytes_per_particle(), 168.0);
}

// A body force's own arrays count too (BodyForce::bytes): here 40 bytes a
// particle beside linear MPM's 136 and the body-force array b_p (16).
class KeepingBodyForce final : public mpmvv::BodyForce {
 public:
  void prepare(const Particles& P) override { kept_.assign(5 * P.size(), 0.0); }
  void evaluate(double, const Particles&, std::vector<Vec2>& b) const override {
    for (Vec2& v : b) v.setZero();
  }
  std::size_t bytes() const override { return mpmvv::bytes_held(kept_); }

 private:
  std::vector<double> kept_;
};

TEST(Stepper, BytesPerParticleCountWhatTheBodyForceKeeps) {
  auto stepper = mpmvv::make_stepper(disk_model(Method::linear), SolverOptions{Method::linear, Scheme::usl},
                                     MaterialModel{kSolid}, std::make_shared<KeepingBodyForce>());
  EXPECT_EQ(stepper->bytes_per_particle(), 136.0 + 16.0 + 40.0);
}

}  // namespace
