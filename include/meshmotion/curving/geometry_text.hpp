#pragma once
/// \file
/// geometry_from_text(): the ready boundary geometries named by a short text, the form the
/// curve_mesh program's --geometry and the Python curve_mesh(geometry={...}) take:
///
///   spline | reconstruct   from the linear mesh (2D spline, 3D surface reconstruction)
///   straight               the facets as they are
///   bump                   the NASA bump-in-channel wall (2D or 3D)
///   circle:X,Y,R           2D
///   naca:XXXX[,CHORD,X0,Y0] 2D, a NACA 4-digit section
///   sphere:X,Y,Z,R         3D
///
/// Numbers are read by the option parser (core/option_text.hpp): exact, finite, nothing after.

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/option_text.hpp"
#include "meshmotion/core/types.hpp"
#include "meshmotion/curving/boundary_snapping.hpp"
#include "meshmotion/curving/function_graph.hpp"
#include "meshmotion/curving/geometry.hpp"
#include "meshmotion/curving/naca_section.hpp"

#include <cctype>
#include <string>
#include <string_view>
#include <vector>

namespace meshmotion {

/// Whether `text` names a CAD file (.step, .stp, .iges, .igs, .brep, any case) rather than a
/// geometry of geometry_from_text(): what the CAD component reads (cad/cad_model.hpp).
[[nodiscard]] inline bool is_cad_file(std::string_view text) {
  const auto dot = text.rfind('.');
  if (dot == std::string_view::npos || text.find('/', dot) != std::string_view::npos) return false;
  std::string ext(text.substr(dot));
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".step" || ext == ".stp" || ext == ".iges" || ext == ".igs" || ext == ".brep";
}

/// The geometry `spec` names (see the file comment) for a Dim-dimensional mesh. Throws
/// InputError naming the text for an unknown or wrong-dimension kind, a malformed number or a
/// wrong count of numbers.
template <int Dim>
[[nodiscard]] BoundaryGeometry<Dim> geometry_from_text(std::string_view spec) {
  const auto colon = spec.find(':');
  const std::string_view kind = spec.substr(0, colon);
  const std::string_view rest = colon == std::string_view::npos ? std::string_view{} : spec.substr(colon + 1);
  const std::string key = "geometry '" + std::string(spec) + "'";
  const auto numbers = [&](std::string_view text, std::size_t count, const char* form) {
    std::vector<double> v;
    parse_option_value(key, text, v);
    if (v.size() != count) throw InputError(key + ": expected " + form + " (got " + std::to_string(v.size()) + " numbers)");
    return v;
  };
  if (kind == "spline" || kind == "reconstruct") return BoundaryGeometry<Dim>::spline();
  if (kind == "straight") return BoundaryGeometry<Dim>::straight();
  if (kind == "bump") {
    if constexpr (Dim == 2) return BoundaryGeometry<Dim>::project(nasa_bump_2d());
    else return BoundaryGeometry<Dim>::project(nasa_bump_3d());
  }
  if constexpr (Dim == 2) {
    if (kind == "circle") {
      const auto v = numbers(rest, 3, "circle:X,Y,R");
      return BoundaryGeometry<2>::project(SphereProjection<2>(Vec<2>(v[0], v[1]), v[2]));
    }
    if (kind == "naca") {
      const std::string_view digits = rest.substr(0, rest.find(','));
      NacaParameters params = naca4(std::string(digits));
      if (rest.size() > digits.size()) {
        const auto v = numbers(rest.substr(digits.size() + 1), 3, "naca:XXXX,CHORD,X0,Y0");
        params.chord = v[0];
        params.leading_edge = Vec<2>(v[1], v[2]);
      }
      return BoundaryGeometry<2>::project(NacaProjection(params));
    }
  } else {
    if (kind == "sphere") {
      const auto v = numbers(rest, 4, "sphere:X,Y,Z,R");
      return BoundaryGeometry<3>::project(SphereProjection<3>(Vec<3>(v[0], v[1], v[2]), v[3]));
    }
  }
  throw InputError("unknown or wrong-dimension " + key +
                   " (expected spline, straight, bump, circle:X,Y,R or naca:XXXX[,CHORD,X0,Y0] in 2D; "
                   "reconstruct, straight, bump or sphere:X,Y,Z,R in 3D)");
}

}  // namespace meshmotion
