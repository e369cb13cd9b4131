// The programs' error reporting (examples/program.hpp): what a user reads when a run fails
// in a way whose own message names nothing, such as running out of memory.
#include "program.hpp"

#include <catch2/catch.hpp>

#include <new>
#include <sstream>
#include <stdexcept>
#include <string>

using namespace meshmotion;

namespace {

struct Captured {
  int rc = 0;
  std::string out, err;
};

/// guarded(json, body) with std::cout and std::cerr captured.
template <class Body>
Captured run_guarded(bool json, Body&& body) {
  std::ostringstream out, err;
  std::streambuf* const old_out = std::cout.rdbuf(out.rdbuf());
  std::streambuf* const old_err = std::cerr.rdbuf(err.rdbuf());
  Captured c;
  c.rc = examples::guarded(json, std::forward<Body>(body));
  std::cout.rdbuf(old_out);
  std::cerr.rdbuf(old_err);
  c.out = out.str();
  c.err = err.str();
  return c;
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

TEST_CASE("programs: running out of memory names the stage, its file and the peak memory", "[programs]") {
  examples::set_stage("moving case.su2 with rbf");
  const Captured c = run_guarded(true, []() -> int { throw std::bad_alloc(); });
  CHECK(c.rc == examples::exit_error);
  INFO(c.out << c.err);
  CHECK(contains(c.err, "out of memory while moving case.su2 with rbf (peak resident memory "));
  CHECK(contains(c.err, " GB): the case needs more than this process may allocate"));
  CHECK(contains(c.out, "\"kind\":\"memory\""));
  CHECK(contains(c.out, "while moving case.su2 with rbf"));

  // Before any stage, the message says no more than it knows.
  examples::set_stage("");
  const Captured early = run_guarded(false, []() -> int { throw std::bad_alloc(); });
  CHECK(early.out.empty());
  CHECK(contains(early.err, "out of memory (peak resident memory "));
}

TEST_CASE("programs: an exception from outside the library names the stage", "[programs]") {
  examples::set_stage("writing out.msh");
  const Captured c = run_guarded(true, []() -> int { throw std::length_error("vector::reserve"); });
  CHECK(c.rc == examples::exit_error);
  CHECK(contains(c.err, "internal error while writing out.msh: vector::reserve"));
  CHECK(contains(c.out, "\"kind\":\"internal\""));
  examples::set_stage("");
}

TEST_CASE("programs: reading and writing set the stage", "[programs]") {
  const std::string missing = std::string(MESHMOTION_TEST_TMP_DIR) + "/no_such_mesh.su2";
  CHECK_THROWS_AS((void)examples::read_input(missing), Error);
  CHECK(examples::current_stage() == "reading " + missing);
  const std::string output = std::string(MESHMOTION_TEST_TMP_DIR) + "/no_such_folder/out.su2";
  CHECK_THROWS_AS(examples::write_output(output, Mesh<2>{}), Error);
  CHECK(examples::current_stage() == "writing " + output);
  examples::set_stage("");
}
