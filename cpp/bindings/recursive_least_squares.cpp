// Binding of the recursive least squares estimator: argument checks, the single-block update and
// the batch update looped in C++ with the GIL released. The recursion itself is in
// cpp/src/recursive_least_squares.cpp.
#include "recursive_least_squares.hpp"

#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

#include "arrays.hpp"
#include "dynid/detail/batch_runner.hpp"
#include "dynid/recursive_least_squares.hpp"
#include "object_lock.hpp"
#include "without_gil.hpp"

namespace dynid::binding {
namespace {

using RLS = RecursiveLeastSquares;
using BlockMap = Eigen::Map<const MatrixX, 0, Eigen::Stride<Eigen::Dynamic, Eigen::Dynamic>>;

// A row-major (m, p) block of a NumPy array, read in place.
BlockMap block(const double* data, Eigen::Index m, Eigen::Index p) {
  return BlockMap(data, m, p, Eigen::Stride<Eigen::Dynamic, Eigen::Dynamic>(1, p));
}

std::string shape_of(std::initializer_list<py::ssize_t> dims) {
  std::string s = "(";
  for (py::ssize_t d : dims) s += (s.size() > 1 ? ", " : "") + std::to_string(d);
  return s + (dims.size() == 1 ? ",)" : ")");
}

// The core names the C++ arguments (P0); the Python user passed initial_covariance.
template <class Call>
void with_python_names(Call call) {
  try {
    call();
  } catch (const std::invalid_argument& e) {
    std::string message = e.what();
    if (message.rfind("P0:", 0) == 0) message = "initial_covariance:" + message.substr(3);
    throw py::value_error(message);
  }
}

// The initial state: initial_covariance a scalar c (P_0 = c I) or a (p, p) matrix, theta0 None
// (zeros) or (p,).
void set_initial_state(RLS& rls, py::handle initial_covariance, py::handle theta0) {
  const int p = rls.p();
  Array P0 = as_real_array(initial_covariance, "initial_covariance");
  if (P0.ndim() != 0 && !(P0.ndim() == 2 && P0.shape(0) == p && P0.shape(1) == p))
    throw py::value_error("initial_covariance: expected a number or shape " + shape_of({p, p}) +
                          ", got " + shape_string(P0));
  require_finite(P0, "initial_covariance");
  if (P0.ndim() == 0 && !(P0.data()[0] > 0.0))
    throw py::value_error("initial_covariance: expected a value > 0, got " +
                          std::string(py::str(py::float_(P0.data()[0]))));
  if (theta0.is_none() && P0.ndim() == 0) {
    rls.reset(P0.data()[0]);
    return;
  }
  VectorX theta = VectorX::Zero(p);
  if (!theta0.is_none())
    theta = Eigen::Map<const VectorX>(parse_fixed(theta0, "theta0", {p}).data(), p);
  const MatrixX P = P0.ndim() == 0 ? MatrixX(P0.data()[0] * MatrixX::Identity(p, p))
                                   : MatrixX(block(P0.data(), p, p));
  with_python_names([&] { rls.reset(theta, P); });
}

void set_max_variance(RLS& rls, py::handle value) {
  if (value.is_none()) {
    rls.set_max_variance(0.0);
    return;
  }
  const double v = parse_number(value, "max_variance");
  if (!std::isfinite(v) || !(v > 0.0))
    throw py::value_error("max_variance: expected None or a finite number > 0, got " +
                          std::string(py::str(py::float_(v))));
  rls.set_max_variance(v);
}

// An update whose numbers overflow double precision (|Y|, |tau| near 1e150 and beyond) leaves
// inf/NaN in the estimate or in the covariance factors: the estimator is put back to its state
// before the call (`before`) and the inputs are named.
void require_finite_state(RLS& rls, const RLS& before, const char* names) {
  if (rls.is_finite()) return;
  rls = before;
  throw py::value_error(std::string(names) +
                        ": the update overflowed (values too large for double precision arithmetic "
                        "in the estimate or its covariance); the estimator is left as before this "
                        "call");
}

py::array_t<double> copy_of(const VectorX& v) {
  py::array_t<double> out(v.size());
  std::memcpy(out.mutable_data(), v.data(), sizeof(double) * static_cast<std::size_t>(v.size()));
  return out;
}

// Column-major Eigen matrix as a C-ordered (rows, cols) array.
py::array_t<double> copy_of_matrix(const MatrixX& M) {
  py::array_t<double> out({M.rows(), M.cols()});
  Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
      out.mutable_data(), M.rows(), M.cols()) = M;
  return out;
}

VectorX vector_from(py::handle obj, const char* name) {
  Array a = as_real_array(obj, name);
  if (a.ndim() != 1) throw py::value_error(std::string(name) + ": expected a vector");
  return Eigen::Map<const VectorX>(a.data(), a.shape(0));
}

MatrixX matrix_from(py::handle obj, const char* name) {
  Array a = as_real_array(obj, name);
  if (a.ndim() != 2) throw py::value_error(std::string(name) + ": expected a matrix");
  return Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
      a.data(), a.shape(0), a.shape(1));
}

