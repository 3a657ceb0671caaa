// The schema's generic half (calligraphy/core/schema.hpp) on a struct of every kind, made here as a parameter
// struct is made next to its own header: one table, and from it the checks, the JSON both ways, the command
// line's text, the JSON Schema and the docs' table. Adding a field is adding one row: the "added" field below
// reaches every form with nothing else written for it.
#include "calligraphy/core/schema.hpp"

#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "core/utc_time.hpp"

namespace calligraphy {
namespace {

enum class Colour { red, light_blue };

struct Inner {
  double width_m = 0.5;
  bool operator==(const Inner&) const = default;
};

struct Circle {
  double radius_m = 1.0;
  bool operator==(const Circle&) const = default;
};
struct Square {
  double side_m = 2.0;
  bool operator==(const Square&) const = default;
};
enum class Shape { circle, square };

struct Sample {
  double rate_hz = 1000.0;
  int count = 3;
  std::uint64_t seed = 7;
  bool on = true;
  Colour colour = Colour::red;
  std::string name = "x";
  std::string when_utc = "2024-05-01T12:34:56.789Z";
  Inner inner;
  std::vector<Inner> list;
  std::array<double, 2> point_m{0.0, 0.0};
  std::optional<Inner> maybe;
  std::variant<Circle, Square> shape;
  double added_s = 0.25;  // the field "added" in document version 2
  bool operator==(const Sample&) const = default;
};

}  // namespace

template <>
struct EnumTable<Colour> {
  static constexpr std::string_view name = "Colour";
  static constexpr std::array<EnumEntry<Colour>, 2> entries{{
      {Colour::red, "red", "the first"},
      {Colour::light_blue, "light-blue", "the second, spelled with a hyphen everywhere"},
  }};
};
template <>
struct EnumTable<Shape> {
  static constexpr std::string_view name = "Shape";
  static constexpr std::array<EnumEntry<Shape>, 2> entries{{
      {Shape::circle, "circle", "a circle"},
      {Shape::square, "square", "a square"},
  }};
};

template <>
struct SchemaOf<Inner> {
  static const Schema& get() {
    static const std::array fields{
        number_field<&Inner::width_m>("width_m", {.low = 0.0, .high = 1.0, .low_open = true},
                                      {.unit = "m", .doc = "a width"}),
    };
    static const Schema schema{
        .name = "Inner", .doc = "inner", .fields = fields, .defaults = default_of<Inner>};
    return schema;
  }
};
template <>
struct SchemaOf<Circle> {
  static const Schema& get() {
    static const std::array fields{number_field<&Circle::radius_m>("radius_m", {.low = 0.0, .high = 10.0},
                                                                   {.unit = "m", .doc = "a radius"})};
    static const Schema schema{
        .name = "Circle", .doc = "c", .fields = fields, .defaults = default_of<Circle>};
    return schema;
  }
};
template <>
struct SchemaOf<Square> {
  static const Schema& get() {
    static const std::array fields{
        number_field<&Square::side_m>("side_m", {.low = 0.0, .high = 10.0}, {.unit = "m", .doc = "a side"})};
    static const Schema schema{
        .name = "Square", .doc = "s", .fields = fields, .defaults = default_of<Square>};
    return schema;
  }
};

namespace {

void no_equal_names(const void* object) {
  const auto& sample = *static_cast<const Sample*>(object);
  if (sample.name == "forbidden") throw InvalidArgument("Sample.name: 'forbidden' is refused by a rule");
}

}  // namespace

template <>
struct SchemaOf<Sample> {
  static const Schema& get() {
    static const std::array fields{
        number_field<&Sample::rate_hz>(
            "rate_hz", {.low = 100.0, .high = 100000.0},
            {.unit = "Hz", .doc = "a rate", .option = "--rate", .option_value_name = "HZ"}),
        integer_field<&Sample::count>("count", -5, 5, {.doc = "a count", .option = "--count"}),
        unsigned_field<&Sample::seed>("seed", {.doc = "a seed", .option = "--seed"}),
        boolean_field<&Sample::on>("on", {.doc = "a switch", .option = "--on"}),
        enum_field<&Sample::colour>("colour", {.doc = "a colour", .option = "--colour"}),
        string_field<&Sample::name>("name", {.doc = "a name", .option = "--name"}),
        string_field<&Sample::when_utc>("when_utc", {.doc = "a time", .format = StringFormat::utc_time}),
        object_field<&Sample::inner>("inner", {.doc = "a nested struct"}),
        object_list_field<&Sample::list>("list", {.doc = "a list of them"}),
        number_array_field<&Sample::point_m, 2>("point_m", {.low = -1.0, .high = 1.0},
                                                {.unit = "m", .doc = "a point"}),
        optional_object_field<&Sample::maybe>("maybe", {.doc = "perhaps a nested struct"}),
        variant_field<&Sample::shape, Shape>("shape", "kind", {.doc = "one of two shapes"}),
        since(2, option_in("ms", 1000.0,
                           number_field<&Sample::added_s>(
                               "added_s", {.low = 0.0, .high = 60.0},
                               {.unit = "s", .doc = "a field added in version 2", .option = "--added-ms"}))),
    };
    static const Schema schema{.name = "Sample",
                               .doc = "every kind",
                               .fields = fields,
                               .defaults = default_of<Sample>,
                               .check_rules = no_equal_names};
    return schema;
  }
};

namespace {

// Fields whose defaults are "none", no value a document could state: an id that must match a pattern, a
// text of at least one character, a count whose 0 means none, a list that must hold one and a time; and a
// default that is a value of its field beside them.
struct Defaults {
  std::string id;
  std::string characters;
  int period = 0;
  std::vector<Inner> plan;
  std::string when_utc;
  std::string label = "a1";
};

}  // namespace

template <>
struct SchemaOf<Defaults> {
  static const Schema& get() {
    static const std::array fields{
        with_pattern("^[a-z0-9]{1,8}$", string_field<&Defaults::id>("id", {.doc = "an id"})),
        with_min_length(1, string_field<&Defaults::characters>("characters", {.doc = "some characters"})),
        integer_field<&Defaults::period>("period", 1, 26, {.doc = "a period; 0: none"}),
        with_item_count(1, 10, object_list_field<&Defaults::plan>("plan", {.doc = "one to ten"})),
        string_field<&Defaults::when_utc>("when_utc", {.doc = "a time", .format = StringFormat::utc_time}),
        with_pattern("^[a-z0-9]{1,8}$", string_field<&Defaults::label>("label", {.doc = "a label"})),
    };
    static const Schema schema{
        .name = "Defaults", .doc = "defaults", .fields = fields, .defaults = default_of<Defaults>};
    return schema;
  }
};

namespace {

std::string error_of(const std::function<void()>& run) {
  try {
    run();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

Sample everything_set() {
  Sample s;
  s.rate_hz = 250.5;
  s.count = -5;
  s.seed = 18446744073709551615ULL;
  s.on = false;
  s.colour = Colour::light_blue;
  s.name = "名字";
  s.when_utc = "2028-02-29T23:59:60Z";
  s.inner.width_m = 1.0;
  s.list = {Inner{0.1}, Inner{0.2}};
  s.point_m = {-1.0, 0.1 + 0.2};
  s.maybe = Inner{0.3};
  s.shape = Square{3.5};
  s.added_s = 0.125;
  return s;
}

}  // namespace

TEST_CASE("A struct survives its schema's JSON both ways, every value to the bit", "[schema]") {
  for (const Sample& sample : {Sample{}, everything_set()}) {
    const std::string text = schema_json(sample);
    CHECK(schema_from_json<Sample>(text, "s.json") == sample);
    CHECK(schema_from_json<Sample>(text, "s.json", {.require_all = true}) == sample);
  }
  const nlohmann::json written = nlohmann::json::parse(schema_json(everything_set()));
  CHECK(written["colour"] == "light-blue");  // the one spelling
  CHECK(written["shape"] == nlohmann::json{{"kind", "square"}, {"side_m", 3.5}});
  CHECK(written["seed"].get<std::uint64_t>() == 18446744073709551615ULL);
  CHECK(nlohmann::json::parse(schema_json(Sample{}))["maybe"].is_null());
}

TEST_CASE("The schema's JSON reader refuses, naming the source and the pointer", "[schema]") {
  const auto refusal = [](const std::string& text, const SchemaReadOptions& options = {}) {
    return error_of([&] { (void)schema_from_json<Sample>(text, "s.json", options); });
  };
  CHECK_THAT(refusal(R"({"surprise": 1})"),
             Catch::Contains("s.json: /surprise") && Catch::Contains("unknown key"));
  CHECK_THAT(refusal(R"({"rate_hz": null})"), Catch::Contains("s.json: /rate_hz") && Catch::Contains("null"));
  CHECK_THAT(refusal(R"({"rate_hz": "fast"})"), Catch::Contains("/rate_hz") && Catch::Contains("a number"));
  CHECK_THAT(refusal(R"({"rate_hz": 99.5})"), Catch::Contains("/rate_hz") &&
                                                  Catch::Contains("[100, 100000] Hz") &&
                                                  Catch::Contains("Sample.rate_hz"));
  CHECK_THAT(refusal(R"({"count": 6})"), Catch::Contains("/count"));
  CHECK_THAT(refusal(R"({"count": 1.5})"), Catch::Contains("/count"));
  CHECK_THAT(refusal(R"({"seed": -1})"), Catch::Contains("/seed"));
  CHECK_THAT(refusal(R"({"on": 1})"), Catch::Contains("/on") && Catch::Contains("true or false"));
  CHECK_THAT(refusal(R"({"colour": "light_blue"})"),
             Catch::Contains("/colour") && Catch::Contains("light-blue"));
  CHECK_THAT(refusal(R"({"inner": {"width_m": 0}})"),
             Catch::Contains("/inner/width_m") && Catch::Contains("(0, 1] m"));
  CHECK_THAT(refusal(R"({"list": [{"width_m": 0.5}, {"width": 0.5}]})"), Catch::Contains("/list/1/width"));
  CHECK_THAT(refusal(R"({"point_m": [0, 2]})"), Catch::Contains("/point_m/1"));
  CHECK_THAT(refusal(R"({"point_m": [0]})"), Catch::Contains("/point_m") && Catch::Contains("2 numbers"));
  CHECK_THAT(refusal(R"({"shape": {"kind": "triangle"}})"), Catch::Contains("/shape/kind"));
  CHECK_THAT(refusal(R"({"shape": {"kind": "circle", "side_m": 1}})"), Catch::Contains("/shape/side_m"));
  // A time of the calendar in UTC, as the program writes it: another form, a zone, or a day the calendar
  // lacks is refused at its pointer, never read as another day.
  for (const char* wrong :
       {"yesterday", "2027-02-29T12:00:00Z", "2026-04-31T00:00:00Z", "2026-11-28T24:00:01Z",
        "2026-11-28T01:45:43+08:00", "2026-11-28T01:45:43", "2026-11-28 01:45:43Z", ""}) {
    CHECK_THAT(refusal(R"({"when_utc": ")" + std::string(wrong) + R"("})"),
               Catch::Contains("s.json: /when_utc") && Catch::Contains("is not a UTC time"));
  }
  CHECK(schema_from_json<Sample>(R"({"when_utc": "1970-01-01T00:00:00Z"})", "s.json").when_utc ==
        "1970-01-01T00:00:00Z");
  CHECK_THAT(refusal(R"({"name": "forbidden"})"),
             Catch::Contains("s.json: /") && Catch::Contains("refused by a rule"));
  CHECK_THAT(refusal(R"([1])"), Catch::Contains("s.json: /") && Catch::Contains("an object"));
  // A record requires every field but those added after its version, which take their defaults and are named.
  nlohmann::json whole = nlohmann::json::parse(schema_json(everything_set()));
  whole.erase("added_s");
  CHECK_THAT(refusal(whole.dump(), {.require_all = true}),
             Catch::Contains("/added_s") && Catch::Contains("missing"));
  Sample old;
  const SchemaReadResult read = schema_from_json(SchemaOf<Sample>::get(), &old, whole.dump(), "old.json",
                                                 {.require_all = true, .version = 1});
  CHECK(read.defaulted == std::vector<std::string>{"/added_s"});
  CHECK(old.added_s == Sample{}.added_s);
  whole.erase("count");
  CHECK_THAT(refusal(whole.dump(), {.require_all = true, .version = 1}), Catch::Contains("/count"));
  // null only where the field may be empty
  whole = nlohmann::json::parse(schema_json(everything_set()));
  whole["maybe"] = nullptr;
  CHECK(!schema_from_json<Sample>(whole.dump(), "s.json").maybe.has_value());
}

TEST_CASE("Every bounded field is accepted at its bounds and refused just past them", "[schema]") {
  const Schema& schema = SchemaOf<Sample>::get();
  for (const SchemaField& field : schema.fields) {
    if (field.kind != FieldKind::number) continue;
    INFO(field.name);
    for (const bool low : {true, false}) {
      const double bound = low ? field.range.low : field.range.high;
      const bool open = low ? field.range.low_open : field.range.high_open;
      const double past = std::nextafter(bound, low ? -INFINITY : INFINITY);
      nlohmann::json document = {{std::string(field.name), bound}};
      if (open) {
        CHECK_THROWS_AS(schema_from_json<Sample>(document.dump(), "s.json"), DataError);
      } else {
        CHECK_NOTHROW(schema_from_json<Sample>(document.dump(), "s.json"));
      }
      document[std::string(field.name)] = past;
      CHECK_THROWS_AS(schema_from_json<Sample>(document.dump(), "s.json"), DataError);
      // The same range in the check and in the command line's text.
      Sample sample;
      field.set_number(field, &sample, 0, past);
      CHECK_THROWS_AS(check_schema(sample), InvalidArgument);
    }
  }
}

TEST_CASE("The command line's text of a field is parsed once and written back the same", "[schema]") {
  const Schema& schema = SchemaOf<Sample>::get();
  const Sample sample = everything_set();
  for (const SchemaField& field : schema.fields) {
    if (field.kind == FieldKind::object || field.kind == FieldKind::object_list ||
        field.kind == FieldKind::number_array || field.kind == FieldKind::variant)
      continue;
    INFO(field.name);
    Sample copy;
    set_field_from_text(field, &copy, field_text(field, &sample));
    CHECK(field_text(field, &copy) == field_text(field, &sample));
  }
  Sample s;
  const SchemaField& added = *schema.field("--added-ms");
  set_field_from_text(added, &s, "250");  // the option is in ms, the field in s
  CHECK(s.added_s == 0.25);
  CHECK(field_text(added, &s) == "250");
  const SchemaField& count = *schema.field("count");
  for (const char* bad : {"-0", "+1", "1.0", "", " 1", "6", "0x1"})
    CHECK_THROWS_AS(set_field_from_text(count, &s, bad), InvalidArgument);
  set_field_from_text(count, &s, "-5");
  CHECK(s.count == -5);
  CHECK_THROWS_AS(set_field_from_text(*schema.field("seed"), &s, "-1"), InvalidArgument);
  CHECK_THROWS_AS(set_field_from_text(*schema.field("rate_hz"), &s, "nan"), InvalidArgument);
  CHECK_THAT(error_of([&] { set_field_from_text(*schema.field("--colour"), &s, "blue"); }),
             Catch::Contains("'red', 'light-blue'"));
  CHECK(parse_enum<Colour>("light-blue") == Colour::light_blue);
  CHECK(enum_spelling(Colour::light_blue) == "light-blue");
}

TEST_CASE("An omissible field may be missing from a document of any version and is not required",
          "[schema]") {
  const Schema& base = SchemaOf<Sample>::get();
  static const std::vector<SchemaField> fields = [] {
    std::vector<SchemaField> out(SchemaOf<Sample>::get().fields.begin(),
                                 SchemaOf<Sample>::get().fields.end());
    for (SchemaField& field : out) {
      if (field.name == "name") field = omissible(field);
    }
    return out;
  }();
  const Schema schema{.name = base.name,
                      .doc = base.doc,
                      .fields = fields,
                      .defaults = base.defaults,
                      .check_rules = base.check_rules};
  nlohmann::json whole = nlohmann::json::parse(schema_json(everything_set()));
  whole.erase("name");
  Sample read;
  const SchemaReadResult result =
      schema_from_json(schema, &read, whole.dump(), "s.json", {.require_all = true});
  CHECK(result.defaulted == std::vector<std::string>{"/name"});
  CHECK(read.name == Sample{}.name);
  CHECK(read.count == everything_set().count);
  // The schema that requires it refuses the same document; null is no value for either.
  CHECK_THAT(error_of([&] { (void)schema_from_json<Sample>(whole.dump(), "s.json", {.require_all = true}); }),
             Catch::Contains("s.json: /name") && Catch::Contains("missing"));
  whole["name"] = nullptr;
  CHECK_THAT(
      error_of([&] { (void)schema_from_json(schema, &read, whole.dump(), "s.json", {.require_all = true}); }),
      Catch::Contains("s.json: /name") && Catch::Contains("null"));
  const nlohmann::json json_schema =
      nlohmann::json::parse(json_schema_text(schema, "https://x.invalid/s.json", "Sample", true));
  CHECK(json_schema["required"].size() == fields.size() - 2);  // neither the omissible nor the added field
  for (const auto& key : json_schema["required"]) CHECK(key != "name");
  CHECK(json_schema["properties"].contains("name"));
}

TEST_CASE("The JSON Schema and the docs' table come from the same fields", "[schema]") {
  const nlohmann::json schema = nlohmann::json::parse(
      json_schema_text(SchemaOf<Sample>::get(), "https://x.invalid/s.json", "Sample", true));
  CHECK(schema["$schema"] == "https://json-schema.org/draft/2020-12/schema");
  CHECK(schema["additionalProperties"] == false);
  const auto& rate = schema["properties"]["rate_hz"];
  CHECK(rate["minimum"] == 100.0);
  CHECK(rate["maximum"] == 100000.0);
  CHECK(rate["default"] == 1000.0);
  CHECK_THAT(rate["description"].get<std::string>(), Catch::Contains("[Hz]"));
  CHECK(schema["$defs"]["Inner"]["properties"]["width_m"]["exclusiveMinimum"] == 0.0);
  CHECK(schema["properties"]["colour"]["enum"] == nlohmann::json{"red", "light-blue"});
  CHECK(schema["properties"]["colour"]["title"] == "Colour");
  CHECK(schema["properties"]["when_utc"]["format"] == "date-time");
  CHECK(schema["properties"]["when_utc"]["pattern"] == std::string(kUtcTimePattern));
  CHECK(schema["properties"]["when_utc"]["default"] == "2024-05-01T12:34:56.789Z");  // a time: a value
  CHECK(!schema["properties"]["name"].contains("format"));  // the enumeration's table names it
  CHECK(schema["properties"]["shape"]["title"] == "Shape");
  CHECK(schema["properties"]["seed"]["maximum"].get<std::uint64_t>() == 18446744073709551615ULL);
  CHECK(schema["properties"]["shape"]["oneOf"].size() == 2);
  CHECK(schema["properties"]["maybe"]["anyOf"][1] == nlohmann::json{{"type", "null"}});
  // Every field but the one added in version 2 is required of a record; none of a person's file.
  CHECK(schema["required"].size() == SchemaOf<Sample>::get().fields.size() - 1);
  const nlohmann::json lenient = nlohmann::json::parse(
      json_schema_text(SchemaOf<Sample>::get(), "https://x.invalid/s.json", "Sample", false));
  CHECK(!lenient.contains("required"));
  const std::string table = schema_markdown(SchemaOf<Sample>::get());
  CHECK_THAT(table, Catch::Contains(
                        "| `added_s` | number | s | in [0, 60] s | `0.25` | a field added in version 2 |"));
  CHECK_THAT(table, Catch::Contains("red\\|light-blue"));
}

TEST_CASE("A default is stated only where it is a value of its field", "[schema]") {
  // A default is what a key left out means: a JSON Schema validator takes it for a value of the property,
  // and the docs' table says it. One that the field refuses is none, stated nowhere.
  const Schema& schema = SchemaOf<Defaults>::get();
  const nlohmann::json json_schema =
      nlohmann::json::parse(json_schema_text(schema, "https://x.invalid/d.json", "Defaults", true));
  const auto& properties = json_schema["properties"];
  for (const char* key : {"id", "characters", "period", "plan", "when_utc"}) {
    INFO(key);
    CHECK(!properties[key].contains("default"));
  }
  CHECK(properties["label"]["default"] == "a1");
  // The rules that make them none are stated with them.
  CHECK(properties["id"]["pattern"] == "^[a-z0-9]{1,8}$");
  CHECK(properties["characters"]["minLength"] == 1);
  CHECK(properties["plan"]["minItems"] == 1);
  CHECK(properties["plan"]["maxItems"] == 10);
  const std::string table = schema_markdown(schema);
  CHECK_THAT(table, Catch::Contains("| `id` | string |  |  | - | an id |"));
  CHECK_THAT(table, Catch::Contains("| `plan` | object list |  |  | - | one to ten |"));
  CHECK_THAT(table, Catch::Contains("| `when_utc` | string |  |  | - | a time |"));
  CHECK_THAT(table, Catch::Contains("| `label` | string |  |  | `\"a1\"` | a label |"));
  // The same judgement on a value: a pattern's match, the length in characters, the list's size.
  Defaults set;
  set.id = "abc";
  set.characters = "十";
  set.period = 26;
  set.plan = {Inner{}};
  set.when_utc = "2024-05-01T12:34:56Z";
  for (const SchemaField& field : schema.fields) {
    INFO(field.name);
    CHECK(field.holds_valid_value(&set));
  }
  set.id = "ABC";
  CHECK(!schema.field("id")->holds_valid_value(&set));
}

}  // namespace calligraphy
