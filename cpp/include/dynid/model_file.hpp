// A Model from the files Python writes, so that a model identified in Python runs in a C++ loop
// with nothing retyped (docs/cpp.md, "An identified model in C++"):
//
// - a model file in JSON (dynid.save_model(robot, "arm.json"); the format of docs/cli.md, "Model
//   files"): the DH table and every field of dynid.model.robot_fields.FIELDS, read by the rules of
//   Python's dynid.load_model (required `convention` and `rows`, the row aliases `a_prev`,
//   `alpha_prev`, `theta_offset`, (n, 10) or 10n params, null meaning the default, unknown fields
//   refused, metadata `format`, `version`, `description`, `notes`, `source`, `units` ignored);
// - the identified model of a physically consistent result (`dynid identify LOG --physical
//   --output DIR`): the folder DIR or DIR/result.json, format "dynid-identification", versions
//   1 to 3 as Python's dynid.load_result reads them; its `model` entry is the identified robot
//   (dynid.load_result(DIR).robot). Only `format`, `version`, `model` and `physical` are read:
//   the coefficients and statistics are not needed for the model.
//
// Refused, each with a std::invalid_argument whose message starts with the file's path and then
// names the field ("arm.json: params: expected numbers of shape (7, 10), got shape (6, 10)",
// "arm.json: rows[3]: not valid JSON: unexpected end of the file ... (line 9, column 1)"): a
// least-squares result (base parameters only, no full robot: the message says to identify with
// --physical), YAML model files (the message says how to convert them to JSON), files over 16 MiB
// (results: 64 MiB), text that is not strict JSON (detail/json.hpp), and every value Python's
// loader or the Model's setters refuse.
//
// Loading allocates (call it at start-up); the Model it returns is evaluated with a Workspace as
// any other, without allocation.
#pragma once

#include <string>
#include <string_view>

#include "dynid/model.hpp"

namespace dynid {

// A model file (.json) or an identification result (its folder, or a file named result.json).
Model load_model(const std::string& path);

// The model of a model file's JSON text; `source` names the text in messages.
Model parse_model(std::string_view json, const std::string& source = "model");

}  // namespace dynid
