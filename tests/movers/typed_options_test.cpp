// Typed options end to end (issue 17): one parser from text, exact numbers, unknown keys
// refused with the known ones, and the curving pipeline asking the options what they take.

#include "meshmotion/core/generators.hpp"
#include "meshmotion/core/option_text.hpp"
#include "meshmotion/curving/curve_mesh.hpp"
#include "meshmotion/movers/any_mover.hpp"
#include "meshmotion/movers.hpp"

#include "messages.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

using namespace meshmotion;

using test::message_of;

TEST_CASE("option text: every double round-trips exactly", "[options]") {
  std::mt19937_64 random(17);
  std::vector<double> values{4.9e-6, 1e-7, 0.1, 1.0 / 3.0, 5e-324, std::numeric_limits<double>::max(), -0.0, 123456789.125};
  for (int k = 0; k < 2000; ++k) {
    std::uint64_t bits = random();
    double x = 0.0;
    std::memcpy(&x, &bits, sizeof x);
    if (std::isfinite(x)) values.push_back(x);
  }
  for (const double x : values) {
    double back = 1.0;
    parse_option_value("x", format_option_value(x), back);
    CHECK(std::memcmp(&back, &x, sizeof x) == 0);
  }
  // What std::to_string did to small radii: 1e-7 became 0, 4.9e-6 became 5e-6.
  double r = 0.0;
  parse_option_value("support_radius", "1e-7", r);
  CHECK(r == 1e-7);
  parse_option_value("support_radius", "+4.9e-6", r);
  CHECK(r == 4.9e-6);
}

TEST_CASE("option text: malformed values are refused naming the key", "[options]") {
  double x = 0.0;
  for (const char* bad : {"", "0.5x", "x0.5", "nan", "inf", "1e999", "0,5", "1 2"})
    CHECK_THAT(message_of<InputError>([&] { parse_option_value("support_radius", bad, x); }),
               Catch::Contains("'support_radius'") && Catch::Contains("finite number"));
  int n = 0;
  CHECK_THROWS_AS(parse_option_value("load_steps", "2.5", n), InputError);
  CHECK_THROWS_AS(parse_option_value("load_steps", "99999999999", n), InputError);
  std::size_t bytes = 0;
  CHECK_THROWS_AS(parse_option_value("bytes", "-1", bytes), InputError);
  bool b = false;
  CHECK_THROWS_AS(parse_option_value("polynomial", "maybe", b), InputError);
  RbfKernel k{};
  CHECK_THAT(message_of<InputError>([&] { parse_option_value("kernel", "wendland3", k); }),
             Catch::Contains("wendland2") && Catch::Contains("tps"));
  Vec<3> v;
  CHECK_THROWS_AS(parse_option_value("axis", "0,0", v), InputError);
  CHECK_THROWS_AS(parse_option_value("axis", "0,0,1,0", v), InputError);
}

TEST_CASE("option text: key=value text", "[options]") {
  const KeyValues kv = parse_key_values("kernel=wendland4  # a comment\nsupport_radius=0.5\n\ncenter=1,2");
  REQUIRE(kv.size() == 3);
  CHECK(kv[0] == std::pair<std::string, std::string>{"kernel", "wendland4"});
  CHECK(kv[2] == std::pair<std::string, std::string>{"center", "1,2"});
  CHECK_THROWS_AS(parse_key_values("kernel"), InputError);
  CHECK_THROWS_AS(parse_key_values("=3"), InputError);
  CHECK_THAT(message_of<InputError>([] { (void)parse_key_values("a=1 a=2"); }), Catch::Contains("'a'"));
}

TEST_CASE("option text: one field set by its key, other keys left alone", "[options]") {
  RbfOptions o;
  CHECK(set_option(o, "support_radius", "0.25"));
  CHECK(o.support_radius == 0.25);
  CHECK(set_option(o, "kernel", "wendland4"));
  CHECK(o.kernel == RbfKernel::wendland4);
  const RbfOptions before = o;
  CHECK_FALSE(set_option(o, "no_such_key", "1"));
  CHECK(o.support_radius == before.support_radius);
  CHECK_THAT(message_of<InputError>([&] { (void)set_option(o, "support_radius", "wide"); }), Catch::Contains("support_radius"));
  const std::vector<std::string> keys = option_keys(RbfOptions{});
  REQUIRE_FALSE(keys.empty());
  CHECK(keys.front() == "kernel");
  CHECK(keys.size() == option_docs(RbfOptions{}).size());
}

