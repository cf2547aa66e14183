// C++ timings of dynid and, when built with DYNID_BENCH_WITH_PINOCCHIO, Pinocchio on the same arm.
//
//   bench_dynamics MODEL_FILE [--runs R] [--calls C] [--states S] [--only FUNCTION]
//
// --only times one function (rnea, crba, gravity, coriolis_matrix, regressor,
// forward_dynamics, rnea_derivatives), e.g. under `perf record` to see where its time goes.
//
// MODEL_FILE is written by bench/run.py from dynid.models.kuka_lwr4() (format in
// bench_inputs.hpp). For each function: S distinct states drawn once with a fixed seed, cycled;
// R timed runs of C calls each (after one untimed warm-up run), the two libraries' runs
// alternating; the figure is the median over runs of the mean time per call, in microseconds
// (the minimum is reported too). Before any timing the two libraries' results are compared on
// every state, and the program exits with status 2 if they differ by more than 1e-9.
// Output: one JSON line on stdout (progress and errors on stderr).
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <tuple>
#include <type_traits>
#include <vector>

#include "bench_inputs.hpp"
#include "dynid/dynid.hpp"
#ifdef DYNID_BENCH_WITH_PINOCCHIO
#include "pinocchio_side.hpp"
#endif

#ifndef DYNID_BENCH_FLAGS
#define DYNID_BENCH_FLAGS "unknown"
#endif