void update(RLS& rls, py::handle Y_obj, py::handle tau_obj) {
  const int p = rls.p();
  Array Y = as_real_array(Y_obj, "Y_k");
  const bool ok =
      (Y.ndim() == 1 && Y.shape(0) == p) || (Y.ndim() == 2 && Y.shape(1) == p && Y.shape(0) >= 1);
  if (!ok)
    throw py::value_error("Y_k: expected shape (m, " + std::to_string(p) + ") with m >= 1 or (" +
                          std::to_string(p) + ",), got " + shape_string(Y));
  const py::ssize_t m = Y.ndim() == 1 ? 1 : Y.shape(0);
  Array tau = as_real_array(tau_obj, "tau_k");
  if (!((tau.ndim() == 1 && tau.shape(0) == m) || (tau.ndim() == 0 && m == 1)))
    throw py::value_error("tau_k: expected shape " + shape_of({m}) +
                          (m == 1 ? " or a number" : "") + " to match Y_k " + shape_string(Y) +
                          ", got " + shape_string(tau));
  require_finite(Y, "Y_k");
  require_finite(tau, "tau_k");
  // The state before the update, kept in a per-thread copy that is only resized when p changes
  // (a plain copy would allocate ten Eigen objects per call, +20% on a 43-parameter update).
  thread_local std::optional<RLS> before;
  const auto lock = lock_object(&rls);
  if (before && before->p() == p)
    *before = rls;
  else
    before.emplace(rls);
  rls.update(block(Y.data(), m, p), Eigen::Map<const VectorX>(tau.data(), m));
  require_finite_state(rls, *before, "Y_k, tau_k");
}

