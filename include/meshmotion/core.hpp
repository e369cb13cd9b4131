#pragma once
/// \file
/// The core layer: element catalogue, shape functions, Mesh<Dim>, the MeshLike concept,
/// topology, orientation, built-in mesh generators, errors.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/extrusion.hpp"
#include "meshmotion/core/generators.hpp"
#include "meshmotion/core/json.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/mesh_like.hpp"
#include "meshmotion/core/name_pattern.hpp"
#include "meshmotion/core/option_text.hpp"
#include "meshmotion/core/orientation.hpp"
#include "meshmotion/core/shape_functions.hpp"
#include "meshmotion/core/threads.hpp"
#include "meshmotion/core/topology.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/version.hpp"
