// Checks shared by the C++ proof programs of tests/cpp. Include after
// cpp/examples/allocation_counter.hpp (its `counting` and `allocations`), in the one translation
// unit of a program.
#pragma once

#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "dynid/model.hpp"
#include "dynid/types.hpp"

namespace {

// True when the counter sees both kinds of heap use the proofs must catch: Eigen's (malloc) and
// the standard library's (operator new). Prints why not otherwise; resets the count.
inline bool allocation_counter_works(int n) {
  counting = true;
  {
    dynid::VectorX probe(n);
    std::vector<double> probe_new(n);
    probe.setZero();
    probe_new[0] = probe[0];
  }
  counting = false;
  if (allocations < 2) {
    std::printf("allocation counter broken: %ld of 2 probe allocations seen\n", allocations);
    return false;
  }
  allocations = 0;
  return true;
}

// Runs call() and checks it throws std::invalid_argument starting with "name:".
template <class Call>
bool names_argument(const char* name, Call call) {
  try {
    call();
  } catch (const std::invalid_argument& e) {
    if (std::string(e.what()).rfind(std::string(name) + ":", 0) == 0) return true;
    std::printf("expected an error naming %s, got: %s\n", name, e.what());
    return false;
  }
  std::printf("expected std::invalid_argument naming %s, nothing thrown\n", name);
  return false;
}

// The 7-joint test arm of the proof programs: non-trivial DH rows, a prismatic joint 3, base
// and tool offsets, distinct link inertias, rotor inertia and friction on every joint.
inline dynid::Model make_test_arm() {
  const int n = 7;
  std::vector<dynid::DHRow> rows(n);
  for (int i = 0; i < n; ++i) {
    rows[i].a = 0.05 * i;
    rows[i].alpha = (i % 2 ? -1.0 : 1.0) * 1.5707963267948966;
    rows[i].d = 0.1 + 0.02 * i;
    rows[i].theta = 0.1 * i;
    rows[i].type = i == 2 ? dynid::JointType::Prismatic : dynid::JointType::Revolute;
  }
  dynid::Matrix4 base = dynid::Matrix4::Identity(), tool = dynid::Matrix4::Identity();
  base(0, 3) = 0.2;
  tool(2, 3) = 0.1;
  dynid::Model model(rows, dynid::Convention::Standard, dynid::Vector3(0.0, 0.0, -9.81), base,
                     tool);
  for (int i = 0; i < n; ++i) {
    dynid::Matrix3 inertia = dynid::Matrix3::Identity() * (0.02 + 0.001 * i);
    model.set_link(i, dynid::RigidBodyParameters::from_physical(
                          2.0 - 0.2 * i, dynid::Vector3(0.01, -0.02, 0.05), inertia));
  }
  model.set_rotor_inertia(dynid::VectorX::Constant(n, 0.1));
  model.set_viscous_friction(dynid::VectorX::Constant(n, 0.5));
  model.set_coulomb_friction(dynid::VectorX::Constant(n, 0.3));
  return model;
}

}  // namespace