// Y (T, m, p) or (T, p), tau (T, m) or (T,): every block is checked before the first update, so
// that a bad sample leaves the estimator untouched.
py::array update_batch(RLS& rls, py::handle Y_obj, py::handle tau_obj, py::handle history_obj) {
  const bool history = parse_flag(history_obj, "history");
  const int p = rls.p();
  Array Y = as_real_array(Y_obj, "Y");
  const bool ok =
      (Y.ndim() == 3 && Y.shape(2) == p && Y.shape(1) >= 1) || (Y.ndim() == 2 && Y.shape(1) == p);
  if (!ok)
    throw py::value_error("Y: expected shape (T, m, " + std::to_string(p) +
                          ") with m >= 1 or (T, " + std::to_string(p) + "), got " +
                          shape_string(Y));
  const py::ssize_t T = Y.shape(0);
  const py::ssize_t m = Y.ndim() == 3 ? Y.shape(1) : 1;
  Array tau = as_real_array(tau_obj, "tau");
  const bool tau_ok = Y.ndim() == 3 ? (tau.ndim() == 2 && tau.shape(0) == T && tau.shape(1) == m)
                                    : (tau.ndim() == 1 && tau.shape(0) == T);
  if (!tau_ok)
    throw py::value_error("tau: expected shape " +
                          (Y.ndim() == 3 ? shape_of({T, m}) : shape_of({T})) + " to match Y " +
                          shape_string(Y) + ", got " + shape_string(tau));
  require_finite(Y, "Y");
  require_finite(tau, "tau");

  py::array_t<double> thetas(history ? std::vector<py::ssize_t>{T, p}
                                     : std::vector<py::ssize_t>{p});
  double* out = thetas.mutable_data();
  const double* Y_data = Y.data();
  const double* tau_data = tau.data();
  const auto lock = lock_object(&rls);  // the whole batch, one thread at a time
  // The updates are sequential: one thread, chunks of blocks between Ctrl-C checks
  // (without_gil.hpp). An interrupted or overflowing batch leaves the estimator as it was before
  // the call.
  const RLS before = rls;
  auto updates = [&](int, Eigen::Index begin, Eigen::Index end) -> Eigen::Index {
    for (Eigen::Index t = begin; t < end; ++t) {
      rls.update(block(Y_data + t * m * p, m, p), Eigen::Map<const VectorX>(tau_data + t * m, m));
      if (history)
        std::memcpy(out + t * p, rls.theta().data(), sizeof(double) * static_cast<std::size_t>(p));
    }
    return -1;  // the state's finiteness is checked at the end
  };
  try {
    without_gil([&] {
      return detail::run_chunks(T, 1, detail::chunk_for_work(static_cast<double>(m) * p * p, 4e6),
                                updates, python_interrupt());
    });
  } catch (...) {
    rls = before;
    throw;
  }
  require_finite_state(rls, before, "Y, tau");
  if (!history) std::memcpy(out, rls.theta().data(), sizeof(double) * static_cast<std::size_t>(p));
  return thetas;
}

constexpr const char* kClassDoc = R"doc(Recursive least squares with exponential forgetting (C++).

Estimates theta in tau_k = Y_k theta one block at a time (one sample of an n-joint robot is a
block of m = n rows of the base regressor). With forgetting factor lambda in (0, 1]:

    K     = P Y_k^T (lambda I + Y_k P Y_k^T)^-1
    theta = theta + K (tau_k - Y_k theta)
    P     = (P - K Y_k P) / lambda

P is kept in UD-factored form (Bierman), so it stays symmetric positive definite. With
lambda = 1 and initial_covariance c the estimate equals the ridge-regularised batch solution
(sum Y^T Y + I/c)^-1 (sum Y^T tau + theta0/c); with lambda < 1 old data fade as lambda^k.

Parameters
----------
p : int
    Number of parameters (columns of Y_k), >= 1.
forgetting : float
    lambda in (0, 1]; 1 keeps all data (stationary parameters).
initial_covariance : float or (p, p) array
    P_0: c * I for a number c > 0, or a symmetric positive definite matrix.
theta0 : (p,) array, optional
    Initial estimate (default zeros).
max_variance : float, optional
    With lambda < 1, cap on the UD variances against covariance windup when the data stop
    exciting some direction; default the largest initial one (c for a number c).

Calls on one estimator from several threads run one after the other (a batch update releases
the GIL but keeps the estimator to itself); use one estimator per thread to run in parallel.)doc";

}  // namespace

