// A Model from the parsed content of a model file: Python's dynid.model.model_files.model_from_dict
// line for line (the same checks in the same order, the same messages), so that a file means the
// same model, or the same error, on both sides.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "dynid/detail/model_file_fields.hpp"

namespace dynid::detail {
namespace {

using Kind = JsonValue::Kind;

// The most joints a model file may hold (dynid._checks.MAX_JOINTS, shared with URDF reading).
constexpr int kMaxJoints = 64;

[[noreturn]] void refuse(const std::string& message) { throw std::invalid_argument(message); }

std::string format_number(double x) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", x);
  return buffer;
}

// What a message shows of a value: a string in quotes, a number, or its kind (at most 60 chars).
std::string describe(const JsonValue& v) {
  if (v.kind == Kind::String) {
    std::string shown = "'" + v.text + "'";
    return shown.size() > 60 ? shown.substr(0, 57) + "..." : shown;
  }
  if (v.kind == Kind::Number) return format_number(v.number);
  if (v.kind == Kind::Bool) return v.boolean ? "true" : "false";
  if (v.kind == Kind::Array) return "a list of " + std::to_string(v.items.size());
  return json_kind_name(v.kind);
}

std::string shape_text(const std::vector<int>& shape) {
  std::string text = "(";
  for (std::size_t k = 0; k < shape.size(); ++k) text += (k ? ", " : "") + std::to_string(shape[k]);
  return text + (shape.size() == 1 ? ",)" : ")");  // Python's tuple notation
}

// The shape of nested lists of numbers as numpy sees it; false when ragged or not numbers (a
// string, true/false, null or an object anywhere).
bool numeric_shape(const JsonValue& v, std::vector<int>& shape) {
  if (v.kind == Kind::Number) return true;
  if (v.kind != Kind::Array) return false;
  shape.push_back(static_cast<int>(v.items.size()));
  if (v.items.empty()) return true;
  std::vector<int> first;
  if (!numeric_shape(v.items[0], first)) return false;
  for (std::size_t k = 1; k < v.items.size(); ++k) {
    std::vector<int> other;
    if (!numeric_shape(v.items[k], other) || other != first) return false;
  }
  shape.insert(shape.end(), first.begin(), first.end());
  return true;
}

void flatten(const JsonValue& v, std::vector<double>& out) {
  if (v.kind == Kind::Number) {
    out.push_back(v.number);
    return;
  }
  for (const JsonValue& item : v.items) flatten(item, out);
}

// Python's _numbers: a float array of `shape` from nested lists (10n accepted for (n, 10)),
// finite. Returned row-major, flat.
std::vector<double> numbers(const JsonValue& v, const std::string& where,
                            const std::vector<int>& shape) {
  std::vector<int> got;
  const bool regular = numeric_shape(v, got);
  const bool flat_params =
      shape.size() == 2 && shape[1] == 10 && got == std::vector<int>{shape[0] * 10};
  if (!regular || !(got == shape || flat_params))
    refuse(where + ": expected numbers of shape " + shape_text(shape) + ", got " +
           (regular ? "shape " + shape_text(got) : describe(v)));
  std::vector<double> values;
  flatten(v, values);
  for (double x : values)
    if (!std::isfinite(x)) refuse(where + ": contains NaN or inf");
  return values;
}

double number(const JsonValue& v, const std::string& where) {
  if (v.kind != Kind::Number || !std::isfinite(v.number))
    refuse(where + ": expected a finite number, got " + describe(v));
  return v.number;
}

// Row i of the DH table: [a, alpha, d, theta] or an object of them (aliases per convention:
// a_prev, alpha_prev in modified DH, theta_offset in both).
DHRow row(const JsonValue& v, int i, bool modified) {
  const std::string where = "rows[" + std::to_string(i) + "]";
  double values[4];
  if (v.kind == Kind::Array) {
    const std::vector<double> x = numbers(v, where, {4});
    std::copy(x.begin(), x.end(), values);
  } else if (v.kind == Kind::Object) {
    const std::vector<std::vector<std::string>> names = {
        modified ? std::vector<std::string>{"a", "a_prev"} : std::vector<std::string>{"a"},
        modified ? std::vector<std::string>{"alpha", "alpha_prev"}
                 : std::vector<std::string>{"alpha"},
        {"d"},
        {"theta", "theta_offset"}};
    std::vector<std::string> accepted;
    for (const auto& aliases : names)
      accepted.insert(accepted.end(), aliases.begin(), aliases.end());
    std::sort(accepted.begin(), accepted.end());
    for (const std::string& key : v.keys) {
      if (std::find(accepted.begin(), accepted.end(), key) != accepted.end()) continue;
      std::string note;
      if (key == "a_prev" || key == "alpha_prev")
        note = " ('" + key + "' is modified-DH notation, but convention is 'standard')";
      std::string list;
      for (const std::string& name : accepted) list += (list.empty() ? "" : ", ") + name;
      refuse(where + ": unknown field '" + key + "'" + note + "; expected " + list);
    }
    static const char* const field[4] = {"a", "alpha", "d", "theta"};
    for (int k = 0; k < 4; ++k) {
      std::vector<std::string> given;
      for (const std::string& alias : names[k])
        if (v.find(alias)) given.push_back(alias);
      if (given.empty()) {
        std::string options;
        for (const std::string& alias : names[k])
          options += (options.empty() ? "'" : " or '") + alias + "'";
        refuse(where + ": missing " + options);
      }
      if (given.size() > 1)
        refuse(where + ": both '" + given[0] + "' and '" + given[1] + "' given for " + field[k]);
      values[k] = number(*v.find(given[0]), where + "." + given[0]);
    }
  } else {
    refuse(where + ": expected an object {a, alpha, d, theta} or a list of 4 numbers, got " +
           describe(v));
  }
  return DHRow{values[0], values[1], values[2], values[3], JointType::Revolute};
}

bool known(const std::string& key) {
  const auto is = [&](const char* name) { return key == name; };
  return std::any_of(kModelFileFields.begin(), kModelFileFields.end(), is) ||
         std::any_of(kModelFileMetadata.begin(), kModelFileMetadata.end(), is);
}

MatrixX matrix(const std::vector<double>& values, int rows, int cols) {
  MatrixX m(rows, cols);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) m(r, c) = values[static_cast<std::size_t>(r) * cols + c];
  return m;
}

