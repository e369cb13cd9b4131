// The JSON writer, the thread-count setting, the process memory settings and the version.

#include "meshmotion/core/generators.hpp"
#include "meshmotion/core/json.hpp"
#include "meshmotion/core/process_memory.hpp"
#include "meshmotion/core/threads.hpp"
#include "meshmotion/quality/quality_report.hpp"
#include "meshmotion/version.hpp"

#include <catch2/catch.hpp>

#include <cstdlib>
#include <optional>
#include <sstream>
#include <string>

using namespace meshmotion;

TEST_CASE("JSON writer: strings escaped, numbers exact, non-finite as null", "[core]") {
  std::ostringstream out;
  JsonWriter w(out);
  w.begin_object().key("file").value("a\"b\\c\n.su2").key("x").value(4.9e-6).key("nan").value(std::nan(""));
  w.key("n").value(Index{3}).end_object();
  CHECK(out.str() == R"({"file":"a\"b\\c\n.su2","x":4.9e-06,"nan":null,"n":3})");
}

TEST_CASE("JSON writer: UTF-8 passes as it is, any other byte is escaped so the output stays JSON", "[core]") {
  const auto written = [](std::string_view text) {
    std::ostringstream out;
    JsonWriter(out).value(text);
    return out.str();
  };
  CHECK(written("\xC3\xA9t\xC3\xA9 \xE2\x82\xAC \xF0\x9F\x98\x80") == "\"\xC3\xA9t\xC3\xA9 \xE2\x82\xAC \xF0\x9F\x98\x80\"");
  // A Latin-1 path, a stray continuation byte, an overlong '/', a surrogate, a cut sequence.
  CHECK(written("caf\xE9.msh") == R"("caf\u00e9.msh")");
  CHECK(written("\x80") == R"("\u0080")");
  CHECK(written("\xC0\xAF") == R"("\u00c0\u00af")");
  CHECK(written("\xED\xA0\x80") == R"("\u00ed\u00a0\u0080")");
  CHECK(written("\xE2\x82") == R"("\u00e2\u0082")");
}

TEST_CASE("thread count: set, read back, same results, OpenMP's default follows, negative and huge refused", "[core]") {
  const Mesh<2> mesh = rectangle_mesh({});
  const QualityReport all = quality_report(mesh, Metric::shape);
#ifdef _OPENMP
  const int openmp_default = omp_get_max_threads();
#endif
  set_num_threads(1);
#ifdef _OPENMP
  CHECK(num_threads() == 1);
  // What CHOLMOD's parallel regions open.
  CHECK(omp_get_max_threads() == 1);
#endif
  const QualityReport one = quality_report(mesh, Metric::shape);
  CHECK(one.min == all.min);
  CHECK(one.mean == all.mean);
  set_num_threads(0);
  CHECK(num_threads() >= 1);
#ifdef _OPENMP
  CHECK(omp_get_max_threads() == openmp_default);
#endif
  CHECK_THROWS_AS(set_num_threads(-2), InputError);
  CHECK_THROWS_WITH(set_num_threads(100000), Catch::Contains("got 100000"));
  CHECK(num_threads() >= 1);
}

TEST_CASE("version: the macros agree with the string", "[core]") {
  const std::string expected = std::to_string(MESHMOTION_VERSION_MAJOR) + "." + std::to_string(MESHMOTION_VERSION_MINOR) +
                               "." + std::to_string(MESHMOTION_VERSION_PATCH);
  CHECK(expected == MESHMOTION_VERSION_STRING);
  CHECK(std::string(version_string) == expected);
}

#if defined(__linux__) && defined(__GLIBC__) && (__GLIBC__ > 2 || __GLIBC_MINOR__ >= 35)
// The cases below decide without restarting: a restart would re-run this test program.
TEST_CASE("process memory: a choice already made in GLIBC_TUNABLES or MESHMOTION_HUGE_PAGES is kept", "[core]") {
  const auto saved = [](const char* name) -> std::optional<std::string> {
    const char* v = std::getenv(name);
    return v ? std::optional<std::string>(v) : std::nullopt;
  };
  const auto tunables = saved("GLIBC_TUNABLES"), choice = saved("MESHMOTION_HUGE_PAGES");
  char name[] = "meshmotion_tests";
  char* argv[] = {name, nullptr};
  setenv("GLIBC_TUNABLES", "glibc.malloc.check=0:glibc.malloc.hugetlb=0", 1);
  CHECK(tune_process_memory(1, argv) == HugePages::declined);
  setenv("GLIBC_TUNABLES", "glibc.malloc.hugetlb=1", 1);
  CHECK(tune_process_memory(1, argv) == HugePages::enabled);
  unsetenv("GLIBC_TUNABLES");
  setenv("MESHMOTION_HUGE_PAGES", "0", 1);
  CHECK(tune_process_memory(1, argv) == HugePages::declined);
  CHECK(std::getenv("GLIBC_TUNABLES") == nullptr);  // nothing set for child processes either
  const auto restore = [](const char* n, const std::optional<std::string>& v) {
    if (v) setenv(n, v->c_str(), 1);
    else unsetenv(n);
  };
  restore("GLIBC_TUNABLES", tunables);
  restore("MESHMOTION_HUGE_PAGES", choice);
}
#endif