namespace {

using bench::ModelFile;
using bench::States;
using Eigen::MatrixXd;
using Eigen::VectorXd;

constexpr double kTolerance = 1e-9;

// ---- input --------------------------------------------------------------------------------

dynid::Model make_dynid_model(const ModelFile& arm) {
  std::vector<dynid::DHRow> rows;
  for (const ModelFile::Joint& j : arm.joints) {
    dynid::DHRow row;
    row.a = j.a;
    row.alpha = j.alpha;
    row.d = j.d;
    row.theta = j.theta;
    row.type = j.revolute ? dynid::JointType::Revolute : dynid::JointType::Prismatic;
    rows.push_back(row);
  }
  dynid::Model model(rows, arm.standard ? dynid::Convention::Standard : dynid::Convention::Modified,
                     arm.gravity, arm.base);
  MatrixXd P(arm.n(), 10);
  for (int i = 0; i < arm.n(); ++i) P.row(i) = arm.params[i].transpose();
  model.set_parameters(P);
  model.set_rotor_inertia(arm.Ia);
  model.set_viscous_friction(arm.Fv);
  model.set_coulomb_friction(arm.Fs);
  return model;
}

// q uniform in [-pi, pi], qd in [-2, 2] rad/s, qdd in [-5, 5] rad/s^2; tau = dynid's rnea.
States make_states(const dynid::Model& model, int count) {
  const int n = model.n();
  std::mt19937_64 rng(20240601);  // fixed seed: the same states in every run
  std::uniform_real_distribution<double> angle(-M_PI, M_PI), rate(-2.0, 2.0), accel(-5.0, 5.0);
  States s{MatrixXd(n, count), MatrixXd(n, count), MatrixXd(n, count), MatrixXd(n, count)};
  for (int k = 0; k < count; ++k)
    for (int i = 0; i < n; ++i) {
      s.q(i, k) = angle(rng);
      s.qd(i, k) = rate(rng);
      s.qdd(i, k) = accel(rng);
    }
  dynid::Workspace ws(model);
  VectorXd tau(n);
  for (int k = 0; k < count; ++k) {
    dynid::rnea(model, ws, s.q.col(k), s.qd.col(k), s.qdd.col(k), tau);
    s.tau.col(k) = tau;
  }
  return s;
}

// ---- timing -------------------------------------------------------------------------------

// Many short runs rather than a few long ones: this machine is shared (load 2-5 on 2 cores),
// and a run that the scheduler interrupts is an outlier the median discards only if most runs
// are not interrupted. One run is one pass over the states (~0.1-1 ms).
struct Plan {
  int runs = 201, calls = 256, states = 256;
  std::string only;  // time this function alone ("": all)
};

// Per function and library: median and minimum over runs of the time per call [us].
struct Stat {
  double median = 0.0, min = 0.0;
};

// The results are summed into a volatile sink: each call's output feeds a value the program
// keeps, so no call can be optimised away (with LTO or inlining as much as without).
volatile double g_sink = 0.0;

// Mean time per call [us] of one run of plan.calls calls; call(k) evaluates state k and
// returns one number read from its output.
template <class Call>
double one_run(const Plan& plan, Call&& call) {
  using clock = std::chrono::steady_clock;
  double sink = 0.0;
  const auto start = clock::now();
  for (int c = 0, k = 0; c < plan.calls; ++c) {
    sink += call(k);
    k = k + 1 == plan.states ? 0 : k + 1;  // cycle the states (no division in the loop)
  }
  const auto stop = clock::now();
  g_sink = g_sink + sink;
  return std::chrono::duration<double, std::micro>(stop - start).count() / plan.calls;
}

Stat summarise(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return {values[values.size() / 2], values.front()};
}

// Median over plan.runs runs of the time per call of eval(side, k), for every side. The sides'
// runs alternate (dynid, Pinocchio, dynid, ...) so that a change in the machine's load (other
// jobs share it) hits both alike; run -1 is an untimed warm-up (caches, branch predictors).
template <class Eval, class... Side>
std::array<Stat, sizeof...(Side)> time_interleaved(const Plan& plan, Eval eval, Side&... sides) {
  std::array<std::vector<double>, sizeof...(Side)> per_call;
  for (int run = -1; run < plan.runs; ++run) {
    std::size_t j = 0;
    const auto run_side = [&](auto& side) {
      const double us = one_run(plan, [&](int k) { return eval(side, k); });
      if (run >= 0) per_call[j].push_back(us);
      ++j;
    };
    (run_side(sides), ...);
  }
  std::array<Stat, sizeof...(Side)> us;
  for (std::size_t j = 0; j < us.size(); ++j) us[j] = summarise(per_call[j]);
  return us;
}

// ---- output -------------------------------------------------------------------------------

std::string json_object(const std::map<std::string, double>& values) {
  std::ostringstream out;
  out.precision(6);
  out << '{';
  bool first = true;
  for (const auto& [key, value] : values) {
    out << (first ? "" : ", ") << '"' << key << "\": " << value;
    first = false;
  }
  out << '}';
  return out.str();
}

// {"rnea": median, ...} or the minima, from the timings of one library.
std::string json_stats(const std::map<std::string, Stat>& stats, bool minimum) {
  std::map<std::string, double> values;
  for (const auto& [name, stat] : stats) values[name] = minimum ? stat.min : stat.median;
  return json_object(values);
}

std::string json_string(const std::string& text) {
  std::string out = "\"";
  for (char ch : text) {
    if (ch == '"' || ch == '\\') out += '\\';
    out += ch;
  }
  return out + '"';
}

// ---- the functions being timed --------------------------------------------------------------
// One class per library, one method per function: evaluate state k into preallocated outputs
// and return one number of the result (for the sink).

// The plain vector or matrix type a dynid function writes into (its last parameter, an
// Eigen::Ref): the benchmark follows the library's choice of storage order (e.g. a row-major
// regressor) instead of hard-coding one that would cost a conversion or fail to compile.
template <class F>
struct output_of;
template <class... Args>
struct output_of<void (*)(Args...)> {
  using type = typename std::decay_t<std::tuple_element_t<sizeof...(Args) - 1, std::tuple<Args...>>>::PlainObject;
};
template <auto F>
using Output = typename output_of<decltype(F)>::type;

class DynidSide {
 public:
  explicit DynidSide(const dynid::Model& m, const States& s)
      : model(m), states(s), ws(m), tau(m.n()), g(m.n()), qdd(m.n()), M(m.n(), m.n()),
        S(m.n(), m.n()), Y(m.n(), dynid::regressor_columns(m.n(), false, false)),
        dtau_dq(m.n(), m.n()), dtau_dqd(m.n(), m.n()) {}