VectorX vector(const std::vector<double>& values) {
  return Eigen::Map<const VectorX>(values.data(), static_cast<Eigen::Index>(values.size()));
}

}  // namespace

Model model_from_json(const JsonValue& data) {
  if (data.kind != Kind::Object)
    refuse(std::string("expected an object with the model's fields, got ") +
           json_kind_name(data.kind));
  std::string unknown;
  for (const std::string& key : data.keys)
    if (!known(key)) unknown += (unknown.empty() ? "'" : ", '") + key + "'";
  if (!unknown.empty()) {
    std::string hint, expected;
    const JsonValue* dh = data.find("dh");
    if (!data.find("rows") && dh && dh->kind == Kind::Object)
      hint = " (the DH rows must be a top-level 'rows' list, with 'convention')";
    for (const char* field : kModelFileFields)
      expected += (expected.empty() ? "" : ", ") + std::string(field);
    refuse("unknown field(s) " + unknown + hint + "; expected " + expected);
  }
  for (const char* key : {"convention", "rows"})
    if (!data.find(key))
      refuse(std::string(key) + ": missing (a model needs 'convention' and 'rows')");
  const JsonValue& convention = *data.find("convention");
  if (convention.kind != Kind::String ||
      (convention.text != "standard" && convention.text != "modified"))
    refuse("convention: expected 'standard' or 'modified', got " + describe(convention));
  const bool modified = convention.text == "modified";
  const JsonValue& rows = *data.find("rows");
  if (rows.kind != Kind::Array || rows.items.empty())
    refuse("rows: expected a non-empty list of DH rows, got " + describe(rows));
  if (rows.items.size() > static_cast<std::size_t>(kMaxJoints))
    refuse("rows: " + std::to_string(rows.items.size()) +
           " DH rows; dynid model files hold at most " + std::to_string(kMaxJoints) + " joints");
  const int n = static_cast<int>(rows.items.size());
  std::vector<DHRow> dh;
  for (int i = 0; i < n; ++i) dh.push_back(row(rows.items[i], i, modified));

  std::string joint_types(static_cast<std::size_t>(n), 'R');
  if (const JsonValue* types = data.find("joint_types")) {
    if (types->kind != Kind::String)
      refuse("joint_types: expected a string of R/P letters, got " + describe(*types));
    joint_types = types->text;
  }
  // Every value checked for its type and shape before the model is built (Python's `values`),
  // in the order of the fields.
  std::string name;
  std::vector<std::string> joint_names, link_names;
  bool has_joint_names = false, has_link_names = false;
  struct Array {
    std::vector<int> shape;
    std::vector<double> values;
  };
  const auto shape_of = [n](const std::string& key) -> std::vector<int> {
    if (key == "gravity") return {3};
    if (key == "base" || key == "tool") return {4, 4};
    if (key == "qlim") return {n, 2};
    if (key == "params") return {n, 10};
    if (key == "transmission") return {n, n};
    return {n};  // Ia, Fv, Fs, gear_ratios, joint_offsets
  };
  std::vector<std::pair<std::string, Array>> arrays;
  for (const char* field : kModelFileFields) {
    const std::string key = field;
    if (key == "convention" || key == "joint_types" || key == "rows") continue;  // structure
    const JsonValue* v = data.find(key);
    if (!v || v->kind == Kind::Null) continue;  // null means the default, as absent
    if (key == "name") {
      if (v->kind != Kind::String) refuse("name: expected a string, got " + describe(*v));
      name = v->text;  // "" means the default
    } else if (key == "joint_names" || key == "link_names") {
      // the count, empty and repeated names are checked by the setter
      const bool strings = v->kind == Kind::Array &&
                           std::all_of(v->items.begin(), v->items.end(),
                                       [](const JsonValue& x) { return x.kind == Kind::String; });
      if (!strings)
        refuse(key + ": expected a list of " + std::to_string(n) + " strings, got " + describe(*v));
      std::vector<std::string>& names = key == "joint_names" ? joint_names : link_names;
      for (const JsonValue& x : v->items) names.push_back(x.text);
      (key == "joint_names" ? has_joint_names : has_link_names) = true;
    } else if (key == "velocity_limits" || key == "effort_limits") {
      // n numbers or nulls, null meaning no limit (+inf: JSON has no infinity); the setter
      // refuses values <= 0
      if (v->kind != Kind::Array || v->items.size() != static_cast<std::size_t>(n))
        refuse(key + ": expected a list of " + std::to_string(n) + " numbers or nulls, got " +
               describe(*v));
      std::vector<double> limits;
      for (std::size_t i = 0; i < v->items.size(); ++i)
        limits.push_back(v->items[i].kind == Kind::Null
                             ? std::numeric_limits<double>::infinity()
                             : number(v->items[i], key + "[" + std::to_string(i) + "]"));
      arrays.emplace_back(key, Array{{n}, limits});
    } else {
      const std::vector<int> shape = shape_of(key);
      arrays.emplace_back(key, Array{shape, numbers(*v, key, shape)});
    }
  }
  const auto value = [&](const char* key) -> const Array* {
    for (const auto& [k, a] : arrays)
      if (k == key) return &a;
    return nullptr;
  };

  // Then the checks of the Python binding's constructor (cpp/bindings/model.cpp, parse_dh).
  if (joint_types.size() != static_cast<std::size_t>(n))
    refuse("joint_types: expected " + std::to_string(n) + " letters (one per DH row), got '" +
           joint_types + "'");
  for (int i = 0; i < n; ++i) {
    const char type = static_cast<char>(std::toupper(static_cast<unsigned char>(joint_types[i])));
    if (type != 'R' && type != 'P')
      refuse("joint_types: expected 'R' or 'P', got '" + std::string(1, joint_types[i]) +
             "' at position " + std::to_string(i));
    dh[i].type = type == 'R' ? JointType::Revolute : JointType::Prismatic;
  }

  // Built, then set in the order of robot_fields.SETTABLE; each setter checks its value
  // (homogeneous transforms, ordered limits, an invertible transmission, ...).
  Model model(std::move(dh), modified ? Convention::Modified : Convention::Standard);
  if (!name.empty()) model.set_name(name);
  if (const Array* a = value("gravity"))
    model.set_gravity(Vector3(a->values[0], a->values[1], a->values[2]));
  if (const Array* a = value("base")) model.set_base(matrix(a->values, 4, 4));
  if (const Array* a = value("tool")) model.set_tool(matrix(a->values, 4, 4));
  if (has_joint_names) model.set_joint_names(joint_names);
  if (has_link_names) model.set_link_names(link_names);
  if (const Array* a = value("qlim")) model.set_joint_limits(matrix(a->values, n, 2));
  if (const Array* a = value("velocity_limits")) model.set_velocity_limits(vector(a->values));
  if (const Array* a = value("effort_limits")) model.set_effort_limits(vector(a->values));
  if (const Array* a = value("params")) model.set_parameters(matrix(a->values, n, 10));
  if (const Array* a = value("Ia")) model.set_rotor_inertia(vector(a->values));
  if (const Array* a = value("Fv")) model.set_viscous_friction(vector(a->values));
  if (const Array* a = value("Fs")) model.set_coulomb_friction(vector(a->values));
  if (const Array* a = value("transmission")) model.set_transmission(matrix(a->values, n, n));
  if (const Array* a = value("gear_ratios")) model.set_gear_ratios(vector(a->values));
  if (const Array* a = value("joint_offsets")) model.set_joint_offsets(vector(a->values));
  return model;
}

}  // namespace dynid::detail
