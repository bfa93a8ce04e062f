// A suite's [[study]]: a scene file, the keys it sets, the lists it sweeps or
// zips and its overrides, expanded into one case for each combination
// (suites/README.md).
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include <toml++/toml.h>

#include "suite.hpp"
#include "tools/app/config.hpp"
#include "tools/app/scene/scene.hpp"

namespace mpmvv::app::suite_file {

struct Study {
  std::vector<KeySpec> keys;         // the keys of its scene
  std::unique_ptr<SceneCase> first;  // its first case, built: what is known before a run (the levels share the motion)
  bool in_tier = true;               // whether the tier loaded runs it (a ci tier leaves out a study without `ci`)
};

// Reads the [[study]] table `node` of suite file `path` and appends its cases
// to `suite.cases` (those of the tier `suite.tier`: a study's `ci` table's
// keys replace its own there), each built once to check the scene's rules between keys;
// `studies` are those read before it. Throws ConfigError naming the file,
// line and key of the first mistake.
std::pair<std::string, Study> expand_study(const toml::node& node, const std::string& path,
                                           const std::map<std::string, Study>& studies, Suite& suite);

}  // namespace mpmvv::app::suite_file
