#pragma once
/// \file
/// The solvers layer: run-time choice among Eigen's sparse and dense solvers.

#include "meshmotion/solvers/dense_solver.hpp"
#include "meshmotion/solvers/linear_solver.hpp"
#include "meshmotion/solvers/solver_options.hpp"
