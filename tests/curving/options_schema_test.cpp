// One description per option and per report field (core/fields.hpp): every key of
// curve_mesh()'s options reads back from its own text, unknown keys are refused naming the
// known ones, and every outlet of a report (JSON, text) holds every field of its description.

#include "meshmotion/core/fields.hpp"
#include "meshmotion/core/generators.hpp"
#include "meshmotion/curving/curve_mesh.hpp"
#include "meshmotion/curving/geometry.hpp"

#include "messages.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <sstream>
#include <string>

using namespace meshmotion;
using meshmotion::test::message_of;

namespace {

KeyValues values_of(const std::vector<OptionDoc>& docs) {
  KeyValues out;
  for (const OptionDoc& d : docs) out.emplace_back(d.key, d.value);
  return out;
}

// Every key of `keys` stands as a JSON key in `json` and as a "key:" line in `text`.
void check_outlets(const std::vector<std::string>& keys, const std::string& json, const std::string& text) {
  for (const std::string& key : keys) {
    INFO(key);
    CHECK(json.find("\"" + key + "\":") != std::string::npos);
    CHECK(text.find(key + ":") != std::string::npos);
  }
}

template <class Report>
void check_report_outlets(const Report& r) {
  std::ostringstream json, text;
  JsonWriter w(json);
  write_json(w, r);
  write_text(text, r);
  check_outlets(field_keys(r), json.str(), text.str());
}

}  // namespace

TEST_CASE("curve options: every key reads back from its text, and typed values arrive", "[options]") {
  CurveOptions<2> defaults;
  const std::vector<OptionDoc> docs = option_docs(defaults);
  REQUIRE(docs.size() > 30);
  CurveOptions<2> back;
  set_curve_options(back, values_of(docs));
  CHECK(values_of(option_docs(back)) == values_of(docs));

  CurveOptions<3> o;
  set_curve_options(o, parse_key_values("order=3 sliding=symmetry,farfield midpoint=parameter untangle=off raise_rounds=2 "
                                        "jacobian_max_leaves=100 aspect_ratio_threshold=5 method=rbf kernel=wendland4 "
                                        "support_radius=0.25"));
  CHECK(o.order == 3);
  CHECK(o.sliding == std::vector<std::string>{"symmetry", "farfield"});
  CHECK(o.snap.midpoint == SplineMidpoint::parameter);
  CHECK(!o.untangle.untangle);
  CHECK(o.untangle.raise_rounds == 2);
  CHECK(o.report.quality.jacobian.max_leaves == 100);
  CHECK(o.layer.aspect_ratio_threshold == 5.0);
  CHECK(o.method == "rbf");
  // A key of both (the support radius) is the pipeline's; the mover's other keys are the mover's.
  CHECK(o.support_radius == 0.25);
  REQUIRE(o.mover_options);
  CHECK(std::get<RbfOptions>(*o.mover_options).kernel == RbfKernel::wendland4);
  // "method" is read first wherever it stands.
  CurveOptions<2> late;
  set_curve_options(late, {{"poisson_ratio", "0.4"}, {"method", "sle"}});
  CHECK(std::get<ElasticityOptions>(*late.mover_options).poisson_ratio == 0.4);
  CHECK(std::get<ElasticityOptions>(*late.mover_options).stiffening_exponent == 2.75);
}

TEST_CASE("curve options: unknown keys, another method's keys and bad values are refused", "[options]") {
  CurveOptions<2> o;
  const std::string typo = message_of<InputError>([&] { set_curve_options(o, {{"untangle_treshold", "0.2"}}); });
  CHECK_THAT(typo, Catch::Contains("did you mean 'untangle_threshold'") && Catch::Contains("blending_factor") &&
                       Catch::Contains("raise_rounds"));
  // The default method (blend) takes no kernel.
  CHECK_THAT(message_of<InputError>([&] { set_curve_options(o, {{"kernel", "wendland4"}}); }),
             Catch::Contains("'kernel'") && Catch::Contains("method 'blend'"));
  CHECK_THAT(message_of<InputError>([&] { set_curve_options(o, {{"order", "2.5"}}); }), Catch::Contains("'order'"));
  CHECK_THAT(message_of<InputError>([&] { set_curve_options(o, {{"midpoint", "middle"}}); }),
             Catch::Contains("arc_length, parameter"));
  CHECK_THAT(message_of<InputError>([&] { set_curve_options(o, {{"method", "magic"}}); }), Catch::Contains("blend, none"));
  CHECK_THAT(message_of<InputError>([&] { set_curve_options(o, {{"sliding", "a,,b"}}); }), Catch::Contains("'sliding'"));
  o = {};
  o.untangle.raise_rounds = -1;
  CHECK_THAT(message_of<InputError>([&] { (void)curve_mesh(o_mesh({}), o); }), Catch::Contains("'raise_rounds'"));
}

TEST_CASE("curve options: the listing holds the pipeline's keys and the method's, once each", "[options]") {
  for (const auto& method : mover_methods<2>()) {
    INFO(method.name);
    const std::vector<OptionDoc> docs = curve_option_docs<2>(std::string(method.name));
    std::vector<std::string> keys;
    for (const OptionDoc& d : docs) keys.push_back(d.key);
    std::sort(keys.begin(), keys.end());
    CHECK(std::adjacent_find(keys.begin(), keys.end()) == keys.end());
    for (const std::string& key : mover_config<2>(std::string(method.name)).keys())
      CHECK(std::binary_search(keys.begin(), keys.end(), key));
  }
}

TEST_CASE("reports: JSON and text hold every field of their description", "[options]") {
  OMeshOptions small;
  small.n_around = 32;
  small.n_radial = 8;
  CurveOptions<2> options;
  options.geometry.emplace("wall", BoundaryGeometry<2>::project(SphereProjection<2>(Vec<2>::Zero(), 0.5)));
  set_curve_options(options, {{"method", "rbf"}});
  const CurveResult<2> r = curve_mesh(o_mesh(small), options);
  REQUIRE(!r.mover_steps.empty());
  REQUIRE(!r.layers.empty());
  REQUIRE(!r.quality.worst.empty());
  check_report_outlets(r);
  check_report_outlets(r.quality);
  check_report_outlets(r.quality.worst.front());
  check_report_outlets(r.quality.per_type.front());
  check_report_outlets(r.mover_steps.front());
  check_report_outlets(r.untangle);
  check_report_outlets(r.layers.front());
  check_report_outlets(r.seconds);
  // Numbers keep every digit in JSON.
  std::ostringstream json;
  JsonWriter w(json);
  write_json(w, r);
  CHECK(json.str().find("\"support_radius\":" + format_option_value(r.support_radius)) != std::string::npos);
  CHECK(json.str().find("\"method\":\"rbf\"") != std::string::npos);
}
