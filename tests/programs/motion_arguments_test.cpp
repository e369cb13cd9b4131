// The boundary conditions the programs build from their arguments (examples/motion_arguments.hpp):
// a group that no condition reaches is named, with the count of its nodes left to move with
// the interior, so that a patch a user forgot does not deform unseen.
#include "motion_arguments.hpp"

#include "meshmotion/core/generators.hpp"

#include <catch2/catch.hpp>

#include <iostream>
#include <sstream>
#include <string>

using namespace meshmotion;

namespace {

std::string notes_of(const Mesh<2>& mesh, const BoundarySpec<2>& spec, const std::vector<std::string>& excluded = {}) {
  std::ostringstream err;
  std::streambuf* const old = std::cerr.rdbuf(err.rdbuf());
  examples::note_unlisted_groups(mesh, spec.resolve(mesh), excluded);
  std::cerr.rdbuf(old);
  return err.str();
}

}  // namespace

TEST_CASE("programs: a group no condition reaches is named with its free nodes", "[programs]") {
  const Mesh<2> mesh = rectangle_mesh({.nx = 10, .ny = 10});
  BoundarySpec<2> spec;
  spec.moving("bottom", Translation<2>{{0.0, 0.1}}).fixed("top");
  const std::string notes = notes_of(mesh, spec);
  // The sides' corners belong to the bottom and the top: 9 of their 11 nodes are free.
  CHECK(notes.find("group 'left' has no condition: 9 of its 11 nodes move with the interior") != std::string::npos);
  CHECK(notes.find("group 'right' has no condition: 9 of its 11 nodes") != std::string::npos);
  CHECK(notes.find("'bottom'") == std::string::npos);
  CHECK(notes.find("'top'") == std::string::npos);
  // Named by a pattern, or left free on purpose: nothing to say.
  CHECK(notes_of(mesh, BoundarySpec<2>{spec}.sliding("(left|right)")).empty());
  CHECK(notes_of(mesh, spec, {"left", "right"}).empty());
}
