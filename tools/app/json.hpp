// The JSON the application writes (the suite's manifest and case files,
// `mms eval --json`): nlohmann's, its objects' members in the order written.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "config.hpp"

namespace mpmvv::app {

using Json = nlohmann::ordered_json;

// JSON's text: a NaN or an infinity is written null, and bytes that are not
// UTF-8 (a solver's message) as U+FFFD, so the text always parses.
inline std::string json_text(const Json& j, int indent = -1) {
  return j.dump(indent, ' ', false, Json::error_handler_t::replace);
}

// A configuration value as JSON: a number, a string or a list of numbers.
inline Json json_of(const Value& v) {
  return std::visit([](const auto& x) { return Json(x); }, v);
}

}  // namespace mpmvv::app