void bind_recursive_least_squares(py::module_& m) {
  py::class_<RLS>(m, "RecursiveLeastSquares", kClassDoc)
      .def(py::init([](py::handle p, py::handle forgetting, py::handle initial_covariance,
                       py::handle theta0, py::handle max_variance) {
             // The core checks forgetting in (0, 1] (std::invalid_argument -> ValueError).
             RLS rls(parse_count(p, "p"), parse_number(forgetting, "forgetting"));
             set_initial_state(rls, initial_covariance, theta0);
             set_max_variance(rls, max_variance);
             return rls;
           }),
           py::arg("p"), py::arg("forgetting") = 1.0, py::arg("initial_covariance") = 1e6,
           py::kw_only(), py::arg("theta0") = py::none(), py::arg("max_variance") = py::none())
      .def("update", &update, py::arg("Y_k"), py::arg("tau_k"),
           "One block: Y_k (m, p) or (p,) for m = 1, tau_k (m,) or a number for m = 1.")
      .def("update_batch", &update_batch, py::arg("Y"), py::arg("tau"), py::arg("history") = false,
           "Updates with T blocks in order, in C++ with the GIL released; exactly the same as "
           "T calls of update(). Y (T, m, p) and tau (T, m), or Y (T, p) and tau (T,) for m = 1. "
           "Returns the final theta (p,), or with history=True the estimate after each block "
           "(T, p).")
      .def(
          "reset",
          [](RLS& self, py::handle initial_covariance, py::handle theta0) {
            const auto lock = lock_object(&self);
            if (initial_covariance.is_none() && theta0.is_none()) {
              self.reset();
              return;
            }
            set_initial_state(
                self, initial_covariance.is_none() ? py::float_(1e6) : initial_covariance, theta0);
          },
          py::arg("initial_covariance") = py::none(), py::arg("theta0") = py::none(),
          "Without arguments: back to the initial state of the constructor (or of the last reset "
          "with arguments). Otherwise restart from a new initial state; a missing argument takes "
          "its constructor default (1e6, zeros).")
      .def_property_readonly("p", &RLS::p, "Number of parameters.")
      .def_property_readonly(
          "theta",
          [](const RLS& self) {
            const auto lock = lock_object(&self);
            return copy_of(self.theta());
          },
          "Current estimate (p,), a copy.")
      .def_property_readonly(
          "covariance",
          [](const RLS& self) {
            py::array_t<double> P({self.p(), self.p()});
            const auto lock = lock_object(&self);
            self.covariance(
                Eigen::Map<MatrixX>(P.mutable_data(), self.p(), self.p()));  // symmetric
            return P;
          },
          "Current covariance P (p, p), exactly symmetric, a copy.")
      .def_property(
          "forgetting", &RLS::forgetting,
          [](RLS& self, py::handle value) {
            self.set_forgetting(parse_number(value, "forgetting"));
          },
          "Forgetting factor lambda in (0, 1]; may be changed between updates.")
      .def_property(
          "max_variance", &RLS::max_variance, &set_max_variance,
          "Cap on the UD variances with forgetting < 1 (None sets the default, the largest "
          "initial one).")
      .def(py::pickle(
          [](const RLS& self) {  // __getstate__: everything that defines the estimator
            const RLS::State st = [&] {
              const auto lock = lock_object(&self);
              return self.state();
            }();
            return py::make_tuple(st.forgetting, st.max_variance, st.max_initial_variance,
                                  copy_of(st.theta), copy_of(st.theta0), copy_of(st.D),
                                  copy_of(st.D0), copy_of_matrix(st.U), copy_of_matrix(st.U0));
          },
          [](const py::tuple& t) {  // __setstate__
            if (t.size() != 9) throw py::value_error("state: expected 9 entries");
            RLS::State st;
            st.forgetting = t[0].cast<double>();
            st.max_variance = t[1].cast<double>();
            st.max_initial_variance = t[2].cast<double>();
            st.theta = vector_from(t[3], "state.theta");
            st.theta0 = vector_from(t[4], "state.theta0");
            st.D = vector_from(t[5], "state.D");
            st.D0 = vector_from(t[6], "state.D0");
            st.U = matrix_from(t[7], "state.U");
            st.U0 = matrix_from(t[8], "state.U0");
            return RLS::from_state(st);
          }))
      .def("__copy__",
           [](const RLS& self) {
             const auto lock = lock_object(&self);
             return RLS(self);
           })
      .def(
          "__deepcopy__",
          [](const RLS& self, py::handle) {
            const auto lock = lock_object(&self);
            return RLS(self);
          },
          py::arg("memo"))
      .def("__repr__", [](const RLS& self) {
        return "RecursiveLeastSquares(p=" + std::to_string(self.p()) +
               ", forgetting=" + std::string(py::str(py::float_(self.forgetting()))) + ")";
      });
}

}  // namespace dynid::binding
