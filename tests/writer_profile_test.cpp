// Writer profiles: the three named profiles, validation naming the field, and setting fields by name.
#include "calligraphy/trial/writer_profile.hpp"

#include <catch2/catch.hpp>
#include <regex>
#include <string>

#include "calligraphy/core/errors.hpp"

using namespace calligraphy;

TEST_CASE("The named profiles are valid and differ as described", "[writer]") {
  const WriterProfile novice = WriterProfile::novice();
  const WriterProfile skilled = WriterProfile::skilled();
  const WriterProfile foreign = WriterProfile::foreign();
  for (const WriterProfile& p : {novice, skilled, foreign}) CHECK_NOTHROW(p.validate());
  CHECK(novice.name == "novice");
  CHECK(writer_profile("skilled").name == "skilled");
  CHECK(writer_profile("foreign").name == "foreign");
  // The paper's foreign student: larger bias, order and direction errors, slower.
  CHECK(foreign.bias_offset_m > novice.bias_offset_m);
  CHECK(foreign.scale_error > novice.scale_error);
  CHECK(foreign.order_error_probability > 0.0);
  CHECK(foreign.backwards_probability > 0.0);
  CHECK(foreign.writing_speed_m_s < novice.writing_speed_m_s);
  CHECK(novice.order_error_probability == 0.0);
  CHECK(skilled.writing_speed_m_s > novice.writing_speed_m_s);
  CHECK(skilled.bias_offset_m < novice.bias_offset_m);
  CHECK_THROWS_WITH(writer_profile("expert"), Catch::Contains("expert") && Catch::Contains("foreign"));
}

TEST_CASE("Every name of the profile list is a profile of that name, and an unknown one lists them all",
          "[writer]") {
  const auto names = writer_profile_names();
  REQUIRE(names.size() == 3);
  for (const std::string_view name : names) {
    CHECK(writer_profile(name).name == name);
    CHECK_THROWS_WITH(writer_profile(std::string(name) + "x"), Catch::Contains(std::string(name)));
  }
}

TEST_CASE("validate names the field that is out of range", "[writer]") {
  WriterProfile p;
  p.writing_speed_m_s = -0.01;
  CHECK_THROWS_WITH(p.validate(), Catch::Contains("writing_speed_m_s"));
  p = WriterProfile{};
  p.order_error_probability = 1.5;
  CHECK_THROWS_WITH(p.validate(), Catch::Contains("order_error_probability"));
  p = WriterProfile{};
  p.visual_delay_s = std::nan("");
  CHECK_THROWS_WITH(p.validate(), Catch::Contains("visual_delay_s"));
  p = WriterProfile{};
  p.max_attempts_per_stroke = 0;
  CHECK_THROWS_WITH(p.validate(), Catch::Contains("max_attempts_per_stroke"));
}

TEST_CASE("Writer parameters are set by name, and an unknown name is refused naming it", "[writer]") {
  WriterProfile p;
  set_writer_parameter(p, "bias_offset_m", 0.004);
  CHECK(p.bias_offset_m == 0.004);
  CHECK(writer_parameter(p, "bias_offset_m") == 0.004);
  set_writer_parameter(p, "max_attempts_per_stroke", 7.0);
  CHECK(p.max_attempts_per_stroke == 7);
  CHECK_THROWS_WITH(set_writer_parameter(p, "max_attempts_per_stroke", 2.5), Catch::Contains("whole number"));
  CHECK_THROWS_WITH(set_writer_parameter(p, "bias_offset", 0.004),
                    Catch::Contains("'bias_offset'") && Catch::Contains("bias_offset_m"));
  CHECK_THROWS_WITH(writer_parameter(p, "speed"), Catch::Contains("'speed'"));
  // A refused value leaves the profile as it was.
  const WriterProfile before = p;
  CHECK_THROWS_WITH(set_writer_parameter(p, "hand_stiffness_n_per_m", -5.0),
                    Catch::Contains("hand_stiffness_n_per_m"));
  CHECK(p.hand_stiffness_n_per_m == before.hand_stiffness_n_per_m);
  // Every listed name can be read and written back.
  for (const std::string& key : writer_parameter_names()) {
    INFO(key);
    WriterProfile q = WriterProfile::foreign();
    const double value = writer_parameter(q, key);
    CHECK_NOTHROW(set_writer_parameter(q, key, value));
    CHECK(writer_parameter(q, key) == value);
  }
}

TEST_CASE("A key=value setting as given on a command line is read once into a typed setting", "[writer]") {
  CHECK(parse_writer_setting("order_error_probability=0.3") == WriterSetting{"order_error_probability", 0.3});
  CHECK(parse_writer_setting("visual_delay_s=1.5e-1") == WriterSetting{"visual_delay_s", 0.15});
  CHECK_THROWS_WITH(parse_writer_setting("order_error_probability"), Catch::Contains("key=value"));
  CHECK_THROWS_WITH(parse_writer_setting("visual_delay_s=fast"), Catch::Contains("'fast' is not a number"));
  CHECK_THROWS_WITH(parse_writer_setting("visual_delay_s=0.1s"), Catch::Contains("not a number"));
  WriterProfile p;
  CHECK_THROWS_WITH(set_writer_parameter(p, parse_writer_setting("delay=0.1").key, 0.1),
                    Catch::Contains("'delay'"));
  // Its text reads back to the same bits.
  const WriterSetting third{"stroke_jitter_m", 1.0 / 3.0 * 1e-4};
  CHECK(parse_writer_setting(writer_setting_text(third)) == third);
}

TEST_CASE("The JSON Schema's pattern of a setting's text takes every text the parser reads", "[writer]") {
  // A version-1 record's settings are this text: the schema may refuse only what the reader refuses.
  const std::regex pattern(std::string(kWriterSettingTextPattern), std::regex::ECMAScript);
  const auto parses = [](const std::string& text) {
    try {
      (void)parse_writer_setting(text);
      return true;
    } catch (const InvalidArgument&) {
      return false;
    }
  };
  for (const std::string text :
       {"bias_offset_m=0.004", "k=-0.5", "k=5.", "k=.5", "k=-.5", "k=1e3", "k=1E+3", "k=2.5e-300", "k=1e-400",
        "=1", "k=0", "k=-0", "k=123456789012345678901234567890", "a b=1"}) {
    INFO(text);
    CHECK(parses(text));
    CHECK(std::regex_search(text, pattern));
  }
  for (const std::string text :
       {"k", "k=", "k=+1", "k= 1", "k=1 ", "k=inf", "k=nan", "k=0x10", "k=1e", "k=.", "k=1=2", "k=1.2.3"}) {
    INFO(text);
    CHECK(!parses(text));
    CHECK(!std::regex_search(text, pattern));
  }
  CHECK(!parses("k=1e999"));  // beyond a double: the parser's own refusal
}
