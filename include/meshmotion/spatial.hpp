#pragma once
/// \file
/// The spatial layer: k-d tree queries over point matrices.

#include "meshmotion/spatial/kd_tree.hpp"
