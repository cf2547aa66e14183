// Internal (dynid::detail, not API): the fields of a model file and what the reader of
// model_file.hpp does with a JSON object of them. The lists are Python's
// (dynid.model.model_files.FIELDS and METADATA); tests/test_cpp_load_model.py checks that they
// stay the same.
#pragma once

#include <array>

#include "dynid/detail/json.hpp"
#include "dynid/model.hpp"

namespace dynid::detail {

// The model's fields, in the order Python writes them (robot_fields.FIELDS' file keys).
constexpr std::array<const char*, 19> kModelFileFields = {"name",
                                                          "convention",
                                                          "joint_types",
                                                          "gravity",
                                                          "rows",
                                                          "base",
                                                          "tool",
                                                          "joint_names",
                                                          "link_names",
                                                          "qlim",
                                                          "velocity_limits",
                                                          "effort_limits",
                                                          "params",
                                                          "Ia",
                                                          "Fv",
                                                          "Fs",
                                                          "transmission",
                                                          "gear_ratios",
                                                          "joint_offsets"};

// Fields a model file may hold besides the model (ignored).
constexpr std::array<const char*, 6> kModelFileMetadata = {"format", "version", "description",
                                                           "notes",  "source",  "units"};

// A Model from the parsed content of a model file (Python's model_from_dict): every value is
// checked for its type and shape first, then the Model's setters check what they need. Throws
// std::invalid_argument naming the field ("rows[2].alpha: expected a finite number, got true").
Model model_from_json(const JsonValue& data);

}  // namespace dynid::detail
