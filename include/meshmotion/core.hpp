#pragma once
/// \file
/// The core layer: element catalogue, Mesh<Dim>, the MeshLike concept, topology, errors.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/mesh_like.hpp"
#include "meshmotion/core/types.hpp"
