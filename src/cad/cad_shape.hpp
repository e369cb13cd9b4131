#pragma once
/// \file
/// The OpenCASCADE side of a CadModel, behind an interface. Debian builds OpenCASCADE's
/// toolkits with immediate binding: loading the 20 a STEP/IGES reader pulls resolves ~100,000
/// symbols, 0.12 s at the start of every program that links them, whether or not it ever reads
/// a CAD file (the 30P30N's whole curve_mesh run takes 0.2 s). So the toolkits are linked into
/// a module of their own (meshmotion_cad_occt, src/cad/occt_shape.cpp) that CadModel::read()
/// loads on first use, as io/detail/cgns_library.hpp does for CGNS; everything else of the
/// component (matching, placement) is built on this interface in meshmotion::cad.

#include "meshmotion/cad/cad_model.hpp"

#include <array>
#include <filesystem>
#include <optional>
#include <vector>

namespace meshmotion::detail {

/// A model's faces and edges, numbered from 1. The caller checks every entity index.
class CadShape {
 public:
  CadShape() = default;
  CadShape(const CadShape&) = delete;
  CadShape& operator=(const CadShape&) = delete;
  virtual ~CadShape() = default;

  [[nodiscard]] virtual int num_faces() const = 0;
  [[nodiscard]] virtual int num_edges() const = 0;
  [[nodiscard]] virtual double diagonal() const = 0;
  [[nodiscard]] virtual std::vector<int> face_edges(int face) const = 0;
  /// Distance from x to the bounding box of entity (dim, index): a lower bound of its distance.
  [[nodiscard]] virtual double box_distance(int dim, int index, const Vec<3>& x) const = 0;
  [[nodiscard]] virtual CadPoint closest_point(int dim, int index, const Vec<3>& x) const = 0;
  /// A face's closest point by a local search from (u0, v0); none when the search fails or
  /// ends outside the face (the caller then takes closest_point()).
  [[nodiscard]] virtual std::optional<CadPoint> closest_point_near(int face, const Vec<3>& x, double u0, double v0) const = 0;
  [[nodiscard]] virtual Vec<3> point_at(int dim, int index, double u, double v) const = 0;
  [[nodiscard]] virtual std::array<double, 2> periods(int dim, int index) const = 0;
  /// Whether the entity's geometry is a plane (face) or a line (edge).
  [[nodiscard]] virtual bool flat(int dim, int index) const = 0;
  /// The parameter of edge `edge` between a and b (unwrapped: b may lie past the seam of a
  /// closed edge) where the arc length from a reaches `fraction` of the length from a to b.
  [[nodiscard]] virtual double arc_length_parameter(int edge, double a, double b, double fraction) const = 0;
  /// The same along an isoline of face `face`: parameter `fixed` (0: u, 1: v) held at `at`,
  /// a and b values of the other one.
  [[nodiscard]] virtual double isoline_arc_length_parameter(int face, int fixed, double at, double a, double b, double fraction) const = 0;
};

/// Raised whenever CadShape changes: a module built from other sources is refused.
inline constexpr int cad_module_version = 4;

}  // namespace meshmotion::detail

// The module's entry points (C names, so that dlsym finds them unmangled).
extern "C" {
/// cad_module_version of the module.
int meshmotion_cad_module_version();
/// Reads a .step/.stp, .iges/.igs or .brep file; throws as CadModel::read() documents.
meshmotion::detail::CadShape* meshmotion_cad_read(const std::filesystem::path* file);
}
