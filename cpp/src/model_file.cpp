// dynid::load_model and dynid::parse_model (model_file.hpp): the file around the model. Which
// file is a result, the size limit, the extension, and the result's format and version, as
// Python's dynid.load_model (model/model_files.py) and dynid.load_result
// (export/result_files.py) decide them; the model itself is detail::model_from_json.
#include "dynid/model_file.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <system_error>

#include "dynid/detail/json.hpp"
#include "dynid/detail/model_file_fields.hpp"

namespace dynid {
namespace {

namespace fs = std::filesystem;
using detail::JsonValue;

// Python's MAX_FILE_BYTES for model files; a result holds more (covariance, training metrics)
// and Python sets it no limit: 64 MiB is far above any result dynid writes.
constexpr std::uintmax_t kMaxModelBytes = 16u << 20;
constexpr std::uintmax_t kMaxResultBytes = 64u << 20;
constexpr const char* kResultFile = "result.json";
constexpr const char* kResultFormat = "dynid-identification";
// The result format versions Python's load_result reads (result_files.VERSION).
constexpr int kResultVersionMax = 3;

// Runs `read` and prefixes its std::invalid_argument with `prefix` ("<file>: model: ...").
template <class Read>
auto prefixed(const std::string& prefix, Read read) -> decltype(read()) {
  try {
    return read();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(prefix + e.what());
  }
}

std::string read_file(const fs::path& path, std::uintmax_t limit) {
  const std::string name = path.string();
  std::error_code error;
  const std::uintmax_t size = fs::file_size(path, error);
  if (error) throw std::invalid_argument(name + ": cannot read it (" + error.message() + ")");
  if (size > limit)
    throw std::invalid_argument(name + ": " + std::to_string(size) +
                                " bytes is more than a model or result file can need (limit " +
                                std::to_string(limit) + " bytes)");
  std::ifstream in(path, std::ios::binary);
  std::string text(std::istreambuf_iterator<char>(in), {});
  if (!in.good() && !in.eof()) throw std::invalid_argument(name + ": cannot read it");
  return text;
}

// The identified model of a result.json (Python's result_from_dict, the parts the model needs).
Model model_of_result(const JsonValue& data) {
  using Kind = JsonValue::Kind;
  if (data.kind != Kind::Object)
    throw std::invalid_argument(std::string("result: expected an object, got ") +
                                detail::json_kind_name(data.kind));
  const JsonValue* format = data.find("format");
  if (!format || format->kind != Kind::String || format->text != kResultFormat)
    throw std::invalid_argument(
        std::string("format: expected '") + kResultFormat + "' (a dynid identify result), got " +
        (format ? detail::json_kind_name(format->kind) : "nothing") +
        (format && format->kind == Kind::String ? " '" + format->text + "'" : std::string()));
  // An integer 1..3 as Python reads it: 2.0 or true is not a version.
  const JsonValue* version = data.find("version");
  if (!version || version->kind != Kind::Number || !version->integer || version->number < 1 ||
      version->number > kResultVersionMax) {
    const JsonValue* by = data.find("dynid_version");
    throw std::invalid_argument(
        "version: expected a format version 1.." + std::to_string(kResultVersionMax) +
        (by && by->kind == Kind::String ? " (the file was written by dynid " + by->text + ")"
                                        : std::string()) +
        ", got " + (version ? detail::json_kind_name(version->kind) : "nothing"));
  }
  const JsonValue* model = data.find("model");
  if (!model) throw std::invalid_argument("model: missing");
  if (model->kind != Kind::Object)
    throw std::invalid_argument(std::string("model: expected an object, got ") +
                                detail::json_kind_name(model->kind));
  const JsonValue* physical = data.find("physical");
  if (!physical || physical->kind == Kind::Null)
    throw std::invalid_argument(
        "a least-squares result (no 'physical' entry) holds base parameters only, not a full "
        "robot; write its physically consistent robot as a model file (dynid export RESULT "
        "--model-file model.json) or identify with --physical (dynid identify LOG --physical) "
        "for a model that dynid::load_model reads");
  if (physical->kind != Kind::Object)
    throw std::invalid_argument(std::string("physical: expected an object, got ") +
                                detail::json_kind_name(physical->kind));
  Model robot = prefixed("model: ", [&] { return detail::model_from_json(*model); });
  for (int i = 0; i < robot.n(); ++i)
    if (!robot.link_inconsistency(i).empty())
      throw std::invalid_argument(
          "model: a physically consistent result whose parameters are not physically "
          "consistent (edited file?): link " +
          std::to_string(i + 1) + ": " + robot.link_inconsistency(i));
  return robot;
}

std::string lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

}  // namespace

Model parse_model(std::string_view json, const std::string& source) {
  const JsonValue data = detail::parse_json(json, source);  // its messages name the source
  return prefixed(source + ": ", [&] { return detail::model_from_json(data); });
}

Model load_model(const std::string& path) {
  fs::path file(path);
  std::error_code error;
  const bool folder = fs::is_directory(file, error);
  if (folder) file /= kResultFile;
  const bool result = folder || file.filename() == kResultFile;
  if (!fs::is_regular_file(file, error)) {
    if (result)
      throw std::invalid_argument("path: no result file " + file.string() +
                                  " (a folder written by dynid identify holds one)");
    // A bare name is a built-in model to Python's load_model; the C++ library has none.
    const std::string hint =
        file.has_extension() || file.has_parent_path()
            ? ""
            : " (the built-in models are Python's: write this one as a model file with "
              "dynid.save_model(dynid.load_model('" +
                  path + "'), '" + path + ".json'))";
    throw std::invalid_argument("path: no such file: " + file.string() + hint);
  }
  const std::string name = file.string();
  if (result) {
    const std::string text = read_file(file, kMaxResultBytes);
    const JsonValue data = detail::parse_json(text, name);
    return prefixed(name + ": ", [&] { return model_of_result(data); });
  }
  const std::string suffix = lower(file.extension().string());
  if (suffix == ".yaml" || suffix == ".yml")
    throw std::invalid_argument(
        name +
        ": YAML model files are read by Python only; convert it to JSON once: "
        "python -c \"import dynid; dynid.save_model(dynid.load_model('" +
        name + "'), 'model.json')\"");
  if (suffix != ".json")
    throw std::invalid_argument(name + ": unknown extension '" + file.extension().string() +
                                "'; expected .json (a model file) or a result folder");
  return parse_model(read_file(file, kMaxModelBytes), name);
}

}  // namespace dynid