TEST_CASE("mover options: every method's values read back to the same options", "[options]") {
  for (const auto& method : mover_methods<3>()) {
    INFO(method.name);
    MoverConfig<3> c = mover_config<3>(method.name);
    const KeyValues values = c.values();
    REQUIRE(values.size() == c.keys().size());
    REQUIRE((!values.empty() || !method.moves_interior));
    MoverConfig<3> back = mover_config<3>(method.name, values);
    CHECK(back.values() == values);
    CHECK_NOTHROW(make_mover(back));
  }
  MoverConfig<2> rbf = mover_config<2>("rbf", {{"support_radius", "4.9e-6"}, {"kernel", "wendland4"}, {"polynomial", "on"}});
  const auto& o = std::get<RbfOptions>(rbf.options);
  CHECK(o.support_radius == 4.9e-6);
  CHECK(o.kernel == RbfKernel::wendland4);
  CHECK(o.polynomial);
  // sle is elasticity with the thesis's stiffening exponent.
  CHECK(std::get<ElasticityOptions>(mover_config<2>("sle").options).stiffening_exponent == 2.75);
  CHECK(std::get<ElasticityOptions>(mover_config<2>("le").options).stiffening_exponent == 0.0);
}

TEST_CASE("option ranges: every default is inside its range, and values outside are refused naming key, value and range",
          "[options]") {
  for (const auto& method : mover_methods<3>()) {
    INFO(method.name);
    CHECK_NOTHROW(mover_config<3>(method.name).check());
  }
  CHECK_NOTHROW(check_option_ranges(CurveOptions<2>{}));
  CHECK_NOTHROW(check_option_ranges(CurveOptions<3>{}));
  CHECK_NOTHROW(check_option_ranges(ReportOptions{}));
  // The values once taken as they came (issue 70), through text: set_option leaves the field.
  const auto refused = [](std::string_view method, const std::string& key, const std::string& value) {
    return message_of<InputError>([&] { (void)mover_config<3>(method, {{key, value}}); }).substr(12);  // less "meshmotion: "
  };
  CHECK(refused("rbf", "tolerance", "-1") == "option 'tolerance': -1 is out of range (expected > 0)");
  CHECK(refused("le", "max_iterations", "-5") == "option 'max_iterations': -5 is out of range (expected >= 0)");
  CHECK(refused("rbf", "patch_overlap", "-1") == "option 'patch_overlap': -1 is out of range (expected >= 0)");
  CHECK(refused("rbf", "patch_centres", "0") == "option 'patch_centres': 0 is out of range (expected >= 1)");
  CHECK(refused("rbf", "condition_limit", "0.5") == "option 'condition_limit': 0.5 is out of range (expected >= 1 or 0)");
  CHECK_NOTHROW(mover_config<3>("rbf", {{"condition_limit", "0"}}));  // 0: never thin, as documented
  CHECK_THAT(refused("rbf", "max_evaluation_cache_bytes", "18446744073709551615"),
             Catch::Contains("18446744073709551615 is out of range (expected 0 to 1125899906842624)"));
  CHECK(refused("rbf", "support_radius", "-1") == "option 'support_radius': -1 is out of range (expected >= 0)");
  CHECK(refused("rbf", "support_radii", "0.5,-2") == "option 'support_radii': -2 is out of range (expected > 0)");
  CHECK(refused("sle", "poisson_ratio", "0.5") == "option 'poisson_ratio': 0.5 is out of range (expected in (-1, 0.5))");
  RbfOptions kept;
  CHECK_THROWS_AS(set_option(kept, "patch_overlap", "-1"), InputError);
  CHECK(kept.patch_overlap == RbfOptions{}.patch_overlap);
  // Set in code: make_mover refuses them the same way.
  RbfOptions coded;
  coded.solver.tolerance = -1.0;
  CHECK_THROWS_WITH(make_mover(MoverConfig<3>{"rbf", coded}), "meshmotion: option 'tolerance': -1 is out of range (expected > 0)");
  coded.solver.tolerance = std::numeric_limits<double>::infinity();
  CHECK_THROWS_AS(make_mover(MoverConfig<3>{"rbf", coded}), InputError);
  // curve_mesh's own keys, and the listings show each range after the type.
  CurveOptions<2> curve;
  CHECK_THROWS_WITH(set_curve_options(curve, {{"support_radius", "-1"}}),
                    Catch::Contains("option 'support_radius': -1 is out of range (expected >= 0)"));
  CHECK_THROWS_WITH(set_curve_options(curve, {{"order", "9"}}), Catch::Contains("option 'order': 9 is out of range (expected 2 to 8)"));
  bool shown = false;
  for (const OptionDoc& d : option_docs(RbfOptions{}))
    if (d.key == "patch_overlap") shown = d.type == "number >= 0";
  CHECK(shown);
}

