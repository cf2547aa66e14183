// Everything a C++ user needs: build a Model, make a Workspace per thread, call the algorithms.
#pragma once

#include "dynid/controllers.hpp"
#include "dynid/coriolis.hpp"
#include "dynid/coriolis_matrix.hpp"
#include "dynid/crba.hpp"
#include "dynid/energy.hpp"
#include "dynid/forward_dynamics.hpp"
#include "dynid/friction.hpp"
#include "dynid/gravity.hpp"
#include "dynid/kinematics.hpp"
#include "dynid/model.hpp"
#include "dynid/regressor.hpp"
#include "dynid/rnea.hpp"
#include "dynid/simulator.hpp"
#include "dynid/workspace.hpp"
