// The JSON writer, the thread-count setting and the version (issue 17).

#include "meshmotion/core/generators.hpp"
#include "meshmotion/core/json.hpp"
#include "meshmotion/core/threads.hpp"
#include "meshmotion/quality/quality_report.hpp"
#include "meshmotion/version.hpp"

#include <catch2/catch.hpp>

#include <sstream>

using namespace meshmotion;

TEST_CASE("JSON writer: strings escaped, numbers exact, non-finite as null", "[core]") {
  std::ostringstream out;
  JsonWriter w(out);
  w.begin_object().key("file").value("a\"b\\c\n.su2").key("x").value(4.9e-6).key("nan").value(std::nan(""));
  w.key("n").value(Index{3}).end_object();
  CHECK(out.str() == R"({"file":"a\"b\\c\n.su2","x":4.9e-06,"nan":null,"n":3})");
}

TEST_CASE("thread count: set, read back, same results; negative refused", "[core]") {
  const Mesh<2> mesh = rectangle_mesh({});
  const QualityReport all = quality_report(mesh, Metric::shape);
  set_num_threads(1);
#ifdef _OPENMP
  CHECK(num_threads() == 1);
#endif
  const QualityReport one = quality_report(mesh, Metric::shape);
  CHECK(one.min == all.min);
  CHECK(one.mean == all.mean);
  set_num_threads(0);
  CHECK(num_threads() >= 1);
  CHECK_THROWS_AS(set_num_threads(-2), InputError);
}

TEST_CASE("version: the macros agree with the string", "[core]") {
  const std::string expected = std::to_string(MESHMOTION_VERSION_MAJOR) + "." + std::to_string(MESHMOTION_VERSION_MINOR) +
                               "." + std::to_string(MESHMOTION_VERSION_PATCH);
  CHECK(expected == MESHMOTION_VERSION_STRING);
  CHECK(std::string(version_string) == expected);
}
