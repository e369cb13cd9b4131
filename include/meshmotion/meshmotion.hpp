#pragma once
/// \file
/// Everything meshmotion offers. Each layer header (and each header below it) also compiles alone.

#include "meshmotion/core.hpp"
