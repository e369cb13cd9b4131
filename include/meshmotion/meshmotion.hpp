#pragma once
/// \file
/// Everything meshmotion offers. Each layer header (and each header below it) also compiles alone.

#include "meshmotion/core.hpp"
#include "meshmotion/curving.hpp"
#include "meshmotion/delaunay.hpp"
#include "meshmotion/io.hpp"
#include "meshmotion/movers.hpp"
#include "meshmotion/quality.hpp"
#include "meshmotion/solvers.hpp"
#include "meshmotion/spatial.hpp"
