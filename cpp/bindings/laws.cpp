// Binding of the laws' core functions (laws.hpp): conversions, shape checks and the loop over
// samples only; the physics is in cpp/src (friction.cpp, elastic_motor.cpp, kinematics.cpp).
#include "laws.hpp"

#include <pybind11/numpy.h>

#include <array>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "arrays.hpp"
#include "dynid/elastic_motor.hpp"
#include "dynid/friction.hpp"
#include "dynid/kinematics.hpp"
#include "model.hpp"

namespace dynid::binding {
namespace {

double band_argument(py::handle obj) {
  const double band = parse_number(obj, "coulomb_band");
  if (!(std::isfinite(band) && band >= 0.0))
    throw py::value_error("coulomb_band: expected a finite value >= 0, got " +
                          std::to_string(band));
  return band;
}

// The four drives of an elastic robot, (n,) each, checked by the core (ValueError naming them).
ElasticDrives drives_argument(py::handle K, py::handle B, py::handle Fv, py::handle Fs) {
  const Array stiffness = as_real_array(K, "stiffness");
  if (stiffness.ndim() != 1 || stiffness.shape(0) < 1)
    throw py::value_error("stiffness: expected shape (n,) with n >= 1, got " +
                          shape_string(stiffness));
  const int n = static_cast<int>(stiffness.shape(0));
  const auto vector = [n](py::handle obj, const char* name) {
    const Array a = parse_fixed(obj, name, {n});
    return VectorX(Eigen::Map<const VectorX>(a.data(), n));
  };
  ElasticDrives drives{vector(K, "stiffness"), vector(B, "motor_inertia"),
                       vector(Fv, "motor_viscous"), vector(Fs, "motor_coulomb")};
  try {
    check_elastic_drives(drives, n);
  } catch (const std::invalid_argument& e) {
    throw py::value_error(e.what());
  }
  return drives;
}

template <std::size_t N, std::size_t... I>
std::array<ConstVec, N> inputs_of(const Samples& s, py::ssize_t t, int n,
                                  std::index_sequence<I...>) {
  return {ConstVec(s.row(I, t, n), n)...};
}

template <std::size_t N>
std::array<ConstVec, N> make_inputs(const Samples& s, py::ssize_t t, int n) {
  return inputs_of<N>(s, t, n, std::make_index_sequence<N>());
}

// kernel(inputs of sample t as (n,) vectors..., output row) calls the core on one sample; inputs
// of one sample (n,) or T samples (T, n), looped in C++ without the GIL; the output has their
// shape.
template <std::size_t N, class Kernel>
py::array per_sample_law(const ElasticDrives& drives,
                         std::initializer_list<std::pair<py::handle, const char*>> inputs,
                         Kernel kernel) {
  const int n = static_cast<int>(drives.stiffness.size());
  const Samples s = parse_samples(inputs, n);
  std::vector<py::ssize_t> shape{n};
  if (!s.single) shape.insert(shape.begin(), s.count);
  py::array_t<double> out(shape);
  double* result = out.mutable_data();
  {
    py::gil_scoped_release release;
    for (py::ssize_t t = 0; t < s.count; ++t) {
      std::array<ConstVec, N> in = make_inputs<N>(s, t, n);
      kernel(in, OutVec(result + t * n, n));
    }
  }
  require_finite_result(result, static_cast<py::ssize_t>(out.size()), s.names.c_str());
  return out;
}

std::vector<py::ssize_t> by_joint(int n) { return {n}; }
std::vector<py::ssize_t> two_by_joint(int n) { return {2, n}; }
std::vector<py::ssize_t> frames_of_links(int n) { return {n, 4, 4}; }

}  // namespace

void bind_laws(py::module_& m) {
  m.def(
      "_friction",
      [](PyModel& self, py::handle qd, py::handle coulomb_band) {
        const double band = band_argument(coulomb_band);
        const int n = self.model->n();
        return evaluate(
            self, parse_samples({{qd, "qd"}}, n), by_joint(n),
            [n, band](const Model& model, Workspace&, const double* const* in, double* tau) {
              friction(model, ConstVec(in[0], n), band, OutVec(tau, n));
            });
      },
      py::arg("model"), py::arg("qd"), py::arg("coulomb_band"),
      "Drive friction T^T (Fv w + Fs s(w)), w = T qd, s = tanh(. / coulomb_band) (sign for 0): "
      "(n,) or (T, n) like qd.");
  m.def(
      "_friction_terms",
      [](PyModel& self, py::handle qd, py::handle coulomb_band) {
        const double band = band_argument(coulomb_band);
        const int n = self.model->n();
        return evaluate(
            self, parse_samples({{qd, "qd"}}, n), two_by_joint(n),
            [n, band](const Model& model, Workspace&, const double* const* in, double* terms) {
              friction_terms(model, ConstVec(in[0], n), band, OutVec(terms, n),
                             OutVec(terms + n, n));
            });
      },
      py::arg("model"), py::arg("qd"), py::arg("coulomb_band"),
      "The viscous T^T (Fv w) and Coulomb T^T (Fs s(w)) friction terms: (2, n) or (T, 2, n).");
  m.def(
      "_asymmetric_friction_columns",
      [](py::handle qd_arg, py::handle offset_arg) {
        const bool offset = parse_flag(offset_arg, "offset");
        const Array qd = as_real_array(qd_arg, "qd");
        if (qd.ndim() != 2 || qd.shape(1) < 1)
          throw py::value_error("qd: expected shape (T, n) with n >= 1, got " + shape_string(qd));
        require_finite(qd, "qd");
        const py::ssize_t T = qd.shape(0);
        const int n = static_cast<int>(qd.shape(1)), P = asymmetric_friction_columns(n, offset);
        py::array_t<double> out({T, static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(P)});
        double* Y = out.mutable_data();
        const double* rows = qd.data();
        {
          py::gil_scoped_release release;
          for (py::ssize_t t = 0; t < T; ++t)
            asymmetric_friction_regressor(ConstVec(rows + t * n, n), offset,
                                          RowMajorMap(Y + t * n * P, n, P));
        }
        return out;
      },
      py::arg("qd"), py::arg("offset"),
      "Columns (T, n, 4n) of the asymmetric friction model for qd (T, n); (T, n, 3n) with "
      "offset (Fv+, Fv-, Fs).");
  m.def(
      "_link_frames",
      [](PyModel& self, py::handle q) {
        const int n = self.model->n();
        return evaluate(
            self, parse_samples({{q, "q"}}, n), frames_of_links(n),
            [n](const Model& model, Workspace& ws, const double* const* in, double* frames) {
              link_frames(model, ws, ConstVec(in[0], n), RowMajorMap(frames, n, 16));
            });
      },
      py::arg("model"), py::arg("q"),
      "World poses of the DH frames 1..n, base A_1 ... A_i: (n, 4, 4) or (T, n, 4, 4).");
  m.def(
      "_motor_friction",
      [](py::handle K, py::handle B, py::handle Fv, py::handle Fs, py::handle thetad,
         py::handle coulomb_band) {
        const ElasticDrives d = drives_argument(K, B, Fv, Fs);
        const double band = band_argument(coulomb_band);
        return per_sample_law<1>(d, {{thetad, "thetad"}}, [&](const auto& in, OutVec tau_F) {
          motor_friction(d, in[0], band, tau_F);
        });
      },
      py::arg("stiffness"), py::arg("motor_inertia"), py::arg("motor_viscous"),
      py::arg("motor_coulomb"), py::arg("thetad"), py::arg("coulomb_band"),
      "Motor-side friction Fv_m thetad + Fs_m s(thetad) of elastic joints (paper eq. (2)).");
  m.def(
      "_motor_acceleration",
      [](py::handle K, py::handle B, py::handle Fv, py::handle Fs, py::handle thetad,
         py::handle tau, py::handle tau_J, py::handle coulomb_band) {
        const ElasticDrives d = drives_argument(K, B, Fv, Fs);
        const double band = band_argument(coulomb_band);
        return per_sample_law<3>(d, {{thetad, "thetad"}, {tau, "tau"}, {tau_J, "tau_J"}},
                                 [&](const auto& in, OutVec thetadd) {
                                   motor_acceleration(d, in[0], in[1], in[2], band, thetadd);
                                 });
      },
      py::arg("stiffness"), py::arg("motor_inertia"), py::arg("motor_viscous"),
      py::arg("motor_coulomb"), py::arg("thetad"), py::arg("tau"), py::arg("tau_J"),
      py::arg("coulomb_band"),
      "thetadd = B^-1 (tau - tau_J - tau_F(thetad)): the motor equation (paper eq. (2)).");
  m.def(
      "_motor_torque",
      [](py::handle K, py::handle B, py::handle Fv, py::handle Fs, py::handle thetad,
         py::handle thetadd, py::handle tau_J, py::handle coulomb_band) {
        const ElasticDrives d = drives_argument(K, B, Fv, Fs);
        const double band = band_argument(coulomb_band);
        return per_sample_law<3>(
            d, {{thetad, "thetad"}, {thetadd, "thetadd"}, {tau_J, "tau_J"}},
            [&](const auto& in, OutVec tau) { motor_torque(d, in[0], in[1], in[2], band, tau); });
      },
      py::arg("stiffness"), py::arg("motor_inertia"), py::arg("motor_viscous"),
      py::arg("motor_coulomb"), py::arg("thetad"), py::arg("thetadd"), py::arg("tau_J"),
      py::arg("coulomb_band"),
      "tau = B thetadd + tau_J + tau_F(thetad): the motor equation (paper eq. (2)).");
}

}  // namespace dynid::binding
