// Everything a C++ user needs: build a Model, make a Workspace per thread, call the algorithms.
// Every public header is included here; dynid/detail/ holds the internals (not API).
#pragma once

#include "dynid/controllers.hpp"
#include "dynid/coriolis.hpp"
#include "dynid/coriolis_matrix.hpp"
#include "dynid/crba.hpp"
#include "dynid/energy.hpp"
#include "dynid/forward_dynamics.hpp"
#include "dynid/friction.hpp"
#include "dynid/gravity.hpp"
#include "dynid/jacobian_dot.hpp"
#include "dynid/kinematics.hpp"
#include "dynid/model.hpp"
#include "dynid/momentum_observer.hpp"
#include "dynid/recursive_least_squares.hpp"
#include "dynid/regressor.hpp"
#include "dynid/rigid_body.hpp"
#include "dynid/rnea.hpp"
#include "dynid/rnea_derivatives.hpp"
#include "dynid/simulator.hpp"
#include "dynid/types.hpp"
#include "dynid/workspace.hpp"
