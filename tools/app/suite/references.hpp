// A suite's [[reference]] tables (suites/README.md): published numbers the
// report sets beside the suite's own, e.g. the time each run of another code
// reached, the error it reached, or the order it observed. They check
// nothing; the gate ignores them.
#pragma once

#include <map>
#include <string>

#include <toml++/toml.h>

#include "study.hpp"
#include "suite.hpp"

namespace mpmvv::app::suite_file {

// Checks that each [[reference]] of suite file `path` names studies of the
// suite, keys of their scenes, and rows that match cases; throws ConfigError
// naming the first that does not. The report reads them from the suite file.
void check_references(const toml::table& top, const std::string& path, const std::map<std::string, Study>& studies,
                      const Suite& suite);

}  // namespace mpmvv::app::suite_file
