// A simulated subject's traits (subject_traits.hpp): drawn from its seed alone, log-normal about the profile
// with the stated spreads, and applied to the profile's fields without leaving their ranges.
#include "calligraphy/sim/subject_traits.hpp"

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "calligraphy/core/errors.hpp"

using namespace calligraphy;

namespace {

struct Moments {
  double mean = 0.0;
  double sd = 0.0;
};

// Mean and standard deviation of the natural log of `values`.
Moments log_moments(const std::vector<double>& values) {
  Moments m;
  for (const double v : values) m.mean += std::log(v);
  m.mean /= static_cast<double>(values.size());
  for (const double v : values) m.sd += (std::log(v) - m.mean) * (std::log(v) - m.mean);
  m.sd = std::sqrt(m.sd / static_cast<double>(values.size() - 1));
  return m;
}

}  // namespace

TEST_CASE("a subject's traits are a function of its seed alone", "[sim][subjects]") {
  const SubjectTraits a = draw_subject_traits(12345);
  const SubjectTraits b = draw_subject_traits(12345);
  const SubjectTraits c = draw_subject_traits(12346);
  CHECK(a.drawn);
  CHECK(a.writing_speed_factor == b.writing_speed_factor);
  CHECK(a.learning.fast_learning == b.learning.fast_learning);
  CHECK(a.writing_speed_factor != c.writing_speed_factor);
}

TEST_CASE("the traits spread about the profile by the stated log-SDs", "[sim][subjects]") {
  // 4000 subjects: the log-SD's standard error is about sigma / sqrt(2 n) = 1.1 % of sigma.
  std::vector<double> speed, spatial, noise, fast_learning, slow_retention_time;
  const SubjectSpread spread;
  for (std::uint64_t seed = 1; seed <= 4000; ++seed) {
    const SubjectTraits t = draw_subject_traits(seed * 0x9e3779b97f4a7c15ULL);
    speed.push_back(t.writing_speed_factor);
    spatial.push_back(t.spatial_error_factor);
    noise.push_back(t.motor_noise_factor);
    fast_learning.push_back(t.learning.fast_learning / TwoStateRates{}.fast_learning);
    slow_retention_time.push_back((1.0 - TwoStateRates{}.slow_retention) / (1.0 - t.learning.slow_retention));
    // The two-state model's order holds for every subject.
    CHECK(t.learning.slow_learning < t.learning.fast_learning);
    CHECK(t.learning.slow_retention > t.learning.fast_retention);
  }
  const auto check = [](const std::vector<double>& values, double sigma) {
    const Moments m = log_moments(values);
    CHECK(std::abs(m.mean) < 0.05 * sigma + 0.01);  // median 1: the profile is the typical subject
    CHECK(m.sd == Approx(sigma).epsilon(0.05));
  };
  check(speed, spread.writing_speed);
  check(spatial, spread.spatial_error);
  check(noise, spread.motor_noise);
  check(fast_learning, spread.learning_rate);
  check(slow_retention_time, spread.retention_time);
}

TEST_CASE("an individual profile scales the profile's fields and stays valid", "[sim][subjects]") {
  const WriterProfile foreign = WriterProfile::foreign();
  SubjectTraits t;
  t.drawn = true;
  t.writing_speed_factor = 0.5;
  t.spatial_error_factor = 2.0;
  t.error_rate_factor = 10.0;
  t.motor_noise_factor = 3.0;
  const WriterProfile p = individual_profile(foreign, t);
  CHECK(p.writing_speed_m_s == Approx(0.5 * foreign.writing_speed_m_s));
  CHECK(p.bias_offset_m == Approx(2.0 * foreign.bias_offset_m));
  CHECK(p.error_tolerance_m == Approx(2.0 * foreign.error_tolerance_m));
  CHECK(p.order_error_probability == Approx(1.0));  // 0.25 x 10, kept a probability
  CHECK(p.noise_fraction == Approx(3.0 * foreign.noise_fraction));
  CHECK(p.hand_stiffness_n_per_m == foreign.hand_stiffness_n_per_m);  // not a trait
  // Not drawn: the profile itself.
  CHECK(individual_profile(foreign, SubjectTraits{}).bias_offset_m == foreign.bias_offset_m);
  t.motor_noise_factor = std::nan("");
  CHECK_THROWS_AS(individual_profile(foreign, t), InvalidArgument);
  SubjectSpread bad;
  bad.learning_rate = -0.1;
  CHECK_THROWS_AS(draw_subject_traits(1, bad), InvalidArgument);
}

TEST_CASE("the spreads' and the two-state rates' ranges are their tables', refused just past each bound",
          "[sim][subject_traits]") {
  // Every spread at each bound of its table range is accepted, just past it refused naming the field.
  for (const ParameterField<SubjectSpread>& field : ParameterTable<SubjectSpread>::fields()) {
    for (const double bound : {field.range.low, field.range.high}) {
      SubjectSpread spread;
      spread.*field.member = bound;
      CHECK_NOTHROW(spread.validate());
      spread.*field.member = std::nextafter(bound, bound == field.range.low ? -1.0 : 3.0);
      CHECK_THROWS_WITH(spread.validate(), Catch::Contains(std::string(field.name)));
    }
  }
  // The two-state rates: each field past its table bound is refused naming it; the closed bounds the rules
  // between fields allow are accepted.
  for (const ParameterField<TwoStateRates>& field : ParameterTable<TwoStateRates>::fields()) {
    for (const double bound : {field.range.low, field.range.high}) {
      TwoStateRates rates;
      const bool open = bound == field.range.low ? field.range.low_open : field.range.high_open;
      rates.*field.member = open ? bound : std::nextafter(bound, bound == field.range.low ? -1.0 : 2.0);
      CHECK_THROWS_WITH(rates.validate(), Catch::Contains(std::string(field.name)));
    }
  }
  TwoStateRates rates;
  rates.fast_retention = 0.0;
  rates.fast_learning = 1.0;
  CHECK_NOTHROW(rates.validate());
  // The rules between fields: the slow state keeps more and learns less than the fast one.
  rates = TwoStateRates{};
  rates.slow_retention = rates.fast_retention;
  CHECK_THROWS_WITH(rates.validate(), Catch::Contains("slow_retention"));
  rates = TwoStateRates{};
  rates.slow_learning = rates.fast_learning;
  CHECK_THROWS_WITH(rates.validate(), Catch::Contains("slow_learning"));
  // Their schemas read JSON by the same tables and rules, naming the pointer.
  CHECK(schema_from_json<TwoStateRates>("{}", "r.json").slow_learning == TwoStateRates{}.slow_learning);
  CHECK_THROWS_WITH(schema_from_json<TwoStateRates>(R"({"fast_retention": 1})", "r.json"),
                    Catch::StartsWith("r.json: /fast_retention: "));
  CHECK_THROWS_WITH(schema_from_json<TwoStateRates>(R"({"slow_learning": 0.5})", "r.json"),
                    Catch::Contains("slow_learning"));
  CHECK_THROWS_WITH(schema_from_json<SubjectSpread>(R"({"motor_noise": 2.5})", "s.json"),
                    Catch::StartsWith("s.json: /motor_noise: "));
  CHECK(schema_from_json<SubjectSpread>(schema_json(SubjectSpread{}), "s.json").learning_rate ==
        SubjectSpread{}.learning_rate);
}
