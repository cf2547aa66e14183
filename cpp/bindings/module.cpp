// dynid._core: the C++ core seen from Python. Nothing but conversions lives in this folder.
#include <pybind11/pybind11.h>

#include <cmath>

#include "elastic.hpp"
#include "lanes.hpp"
#include "laws.hpp"
#include "model.hpp"
#include "recursive_least_squares.hpp"
#include "signal.hpp"
#include "simulator.hpp"
#include "text_signatures.hpp"
#include "uses.hpp"

namespace py = pybind11;

PYBIND11_MODULE(_core, m) {
  m.doc() = "dynid C++ core (use the dynid package, not this module)";
  dynid::binding::bind_model(m);  // Model and its calls (call_table.hpp); first: others take Models
  dynid::binding::bind_uses(m);
  dynid::binding::bind_elastic(m);
  dynid::binding::bind_lanes(m);
  dynid::binding::bind_recursive_least_squares(m);
  dynid::binding::bind_simulator(m);
  dynid::binding::bind_signal(m);
  dynid::binding::bind_laws(m);  // friction, elastic motor equation, link frames (laws.hpp)
  m.def(
      "standard_parameters",
      [](double mass, py::handle com, py::handle inertia_com) {
        using namespace dynid;
        using namespace dynid::binding;
        if (!std::isfinite(mass)) throw py::value_error("mass: expected a finite number");
        const Array c = parse_fixed(com, "com", {3});
        const Array I = parse_fixed(inertia_com, "inertia_com", {3, 3});
        const RigidBodyParameters body = RigidBodyParameters::from_physical(
            mass, Vector3(c.data()[0], c.data()[1], c.data()[2]),
            Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(I.data()));
        py::array_t<double> out(10);
        body.to_standard(out.mutable_data());
        return out;
      },
      py::arg("mass"), py::arg("com"), py::arg("inertia_com"),
      "The ten standard parameters (about the frame origin, Steiner) of a body given by its mass, "
      "centre of mass and inertia about the centre of mass; no consistency check.");
  m.def(
      "physical_inconsistency",
      [](double mass, py::handle inertia_com) {
        using namespace dynid::binding;
        const Array I = parse_fixed(inertia_com, "inertia_com", {3, 3});
        return dynid::physical_inconsistency(
            mass, Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(I.data()));
      },
      py::arg("mass"), py::arg("inertia_com"),
      "Why a body of this mass and inertia about its centre of mass cannot exist ('' if it can).");
  dynid::binding::add_text_signatures(m);  // after every function is defined
}