  double rnea(int k) {
    dynid::rnea(model, ws, states.q.col(k), states.qd.col(k), states.qdd.col(k), tau);
    return tau[0];
  }
  double crba(int k) {
    dynid::crba(model, ws, states.q.col(k), M);
    return M(0, 0);
  }
  double gravity(int k) {
    dynid::gravity(model, ws, states.q.col(k), g);
    return g[0];
  }
  double coriolis_matrix(int k) {
    dynid::coriolis_matrix(model, ws, states.q.col(k), states.qd.col(k), S);
    return S(0, 0);
  }
  double regressor(int k) {
    dynid::regressor(model, ws, states.q.col(k), states.qd.col(k), states.qdd.col(k), false, false, Y);
    return Y(0, 0);
  }
  double forward_dynamics(int k) {
    dynid::forward_dynamics(model, ws, states.q.col(k), states.qd.col(k), states.tau.col(k), qdd);
    return qdd[0];
  }
  double rnea_derivatives(int k) {
    dynid::rnea_derivatives(model, ws, states.q.col(k), states.qd.col(k), states.qdd.col(k), dtau_dq, dtau_dqd);
    return dtau_dq(0, 0);
  }

  const dynid::Model& model;
  const States& states;
  dynid::Workspace ws;
  Output<&dynid::rnea> tau;
  Output<&dynid::gravity> g;
  Output<&dynid::forward_dynamics> qdd;
  Output<&dynid::crba> M;
  Output<&dynid::coriolis_matrix> S;
  Output<&dynid::regressor> Y;
  MatrixXd dtau_dq, dtau_dqd;
};

#ifdef DYNID_BENCH_WITH_PINOCCHIO

// Largest |dynid - Pinocchio| per function over all states. dynid's regressor is compared with
// Pinocchio's mapped to dynid's parameters (PinocchioSide::regressor_map).
std::map<std::string, double> compare(DynidSide& d, bench::PinocchioSide& p) {
  const MatrixXd T = p.regressor_map();
  std::map<std::string, double> worst;
  const auto note = [&worst](const std::string& name, const auto& difference) {
    const double diff = difference.cwiseAbs().maxCoeff();
    // NaN compares false: keep it explicitly so that it fails the check
    worst[name] = std::isnan(diff) ? diff : std::max(worst[name], diff);
  };
  for (int k = 0; k < d.states.q.cols(); ++k) {
    d.rnea(k), p.rnea(k);
    note("rnea", d.tau - p.tau());
    d.crba(k), p.crba(k);
    note("crba", d.M - p.M());
    d.gravity(k), p.gravity(k);
    note("gravity", d.g - p.g());
    d.coriolis_matrix(k), p.coriolis_matrix(k);
    note("coriolis_matrix", d.S - p.C());
    d.regressor(k), p.regressor(k);
    note("regressor", d.Y - p.Y() * T);
    d.forward_dynamics(k), p.forward_dynamics(k);
    note("forward_dynamics", d.qdd - p.qdd());
    d.rnea_derivatives(k), p.rnea_derivatives(k);
    note("rnea_derivatives", d.dtau_dq - p.dtau_dq());
    note("rnea_derivatives", d.dtau_dqd - p.dtau_dqd());  // the bench arm has Fv = 0
  }
  return worst;
}

#endif  // DYNID_BENCH_WITH_PINOCCHIO

// Times every function on every side; returns per side a map function -> us per call.
template <class... Side>
std::array<std::map<std::string, Stat>, sizeof...(Side)> time_all(const Plan& plan, Side&... sides) {
  std::array<std::map<std::string, Stat>, sizeof...(Side)> us;
  const auto record = [&](const char* name, auto eval) {
    if (!plan.only.empty() && plan.only != name) return;
    const auto medians = time_interleaved(plan, eval, sides...);
    for (std::size_t j = 0; j < medians.size(); ++j) us[j][name] = medians[j];
  };
  record("rnea", [](auto& side, int k) { return side.rnea(k); });
  record("crba", [](auto& side, int k) { return side.crba(k); });
  record("gravity", [](auto& side, int k) { return side.gravity(k); });
  record("coriolis_matrix", [](auto& side, int k) { return side.coriolis_matrix(k); });
  record("regressor", [](auto& side, int k) { return side.regressor(k); });
  record("forward_dynamics", [](auto& side, int k) { return side.forward_dynamics(k); });
  record("rnea_derivatives", [](auto& side, int k) { return side.rnea_derivatives(k); });
  if (us[0].empty()) throw std::runtime_error("--only: no function named " + plan.only);
  return us;
}

int parse_int(const char* text, const char* name) {
  char* end = nullptr;
  const long value = std::strtol(text, &end, 10);
  if (*end != '\0' || value <= 0) throw std::runtime_error(std::string(name) + ": expected a positive integer");
  return static_cast<int>(value);
}

}  // namespace

