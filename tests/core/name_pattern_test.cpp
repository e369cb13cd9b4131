// Group names as OpenFOAM users write them (core/name_pattern.hpp): the whole name matches,
// alternatives, classes and quantifiers as in OpenFOAM's dictionaries, malformed patterns
// refused naming the position.

#include "meshmotion/core/name_pattern.hpp"

#include "messages.hpp"

#include <catch2/catch.hpp>

#include <string>

using namespace meshmotion;

namespace {

bool matches(const char* pattern, const char* name) { return NamePattern(pattern).matches(name); }

}  // namespace

TEST_CASE("a name pattern matches whole names as OpenFOAM's regular expressions do", "[core][names]") {
  CHECK(matches("(inlet|outlet)", "inlet"));
  CHECK(matches("(inlet|outlet)", "outlet"));
  CHECK_FALSE(matches("(inlet|outlet)", "inlet2"));
  CHECK_FALSE(matches("(inlet|outlet)", "xoutlet"));
  CHECK(matches("wall.*", "wall"));
  CHECK(matches("wall.*", "wallUpper"));
  CHECK_FALSE(matches("wall.*", "lowerwall"));
  CHECK(matches(".*Wall", "lowerWall"));
  CHECK_FALSE(matches(".*Wall", "lowerWalls"));
  CHECK(matches("[ab]c", "bc"));
  CHECK_FALSE(matches("[ab]c", "cc"));
  CHECK(matches("[^0-9]x", "ax"));
  CHECK_FALSE(matches("[^0-9]x", "1x"));
  CHECK(matches("[a-c]+", "abcab"));
  CHECK_FALSE(matches("[a-c]+", "abd"));
  CHECK(matches("procBoundary\\d+to\\d+", "procBoundary0to12"));
  CHECK_FALSE(matches("procBoundary\\d+to\\d+", "procBoundaryto1"));
  CHECK(matches("a\\.b", "a.b"));
  CHECK_FALSE(matches("a\\.b", "axb"));
  CHECK(matches("(a|)", ""));
  CHECK(matches("a(bc)*d", "ad"));
  CHECK(matches("a(bc)*d", "abcbcd"));
  CHECK_FALSE(matches("a(bc)*d", "abd"));
  CHECK(matches("x?y", "y"));
  CHECK(matches("x?y", "xy"));
  CHECK(matches("(a*)*b", "aaab"));
  CHECK_FALSE(matches("(a*)*b", "aaaa"));
  CHECK(matches("^side$", "side"));
  CHECK(NamePattern::is_pattern("(front|back)"));
  CHECK_FALSE(NamePattern::is_pattern("lowerWall"));
}

TEST_CASE("a malformed name pattern is refused, naming the pattern and the position", "[core][names]") {
  const auto refusal = [](const char* pattern) { return test::message_of<InputError>([&] { (void)NamePattern(pattern); }); };
  CHECK_THAT(refusal("(inlet|outlet"), Catch::Contains("'(inlet|outlet'") && Catch::Contains("'(' is not closed at position 0"));
  CHECK_THAT(refusal("inlet)"), Catch::Contains("closes no group at position 5"));
  CHECK_THAT(refusal("*Wall"), Catch::Contains("nothing to repeat at position 0"));
  CHECK_THAT(refusal("a{2}"), Catch::Contains("counted repetition is not supported"));
  CHECK_THAT(refusal("[ab"), Catch::Contains("'[' is not closed"));
  CHECK_THAT(refusal("a**"), Catch::Contains("repeats a quantifier"));
  CHECK_THAT(refusal("a\\"), Catch::Contains("ends the pattern"));
}
