// dynid::load_model / parse_model (model_file.hpp) from C++: the reader of the model and result
// files Python writes. Four modes:
//
//   model_file                  (ctest) malformed texts, each refused with std::invalid_argument
//                               naming the field; a one-link arm read from text against its
//                               closed-form gravity torque; prints "model file checks: N probes,
//                               F failures" and exits 1 on a failure
//   model_file fields           the field names the reader knows, one "field K" / "metadata K"
//                               per line (tests/test_cpp_load_model.py: Python's lists)
//   model_file eval FILE STATES the model of FILE: every field ("field K v..."), then for each
//                               state of STATES (K, then K rows of q qd qdd) rnea, M and g
//                               ("rnea v...", "M v...", "g v..."), %.17g; the evaluation loop is
//                               counted for heap allocations ("allocations: A in K states")
//   model_file error FILE...    one line per file: "FILE<TAB>refused: message" or
//                               "FILE<TAB>loaded"
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "dynid/detail/model_file_fields.hpp"
#include "dynid/dynid.hpp"

#include "allocation_counter.hpp"  // cpp/examples/ (after Eigen: it replaces posix_memalign)

namespace {

void print_numbers(const char* label, const double* x, long count) {
  std::printf("%s", label);
  for (long k = 0; k < count; ++k) std::printf(" %.17g", x[k]);
  std::printf("\n");
}

// Row-major, as Python's arrays are flattened.
void print_matrix(const char* label, const dynid::MatrixX& m) {
  const dynid::RowMajorMatrixX r = m;
  print_numbers(label, r.data(), r.size());
}

void print_fields(const dynid::Model& model) {
  std::printf("field name %s\n", model.name().c_str());
  std::printf("field convention %s\n",
              model.convention() == dynid::Convention::Standard ? "standard" : "modified");
  std::string types;
  std::vector<double> dh;
  for (const dynid::DHRow& r : model.dh()) {
    types += r.type == dynid::JointType::Revolute ? 'R' : 'P';
    dh.insert(dh.end(), {r.a, r.alpha, r.d, r.theta});
  }
  std::printf("field joint_types %s\n", types.c_str());
  print_numbers("field gravity", model.gravity().data(), 3);
  print_numbers("field rows", dh.data(), static_cast<long>(dh.size()));
  print_matrix("field base", model.base());
  print_matrix("field tool", model.tool());
  std::printf("field joint_names");
  for (const std::string& name : model.joint_names()) std::printf(" %s", name.c_str());
  std::printf("\n");
  std::printf("field link_names");
  for (const std::string& name : model.link_names()) std::printf(" %s", name.c_str());
  std::printf("\n");
  print_matrix("field qlim", model.joint_limits());
  print_numbers("field velocity_limits", model.velocity_limits().data(), model.n());
  print_numbers("field effort_limits", model.effort_limits().data(), model.n());
  print_matrix("field params", model.parameters());
  print_numbers("field Ia", model.rotor_inertia().data(), model.n());
  print_numbers("field Fv", model.viscous_friction().data(), model.n());
  print_numbers("field Fs", model.coulomb_friction().data(), model.n());
  print_matrix("field transmission", model.transmission());
  print_numbers("field gear_ratios", model.gear_ratios().data(), model.n());
  print_numbers("field joint_offsets", model.joint_offsets().data(), model.n());
}

int evaluate(const char* path, const char* states_path) {
  const dynid::Model model = dynid::load_model(path);
  print_fields(model);
  const int n = model.n();
  std::ifstream in(states_path);
  long count = 0;
  in >> count;
  std::vector<dynid::VectorX> q(count, dynid::VectorX(n)), qd = q, qdd = q;
  for (long k = 0; k < count; ++k)
    for (dynid::VectorX* v : {&q[k], &qd[k], &qdd[k]})
      for (int i = 0; i < n; ++i) in >> (*v)[i];
  if (!in) {
    std::printf("%s: expected %ld states of 3 x %d numbers\n", states_path, count, n);
    return 2;
  }
  // Results kept in buffers sized here: the loop itself is what a controller runs per cycle.
  dynid::Workspace ws(model);
  std::vector<dynid::VectorX> tau(count, dynid::VectorX(n)), g = tau;
  std::vector<dynid::MatrixX> M(count, dynid::MatrixX(n, n));
  counting = true;
  for (long k = 0; k < count; ++k) {
    dynid::rnea(model, ws, q[k], qd[k], qdd[k], tau[k]);
    dynid::crba(model, ws, q[k], M[k]);
    dynid::gravity(model, ws, q[k], g[k]);
  }
  counting = false;
  for (long k = 0; k < count; ++k) {
    print_numbers("rnea", tau[k].data(), n);
    print_matrix("M", M[k]);
    print_numbers("g", g[k].data(), n);
  }
  std::printf("allocations: %ld in %ld states\n", allocations, count);
  return 0;
}

int errors(int argc, char** argv) {
  for (int k = 2; k < argc; ++k) {
    try {
      dynid::load_model(argv[k]);
      std::printf("%s\tloaded\n", argv[k]);
    } catch (const std::invalid_argument& e) {
      std::printf("%s\trefused: %s\n", argv[k], e.what());
    }
  }
  return 0;
}

// ---------------------------------------------------------------------------- self checks

int probes = 0, failures = 0;

void fail(const std::string& text) {
  ++failures;
  std::printf("FAIL %s\n", text.c_str());
}

// parse_model(text) must throw std::invalid_argument whose message contains `expected`.
void refused(const std::string& text, const std::string& expected) {
  ++probes;
  try {
    dynid::parse_model(text, "t.json");
  } catch (const std::invalid_argument& e) {
    const std::string message = e.what();
    if (message.rfind("t.json: ", 0) != 0 || message.find(expected) == std::string::npos)
      fail("expected '" + expected + "' in: " + message);
    return;
  }
  fail("no error for " + text.substr(0, 80) + " (expected '" + expected + "')");
}

const std::string kArm = R"({"convention": "standard", "rows": [[0.5, 0, 0, 0]])";

void self_checks() {
  // Syntax: each error names the value being read.
  refused(R"({"convention": "standard", "rows": [[0.5, 0, 0)", "rows[0][2]: not valid JSON");
  refused(R"({"convention": "standard", "rows": [[0.5, 0, 0, 0]]} x)", "extra data");
  refused(R"({"convention": "standard", "rows": [{"a": 01, "alpha": 0, "d": 0, "theta": 0}]})",
          "rows[0].a: not valid JSON: a number with a leading zero");
  refused(R"({"convention": "standard", "convention": "modified", "rows": []})",
          "convention: not valid JSON: the key 'convention' appears twice");
  refused(R"({"name": "a\qb", "convention": "standard", "rows": [[0.5, 0, 0, 0]]})",
          "name: not valid JSON: an invalid escape");
  refused(R"({"name": "\ud800", "convention": "standard", "rows": [[0.5, 0, 0, 0]]})",
          "unpaired UTF-16 surrogate");
  refused("{\"name\": \"a\tb\", " + kArm.substr(1) + "}", "name: not valid JSON: a control");
  refused("{\"name\": \"\xff\", " + kArm.substr(1) + "}", "not UTF-8 text (byte 10)");
  refused(R"({"notes": )" + std::string(300, '[') + std::string(300, ']') + "}",
          "nested more than 256 levels deep");
  refused("", "unexpected end of the file, expected a value");
  refused("\xEF\xBB\xBF" + kArm + "}", "byte order mark");
  // Structure and types, with Python's messages.
  refused("[1, 2]", "expected an object with the model's fields, got a list");
  refused(R"({"convention": "standard", "rows": [[0.5, 0, 0, 0]], "gravty": [0, 0, -9.81]})",
          "unknown field(s) 'gravty'; expected name, convention,");
  refused(R"({"convention": "standard", "dh": {"rows": []}})",
          "(the DH rows must be a top-level 'rows' list, with 'convention')");
  refused(R"({"rows": [[0.5, 0, 0, 0]]})", "convention: missing");
  refused(R"({"convention": "standard"})", "rows: missing");
  refused(R"({"convention": "Standard", "rows": [[0.5, 0, 0, 0]]})",
          "convention: expected 'standard' or 'modified', got 'Standard'");
  refused(R"({"convention": "standard", "rows": []})", "rows: expected a non-empty list");
  refused(R"({"convention": "standard", "rows": [[0.5, 0, 0]]})",
          "rows[0]: expected numbers of shape (4,), got shape (3,)");
  refused(R"({"convention": "standard", "rows": [[0.5, 0, 0, NaN]]})",
          "rows[0]: contains NaN or inf");
  refused(R"({"convention": "standard", "rows": [[0.5, 0, 0, 1e999]]})",
          "rows[0]: contains NaN or inf");
  refused(R"({"convention": "standard", "rows": [{"a": 0.5, "alpha": 0, "d": 0}]})",
          "rows[0]: missing 'theta' or 'theta_offset'");
  refused(R"({"convention": "standard", "rows": [{"a": 0.5, "alpha": true, "d": 0, "theta": 0}]})",
          "rows[0].alpha: expected a finite number, got true");
  refused(
      R"({"convention": "standard", "rows": [{"a_prev": 0.5, "alpha": 0, "d": 0, "theta": 0}]})",
      "rows[0]: unknown field 'a_prev' ('a_prev' is modified-DH notation");
  refused(R"({"convention": "modified", "rows": [{"a": 0, "a_prev": 0, "alpha": 0, "d": 0,
              "theta": 0}]})",
          "rows[0]: both 'a' and 'a_prev' given for a");
  refused(R"({"convention": "standard", "rows": ["x"]})", "rows[0]: expected an object");
  refused(kArm + R"(, "joint_types": "RP"})", "joint_types: expected 1 letters");
  refused(kArm + R"(, "joint_types": "X"})", "joint_types: expected 'R' or 'P', got 'X'");
  refused(kArm + R"(, "joint_types": 1})", "joint_types: expected a string of R/P letters");
  refused(kArm + R"(, "name": 3})", "name: expected a string, got 3");
  refused(kArm + R"(, "joint_names": [1]})", "joint_names: expected a list of 1 strings");
  refused(kArm + R"(, "joint_names": ["a", "b"]})", "joint_names: expected 1 names, got 2");
  refused(kArm + R"(, "link_names": ["a", ""]})", "link_names:");
  refused(kArm + R"(, "velocity_limits": [0]})", "velocity_limits:");
  refused(kArm + R"(, "effort_limits": [1, 2]})", "effort_limits: expected a list of 1 numbers");
  refused(kArm + R"(, "effort_limits": ["x"]})", "effort_limits[0]: expected a finite number");
  refused(kArm + R"(, "params": [[1, 0, 0, 0, 0, 0, 0, 0, 0]]})",
          "params: expected numbers of shape (1, 10), got shape (1, 9)");
  refused(kArm + R"(, "params": "zeros"})",
          "params: expected numbers of shape (1, 10), got 'zeros'");
  refused(kArm + R"(, "params": [[1, 0, 0, 0, 0, 0, 0, 0, 0, false]]})",
          "params: expected numbers");
  refused(kArm + R"(, "params": [[1, 0, 0, 0, 0, 0, 0, 0, 0, [0]]]})", "params: expected numbers");
  refused(kArm + R"(, "Ia": [-Infinity]})", "Ia: contains NaN or inf");
  refused(kArm + R"(, "gravity": [0, 0]})", "gravity: expected numbers of shape (3,)");
  refused(kArm + R"(, "qlim": [[1, -1]]})", "qlim: every lower limit must be below its upper");
  refused(kArm + R"(, "base": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 2]]})",
          "base: expected a homogeneous transform");
  refused(kArm + R"(, "transmission": [[0]]})", "transmission:");
  refused(kArm + R"(, "gear_ratios": [0]})", "gear_ratios:");

  // Accepted: Python's aliases, null as the default, metadata ignored, flat params; a one-link
  // arm (standard DH, link length 0.5, gravity along -y): the centre of mass 0.25 m from the
  // joint gives g(q) = m g0 0.25 cos(q) (potential m g0 0.25 sin q).
  ++probes;
  try {
    const double m = 2.0, g0 = 9.81, q0 = 0.3;
    const dynid::Model model = dynid::parse_model(
        R"({"format": "dynid-model", "version": 7, "notes": {"any": [1, "thing"]},
            "name": null, "convention": "standard", "joint_types": "r", "gravity": [0, -9.81, 0],
            "rows": [{"a": 0.5, "alpha": 0, "d": 0, "theta_offset": 0}],
            "params": [2, -0.5, 0, 0, 0, 0, 0, 0, 0, 0], "Ia": [0.25], "tool": null})",
        "t.json");
    dynid::Workspace ws(model);
    dynid::VectorX q(1), g(1);
    q << q0;
    dynid::gravity(model, ws, q, g);
    const double expected = m * g0 * 0.25 * std::cos(q0);
    if (std::abs(g[0] - expected) > 1e-12 || model.name() != "1-dof arm" ||
        model.rotor_inertia()[0] != 0.25)
      fail("one-link arm: g = " + std::to_string(g[0]) + ", expected " + std::to_string(expected));
  } catch (const std::exception& e) {
    fail(std::string("one-link arm refused: ") + e.what());
  }
  // Modified DH with a_{i-1}, alpha_{i-1} names equals the same table as lists.
  ++probes;
  try {
    const dynid::Model named = dynid::parse_model(
        R"({"convention": "modified", "rows": [{"a_prev": 0, "alpha_prev": 0, "d": 0.3, "theta": 0},
             {"a_prev": 0.1, "alpha_prev": 1.5707963267948966, "d": 0, "theta": 0.2}]})");
    const dynid::Model listed = dynid::parse_model(
        R"({"convention": "modified", "rows": [[0, 0, 0.3, 0], [0.1, 1.5707963267948966, 0, 0.2]]})");
    for (int i = 0; i < 2; ++i) {
      const dynid::DHRow &a = named.dh()[i], &b = listed.dh()[i];
      if (a.a != b.a || a.alpha != b.alpha || a.d != b.d || a.theta != b.theta)
        fail("modified DH names and lists differ in row " + std::to_string(i));
    }
  } catch (const std::exception& e) {
    fail(std::string("modified DH refused: ") + e.what());
  }
  // Files: a missing one names the path.
  ++probes;
  try {
    dynid::load_model("/nonexistent/arm.json");
    fail("no error for a missing file");
  } catch (const std::invalid_argument& e) {
    if (std::string(e.what()).rfind("path: no such file", 0) != 0) fail(e.what());
  }
  // A built-in model's name (Python's load_model reads those) says how to write its file.
  ++probes;
  try {
    dynid::load_model("kuka_lwr4");
    fail("no error for a built-in model's name");
  } catch (const std::invalid_argument& e) {
    if (std::string(e.what()).find("dynid.save_model(dynid.load_model('kuka_lwr4'), "
                                   "'kuka_lwr4.json')") == std::string::npos)
      fail(e.what());
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 2 && std::strcmp(argv[1], "fields") == 0) {
    for (const char* key : dynid::detail::kModelFileFields) std::printf("field %s\n", key);
    for (const char* key : dynid::detail::kModelFileMetadata) std::printf("metadata %s\n", key);
    return 0;
  }
  if (argc == 4 && std::strcmp(argv[1], "eval") == 0) return evaluate(argv[2], argv[3]);
  if (argc >= 2 && std::strcmp(argv[1], "error") == 0) return errors(argc, argv);
  if (argc != 1) {
    std::printf("usage: model_file [fields | eval FILE STATES | error FILE...]\n");
    return 2;
  }
  self_checks();
  std::printf("model file checks: %d probes, %d failures\n", probes, failures);
  return failures == 0 ? 0 : 1;
}
