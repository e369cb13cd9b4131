// The programs' error reporting (examples/program.hpp): what a user reads when a run fails
// in a way whose own message names nothing, such as running out of memory; and how they choose
// a mesh in an OpenFOAM case (--time, --latest-time, --region).
#include "program.hpp"

#include "messages.hpp"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
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

TEST_CASE("programs: --time, --latest-time and --region choose in an OpenFOAM case as OpenFOAM's tools do", "[programs]") {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(MESHMOTION_TEST_TMP_DIR) / "foam_selection";
  fs::remove_all(dir);
  for (const char* mesh : {"constant/polyMesh", "constant/solid/polyMesh"}) {
    fs::create_directories(dir / mesh);
    std::ofstream(dir / mesh / "faces") << "";
  }
  for (const char* time : {"0", "0.5", "1e-1", "2/solid"}) fs::create_directories(dir / time);
  fs::create_directories(dir / "system");
  const auto input = [&](examples::FoamSelection s) { return examples::foam_input(dir, s); };
  CHECK(input({}) == dir);
  CHECK(input({.time = "0.5"}) == dir / "0.5");
  CHECK(input({.time = "0.10"}) == dir / "1e-1");  // by value, as OpenFOAM matches times
  CHECK(input({.latest_time = true}) == dir / "2");
  CHECK(input({.region = "solid"}) == dir / "constant/solid/polyMesh");
  CHECK(input({.time = "2", .region = "solid"}) == dir / "2/solid");
  const auto refused = [&](examples::FoamSelection s) { return test::message_of<InputError>([&] { (void)input(s); }); };
  CHECK(refused({.time = "0.3"}).find("no time 0.3 (times: ") != std::string::npos);
  CHECK(refused({.time = "0.5", .region = "solid"}).find("time 0.5 has no folder for region solid") != std::string::npos);
  CHECK(refused({.region = "liquid"}).find("constant/liquid/polyMesh holds no mesh") != std::string::npos);
  CHECK(refused({.time = "x"}).find("--time x: not a time") != std::string::npos);
  CHECK(refused({.time = "0", .latest_time = true}).find("not both") != std::string::npos);
  // Without a time folder, the latest time is the constant mesh.
  fs::remove_all(dir / "0");
  fs::remove_all(dir / "0.5");
  fs::remove_all(dir / "1e-1");
  fs::remove_all(dir / "2");
  CHECK(input({.latest_time = true}) == dir / "constant/polyMesh");
  // The region's output: in the case, or in a time folder of it; anything else as given.
  CHECK(examples::foam_output(dir, {.region = "solid"}) == dir / "constant/solid/polyMesh");
  CHECK(examples::foam_output(dir / "0.25", {.region = "solid"}) == dir / "0.25/solid");
  CHECK(examples::foam_output(dir / "0.25", {}) == dir / "0.25");
  CHECK(examples::foam_output("moved.msh", {.region = "solid"}) == "moved.msh");
  fs::remove_all(dir);
}
