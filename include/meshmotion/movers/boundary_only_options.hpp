#pragma once
/// \file
/// BoundaryOnlyOptions: the options of BoundaryOnlyMover (movers/boundary_only.hpp): none.
/// Light: the options and their one description (visit_options: key, field, doc), no mover.

#include "meshmotion/core/types.hpp"

#include <string>

namespace meshmotion {

/// Options of BoundaryOnlyMover: none.
struct BoundaryOnlyOptions {
  /// The mover leaves the interior where it is: a caller that repairs interior cells (the
  /// curving pipeline's untangling) does not act on its result.
  static constexpr bool moves_interior = false;
};

// visit_options(o, f) calls f(key, field, help) for every field of `o` that text may set.
template <class F>
void visit_options(BoundaryOnlyOptions&, F&&, const std::string& = {}) {}

}  // namespace meshmotion
