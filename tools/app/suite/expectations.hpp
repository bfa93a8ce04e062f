// A suite's [[expect]] tables (suites/README.md): what the gate holds each
// study to, an observed order within a band, a bound on the error, or both.
// Checked here, once, against the studies and their cases; the manifest
// records them as JSON for the gate and the report, which check nothing of
// them again.
#pragma once

#include <map>
#include <string>

#include <toml++/toml.h>

#include "study.hpp"
#include "suite.hpp"

namespace mpmvv::app::suite_file {

// Reads every [[expect]] of suite file `path` (its top table `top`) into
// `suite.expectations`, with a warning in `suite.warnings` for one read where
// the exact signal is trivial. Throws ConfigError naming the first mistake.
void read_expectations(const toml::table& top, const std::string& path, const std::map<std::string, Study>& studies,
                       Suite& suite);

}  // namespace mpmvv::app::suite_file
