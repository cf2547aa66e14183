// Binding of the Model: construction from a DH table, parameters and drive terms; its dynamics
// calls come from call_table.hpp (calls.cpp).
#include "model.hpp"

#include "calls.hpp"

#include <atomic>
#include <cctype>
#include <stdexcept>

namespace dynid::binding {
namespace {

Convention parse_convention(const std::string& convention) {
  if (convention == "standard") return Convention::Standard;
  if (convention == "modified") return Convention::Modified;
  throw py::value_error("convention: expected 'standard' or 'modified', got '" + convention + "'");
}

std::vector<DHRow> parse_dh(py::handle dh_obj, const std::string& joint_types) {
  Array dh = as_real_array(dh_obj, "dh");
  if (dh.ndim() != 2 || dh.shape(1) != 4 || dh.shape(0) < 1)
    throw py::value_error("dh: expected shape (n, 4) with rows [a, alpha, d, theta], n >= 1, got " +
                          shape_string(dh));
  require_finite(dh, "dh");
  const auto n = static_cast<std::size_t>(dh.shape(0));
  if (joint_types.size() != n)
    throw py::value_error("joint_types: expected " + std::to_string(n) +
                          " letters (one per DH row), got '" + joint_types + "'");
  std::vector<DHRow> rows(n);
  for (std::size_t i = 0; i < n; ++i) {
    const char type = static_cast<char>(std::toupper(static_cast<unsigned char>(joint_types[i])));
    if (type != 'R' && type != 'P')
      throw py::value_error("joint_types: expected 'R' or 'P', got '" +
                            std::string(1, joint_types[i]) + "' at position " + std::to_string(i));
    const double* r = dh.data() + 4 * i;
    rows[i] =
        DHRow{r[0], r[1], r[2], r[3], type == 'R' ? JointType::Revolute : JointType::Prismatic};
  }
  return rows;
}

Matrix4 parse_transform(py::handle obj, const char* name) {
  if (obj.is_none()) return Matrix4::Identity();
  Array a = parse_fixed(obj, name, {4, 4});
  return Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(a.data());
}

Vector3 parse_vector3(py::handle obj, const char* name) {
  Array a = parse_fixed(obj, name, {3});
  return Vector3(a.data()[0], a.data()[1], a.data()[2]);
}

// A read-only copy, so that `robot.Ia[0] = 1` fails loudly instead of changing a copy.
py::array read_only(const double* data, std::vector<py::ssize_t> shape) {
  py::array_t<double> out(shape);
  std::copy(data, data + out.size(), out.mutable_data());
  py::detail::array_proxy(out.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return out;
}

py::array vector_property(const VectorX& v) { return read_only(v.data(), {v.size()}); }

VectorX parse_drive(py::handle obj, const char* name, int n) {
  Array a = parse_fixed(obj, name, {n});
  return ConstVec(a.data(), n);
}

// A sequence of strings (a str alone is refused: "abc" would name three joints a, b, c).
std::vector<std::string> parse_names(py::handle value, const char* name) {
  if (py::isinstance<py::str>(value) || !py::isinstance<py::sequence>(value))
    throw py::value_error(std::string(name) + ": expected a sequence of strings, got " +
                          std::string(py::repr(value)));
  std::vector<std::string> names;
  for (py::handle item : value) {
    if (!py::isinstance<py::str>(item))
      throw py::value_error(std::string(name) + ": expected strings, got " +
                            std::string(py::repr(item)));
    names.push_back(item.cast<std::string>());
  }
  return names;
}

py::tuple names_tuple(const std::vector<std::string>& names) {
  py::tuple out(names.size());
  for (std::size_t i = 0; i < names.size(); ++i) out[i] = names[i];
  return out;
}

// n limits: infinity allowed (not limited); the model's setter refuses NaN and values <= 0.
VectorX parse_limits(py::handle obj, const char* name, int n) {
  Array a = as_real_array(obj, name);
  if (a.ndim() != 1 || a.shape(0) != n)
    throw py::value_error(std::string(name) + ": expected shape (" + std::to_string(n) +
                          ",), got " + shape_string(a));
  return ConstVec(a.data(), n);
}

}  // namespace

namespace {
std::atomic<int> g_batch_threads{1};
}  // namespace

std::atomic<int> last_batch_threads{0};

int batch_threads() { return g_batch_threads.load(); }

void set_batch_threads(int threads) { g_batch_threads.store(threads); }

void bind_model(py::module_& m) {
  m.def(
      "set_threads", [](py::handle threads) { set_batch_threads(parse_count(threads, "threads")); },
      py::arg("threads"),
      "Use this many threads (each with its own workspace, GIL released) for batch calls of "
      "at least 512 samples per thread. Default 1. Threads the system refuses (memory, thread "
      "limit) are skipped: the batch runs on those that start, at least the calling one.");
  m.def("get_threads", &batch_threads, "Threads used by batch calls.");
  m.def(
      "_last_batch_threads", [] { return last_batch_threads.load(); },
      "Threads the last batch call ran on.");

  py::class_<PyModel> model(m, "Model");
  model
      .def(py::init([](py::handle dh, const std::string& joint_types, const std::string& convention,
                       py::handle gravity, py::handle base, py::handle tool) {
             std::vector<DHRow> rows = parse_dh(dh, joint_types);
             return PyModel(Model(std::move(rows), parse_convention(convention),
                                  parse_vector3(gravity, "gravity"), parse_transform(base, "base"),
                                  parse_transform(tool, "tool")));
           }),
           py::arg("dh"), py::arg("joint_types"), py::arg("convention") = "standard",
           py::arg("gravity") = py::make_tuple(0.0, 0.0, -9.81), py::arg("base") = py::none(),
           py::arg("tool") = py::none())
      .def_property_readonly(
          "n", [](const PyModel& self) { return self.model->n(); }, "Degrees of freedom.")
      .def_property_readonly(
          "dh",
          [](const PyModel& self) {
            std::vector<double> rows;
            for (const DHRow& r : self.model->dh())
              rows.insert(rows.end(), {r.a, r.alpha, r.d, r.theta});
            return read_only(rows.data(), {self.model->n(), 4});
          },
          "DH table (n, 4), rows [a, alpha, d, theta] as given.")
      .def_property_readonly("joint_types",
                             [](const PyModel& self) {
                               std::string types;
                               for (const DHRow& r : self.model->dh())
                                 types += r.type == JointType::Revolute ? 'R' : 'P';
                               return types;
                             })
      .def_property_readonly("convention",
                             [](const PyModel& self) {
                               return self.model->convention() == Convention::Standard ? "standard"
                                                                                       : "modified";
                             })
      .def_property(
          "name", [](const PyModel& self) { return self.model->name(); },
          [](PyModel& self, py::handle value) {
            if (!py::isinstance<py::str>(value))
              throw py::value_error("name: expected a string, got " + std::string(py::repr(value)));
            std::string name = value.cast<std::string>();
            self.modify([&](Model& model) { model.set_name(std::move(name)); });
          },
          "A label for printing; '<n>-dof arm' by default.")
      .def_property(
          "joint_names", [](const PyModel& self) { return names_tuple(self.model->joint_names()); },
          [](PyModel& self, py::handle value) {
            std::vector<std::string> names = parse_names(value, "joint_names");
            // std::invalid_argument (count, empty, repeated) reaches Python as a ValueError.
            self.modify([&](Model& model) { model.set_joint_names(std::move(names)); });
          },
          "One name per joint (tuple of n strings), 'q1'..'qn' by default; Robot.from_urdf takes "
          "the URDF's joint names. Logs that name their joints (ROS JointState) are matched to "
          "them. ValueError naming joint_names unless n non-empty, distinct strings.")
      .def_property(
          "link_names", [](const PyModel& self) { return names_tuple(self.model->link_names()); },
          [](PyModel& self, py::handle value) {
            std::vector<std::string> names = parse_names(value, "link_names");
            self.modify([&](Model& model) { model.set_link_names(std::move(names)); });
          },
          "One name per link (tuple of n strings; the body moved by joint i), 'link1'..'linkn' by "
          "default; Robot.from_urdf takes the URDF's link names, the URDF and MJCF writers use "
          "them. ValueError naming link_names unless n non-empty, distinct strings.")
      .def_property(
          "qlim",
          [](const PyModel& self) {
            const RowMajorMatrixX limits = self.model->joint_limits();
            return read_only(limits.data(), {self.model->n(), 2});
          },
          [](PyModel& self, py::handle value) {
            const int n = self.model->n();
            Array a = parse_fixed(value, "qlim", {n, 2});
            const MatrixX limits = Eigen::Map<const RowMajorMatrixX>(a.data(), n, 2);
            // std::invalid_argument (a lower limit not below its upper) reaches Python as a
            // ValueError.
            self.modify([&](Model& model) { model.set_joint_limits(limits); });
          },
          "Joint limits (n, 2), rows [lower, upper]; default (-pi, pi) for revolute and (-1, 1) m "
          "for prismatic joints. ValueError naming qlim unless finite with lower < upper.")
      .def_property(
          "velocity_limits",
          [](const PyModel& self) { return vector_property(self.model->velocity_limits()); },
          [](PyModel& self, py::handle v) {
            const VectorX limits = parse_limits(v, "velocity_limits", self.model->n());
            self.modify([&](Model& model) { model.set_velocity_limits(limits); });
          },
          "Joint velocity limits (n,), rad/s or m/s; inf (not known, not limited) by default. "
          "ValueError naming velocity_limits unless every value > 0 (inf allowed).")
      .def_property(
          "effort_limits",
          [](const PyModel& self) { return vector_property(self.model->effort_limits()); },
          [](PyModel& self, py::handle v) {
            const VectorX limits = parse_limits(v, "effort_limits", self.model->n());
            self.modify([&](Model& model) { model.set_effort_limits(limits); });
          },
          "Joint effort limits (n,), N m or N; inf (not known, not limited) by default. "
          "ValueError naming effort_limits unless every value > 0 (inf allowed).")
      .def_property(
          "gravity_vector",
          [](const PyModel& self) { return vector_property(self.model->gravity()); },
          [](PyModel& self, py::handle g) {
            const Vector3 v = parse_vector3(g, "gravity");
            self.modify([&](Model& model) { model.set_gravity(v); });
          },
          "Gravity acceleration in world coordinates (3,).")
      .def_property(
          "base",
          [](const PyModel& self) {
            const Eigen::Matrix<double, 4, 4, Eigen::RowMajor> T = self.model->base();
            return read_only(T.data(), {4, 4});
          },
          [](PyModel& self, py::handle T) {
            const Matrix4 base = parse_transform(T, "base");
            self.modify([&](Model& model) { model.set_base(base); });
          },
          "World pose of frame 0 (4, 4).")
      .def_property(
          "tool",
          [](const PyModel& self) {
            const Eigen::Matrix<double, 4, 4, Eigen::RowMajor> T = self.model->tool();
            return read_only(T.data(), {4, 4});
          },
          [](PyModel& self, py::handle T) {
            const Matrix4 tool = parse_transform(T, "tool");
            self.modify([&](Model& model) { model.set_tool(tool); });
          },
          "Pose of the tool in the last DH frame (4, 4).")
      .def_property(
          "params",
          [](const PyModel& self) {
            const Eigen::Matrix<double, Eigen::Dynamic, 10, Eigen::RowMajor> P =
                self.model->parameters();
            return read_only(P.data(), {self.model->n(), 10});
          },
          [](PyModel& self, py::handle value) {
            const int n = self.model->n();
            Array a = as_real_array(value, "params");
            const bool ok = (a.ndim() == 2 && a.shape(0) == n && a.shape(1) == 10) ||
                            (a.ndim() == 1 && a.shape(0) == 10 * n);
            if (!ok)
              throw py::value_error("params: expected shape (" + std::to_string(n) + ", 10) or (" +
                                    std::to_string(10 * n) + ",), got " + shape_string(a));
            require_finite(a, "params");
            const MatrixX P =
                Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 10, Eigen::RowMajor>>(
                    a.data(), n, 10);
            self.modify([&](Model& model) { model.set_parameters(P); });
          },
          "Standard inertial parameters (n, 10): [m, mx, my, mz, Ixx, Ixy, Ixz, Iyy, Iyz, Izz] per "
          "link, about the origin of DH frame i. Accepts (n, 10) or (10n,).")
      .def_property(
          "Ia", [](const PyModel& self) { return vector_property(self.model->rotor_inertia()); },
          [](PyModel& self, py::handle v) {
            const VectorX Ia = parse_drive(v, "Ia", self.model->n());
            self.modify([&](Model& model) { model.set_rotor_inertia(Ia); });
          },
          "Rotor inertias reflected to the link side (n,).")
      .def_property(
          "Fv", [](const PyModel& self) { return vector_property(self.model->viscous_friction()); },
          [](PyModel& self, py::handle v) {
            const VectorX Fv = parse_drive(v, "Fv", self.model->n());
            self.modify([&](Model& model) { model.set_viscous_friction(Fv); });
          },
          "Viscous friction coefficients (n,).")
      .def_property(
          "Fs", [](const PyModel& self) { return vector_property(self.model->coulomb_friction()); },
          [](PyModel& self, py::handle v) {
            const VectorX Fs = parse_drive(v, "Fs", self.model->n());
            self.modify([&](Model& model) { model.set_coulomb_friction(Fs); });
          },
          "Coulomb friction coefficients (n,).")
      .def_property(
          "transmission",
          [](const PyModel& self) {
            const RowMajorMatrixX T = self.model->transmission();
            return read_only(T.data(), {self.model->n(), self.model->n()});
          },
          [](PyModel& self, py::handle value) {
            const int n = self.model->n();
            MatrixX T = MatrixX::Identity(n, n);
            if (!value.is_none()) {
              Array a = parse_fixed(value, "transmission", {n, n});
              T = Eigen::Map<const RowMajorMatrixX>(a.data(), n, n);
            }
            // std::invalid_argument (shape, NaN, singular) reaches Python as a ValueError.
            self.modify([&](Model& model) { model.set_transmission(T); });
          },
          "Transmission coupling T (n, n): motor velocities (after the gears) theta_dot = T qd "
          "(notes p. 11-13). Identity (set None) is the decoupled model; otherwise Ia, Fv, Fs are "
          "per motor and the drive torque is T^T (Ia T qdd + Fv T qd + Fs sign(T qd)). "
          "ValueError naming transmission unless T is finite and invertible "
          "(sigma_min / sigma_max > 1e-12).")
      .def_property(
          "gear_ratios",
          [](const PyModel& self) { return vector_property(self.model->gear_ratios()); },
          [](PyModel& self, py::handle v) {
            const VectorX N = parse_drive(v, "gear_ratios", self.model->n());
            self.modify([&](Model& model) { model.set_gear_ratios(N); });
          },
          "Gear ratios (n,), motor angle over joint angle: motor-side logs map to the joints "
          "through R = diag(gear_ratios) T (docs/data.md). Ones by default; ValueError naming "
          "gear_ratios for a zero or non-finite value.")
      .def_property(
          "joint_offsets",
          [](const PyModel& self) { return vector_property(self.model->joint_offsets()); },
          [](PyModel& self, py::handle v) {
            const VectorX offsets = parse_drive(v, "joint_offsets", self.model->n());
            self.modify([&](Model& model) { model.set_joint_offsets(offsets); });
          },
          "Joint zero offsets (n,): a motor-side log's joint angles are q = R^-1 theta - "
          "joint_offsets (docs/data.md). Zeros by default.")
      .def(
          "_set_link_physical",
          [](PyModel& self, int i, double mass, py::handle com, py::handle inertia_com) {
            if (i < 0 || i >= self.model->n())
              throw py::value_error("i: expected a link index in [0, " +
                                    std::to_string(self.model->n()) + "), got " +
                                    std::to_string(i));
            if (!std::isfinite(mass)) throw py::value_error("mass: expected a finite number");
            const Vector3 c = parse_vector3(com, "com");
            Array I = parse_fixed(inertia_com, "inertia_com", {3, 3});
            const Matrix3 Ic =
                Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(I.data());
            const std::string why = physical_inconsistency(mass, Ic);
            if (!why.empty())
              throw py::value_error(
                  std::string(why.rfind("mass", 0) == 0 ? "mass" : "inertia_com") + ": link " +
                  std::to_string(i) + " is not physically possible: " + why);
            const RigidBodyParameters body = RigidBodyParameters::from_physical(mass, c, Ic);
            self.modify([&](Model& model) { model.set_link(i, body); });
          },
          py::arg("i"), py::arg("mass"), py::arg("com"), py::arg("inertia_com"))
      .def(
          "_link_inconsistency",
          [](const PyModel& self, int i) { return self.model->link_inconsistency(i); },
          "Why link i (0-based) is not physically consistent, or '' when it is.");

  bind_calls(model);  // rnea, mass_matrix, ...: call_table.hpp
}

}  // namespace dynid::binding
