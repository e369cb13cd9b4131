#pragma once
/// \file
/// The spatial layer: k-d tree queries over point matrices, a constant-time cover of balls.

#include "meshmotion/spatial/ball_cover.hpp"
#include "meshmotion/spatial/kd_tree.hpp"
