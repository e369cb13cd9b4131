#pragma once
/// \file
/// AnyMesh: a mesh whose dimension is known only after reading a file.

#include "meshmotion/core/mesh.hpp"

#include <variant>

namespace meshmotion {

/// A 2D or 3D mesh; std::visit it, or use read_mesh_as<Dim>() when the dimension is known.
using AnyMesh = std::variant<Mesh<2>, Mesh<3>>;

/// Dimension (2 or 3) of the mesh held.
[[nodiscard]] inline int dimension(const AnyMesh& mesh) noexcept { return mesh.index() == 0 ? 2 : 3; }

}  // namespace meshmotion