TEST_CASE("mover options: unknown keys and methods are refused with what is known", "[options]") {
  const std::string typo = message_of<InputError>([] { (void)mover_config<2>("rbf", {{"suport_radius", "0.5"}}); });
  CHECK_THAT(typo, Catch::Contains("'suport_radius'") && Catch::Contains("did you mean 'support_radius'") &&
                       Catch::Contains("kernel") && Catch::Contains("polynomial"));
  // A key of another method: elasticity's Poisson ratio means nothing to the RBF.
  CHECK_THROWS_AS(mover_config<2>("rbf", {{"poisson_ratio", "0.3"}}), InputError);
  CHECK_THAT(message_of<InputError>([] { (void)mover_config<2>("rfb"); }),
             Catch::Contains("'rfb'") && Catch::Contains("sle") && Catch::Contains("dgrbf2"));
  // Options of the wrong type for the method.
  MoverConfig<2> wrong{"sle", RbfOptions{}};
  CHECK_THROWS_AS(make_mover(wrong), InputError);
  CHECK_THROWS_AS(wrong.set("poisson_ratio", "0.3"), InputError);
  // axis is a 3D key of dgrbf2.
  CHECK_NOTHROW(mover_config<3>("dgrbf2", {{"axis", "0,0,1"}}));
  CHECK_THROWS_AS(mover_config<2>("dgrbf2", {{"axis", "0,0,1"}}), InputError);
}

TEST_CASE("curve_mesh: typed mover options, checked before any work", "[options][curving]") {
  OMeshOptions o;
  o.n_around = 24;
  o.n_radial = 6;
  const Mesh<2> linear = o_mesh(o);
  CurveOptions<2> options;
  options.geometry.emplace("wall", BoundaryGeometry<2>::project(SphereProjection<2>(Vec<2>::Zero(), 0.5)));
  options.method = "sle";
  options.mover_options = RbfOptions{};
  CHECK_THAT(message_of<InputError>([&] { (void)curve_mesh(linear, options); }), Catch::Contains("'sle'"));
  options.method = "blend";
  CHECK_THROWS_AS(curve_mesh(linear, options), InputError);
  options.method = "magic";
  options.mover_options.reset();
  CHECK_THAT(message_of<InputError>([&] { (void)curve_mesh(linear, options); }), Catch::Contains("blend"));
  options.method = "rbf";
  options.active_radius_factor = -1.0;
  CHECK_THROWS_AS(curve_mesh(linear, options), InputError);

  // The support radius the pipeline measured reaches the RBF through its options; the
  // kernel given in them is kept.
  options.active_radius_factor = 4.0;
  RbfOptions rbf;
  rbf.kernel = RbfKernel::wendland4;
  options.mover_options = rbf;
  options.support_radius = 0.3;
  const CurveResult<2> r = curve_mesh(linear, options);
  CHECK(r.support_radius == 0.3);
  CHECK(r.invalid() == 0);
  CHECK(r.mover_steps.front().evaluated_nodes > 0);
}
