// Checks shared by the C++ proof programs of tests/cpp. Include after
// cpp/examples/allocation_counter.hpp (its `counting` and `allocations`), in the one translation
// unit of a program.
#pragma once

#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

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

}  // namespace
