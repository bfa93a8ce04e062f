// `mpmvv mms`: the manufactured solutions for a person or a script.
//   list                 the solutions and their parameters
//   eval NAME --at X,Y --time T [--set k=v] [--json]
//                        exact fields and body force at one reference point
//   check NAME [--points N] [--tolerance E] [--set k=v]
//                        the residual a - Div P / rho_0 - b by finite differences
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "config.hpp"
#include "scene/setup.hpp"

namespace mpmvv::app {

// The scene of that name; throws ConfigError naming the known ones.
const SceneType& scene_named(const std::string& name);
// Its setup with its defaults and the overrides "key=value"; throws ConfigError,
// naming an override as `how` says (Config::set_from_text).
SceneSetup setup_for(const SceneType& scene, const std::vector<std::string>& overrides,
                     const std::string& how = "--set");
// The keys that set the scene's solution (its own and its material's), not the run's.
std::vector<KeySpec> solution_parameters(const SceneType& scene);

std::string mms_list();

struct MmsEvalRequest {
  std::string name;
  std::vector<double> at;  // X, Y (R, Z in r-z)
  double time = 0.0;
  std::vector<std::string> overrides;
  bool json = false;
};
// Exit status 0, or 2 on bad input (one line on err).
int mms_eval(const MmsEvalRequest& request, std::ostream& out, std::ostream& err);

struct MmsCheckRequest {
  std::string name;
  int points = 1000;
  double tolerance = 0.0;  // 0: from the differences' own error (mms::judge_residuals)
  unsigned seed = 1;
  std::vector<std::string> overrides;
};
// Exit status 0 when the largest residual, relative to the largest force term
// over the sampled points, is within the tolerance; 1 above; 2 bad input.
int mms_check(const MmsCheckRequest& request, std::ostream& out, std::ostream& err);

}  // namespace mpmvv::app