int main(int argc, char** argv) try {
  if (argc < 2) {
    std::cerr << "usage: bench_dynamics MODEL_FILE [--runs R] [--calls C] [--states S] [--only FUNCTION]\n";
    return 1;
  }
  Plan plan;
  if (argc % 2 != 0) throw std::runtime_error("every option needs a value");
  for (int a = 2; a + 1 < argc; a += 2) {
    const std::string flag = argv[a];
    if (flag == "--runs") plan.runs = parse_int(argv[a + 1], "--runs");
    else if (flag == "--calls") plan.calls = parse_int(argv[a + 1], "--calls");
    else if (flag == "--states") plan.states = parse_int(argv[a + 1], "--states");
    else if (flag == "--only") plan.only = argv[a + 1];
    else throw std::runtime_error("unknown option " + flag);
  }
  const ModelFile arm = bench::read_model(argv[1]);
  const dynid::Model model = make_dynid_model(arm);
  const States states = make_states(model, plan.states);
  DynidSide dynid_side(model, states);

  std::ostringstream json;
  json << "{\"n\": " << model.n() << ", \"runs\": " << plan.runs << ", \"calls\": " << plan.calls
       << ", \"states\": " << plan.states << ", \"compiler\": " << json_string(__VERSION__)
       << ", \"flags\": " << json_string(DYNID_BENCH_FLAGS) << ", \"eigen\": \""
       << EIGEN_WORLD_VERSION << '.' << EIGEN_MAJOR_VERSION << '.' << EIGEN_MINOR_VERSION << '"';

#ifdef DYNID_BENCH_WITH_PINOCCHIO
  bench::PinocchioSide pinocchio_side(arm, states);
  // Check before timing: the numbers only mean something if both compute the same thing.
  const std::map<std::string, double> diff = compare(dynid_side, pinocchio_side);
  bool agree = true;
  for (const auto& [name, value] : diff) {
    if (!(value <= kTolerance)) {
      std::cerr << "bench_dynamics: dynid and Pinocchio disagree on " << name << ": max |diff| = "
                << value << " > " << kTolerance << " over " << plan.states << " states\n";
      agree = false;
    }
  }
  if (!agree) return 2;
  std::cerr << "bench_dynamics: dynid and Pinocchio agree on " << plan.states
            << " states (max |diff| <= " << kTolerance << ")\n";
  const auto us = time_all(plan, dynid_side, pinocchio_side);
  json << ", \"pinocchio_version\": \"" << bench::PinocchioSide::version() << "\", \"max_abs_diff\": "
       << json_object(diff) << ", \"dynid_us\": " << json_stats(us[0], false)
       << ", \"dynid_us_min\": " << json_stats(us[0], true)
       << ", \"pinocchio_us\": " << json_stats(us[1], false)
       << ", \"pinocchio_us_min\": " << json_stats(us[1], true);
#else
  const auto us = time_all(plan, dynid_side);
  json << ", \"pinocchio_version\": null, \"dynid_us\": " << json_stats(us[0], false)
       << ", \"dynid_us_min\": " << json_stats(us[0], true)
       << ", \"pinocchio_us\": null, \"pinocchio_us_min\": null";
#endif
  json << '}';
  std::cout << json.str() << std::endl;
  return 0;
} catch (const std::exception& error) {
  std::cerr << "bench_dynamics: " << error.what() << '\n';
  return 1;
}
