// The one parse and strict reader of JSON documents (src/core/json_document.hpp, json_reader.hpp): an error
// names the source and the RFC 6901 pointer of the value, keys escaped ("~" as "~0", "/" as "~1").
#include "core/json_document.hpp"

#include <catch2/catch.hpp>
#include <string>

#include "calligraphy/core/errors.hpp"
#include "core/json_reader.hpp"

using namespace calligraphy;

namespace {

std::string error_of(const std::string& text) {
  try {
    (void)json_detail::parse_json_document(text, "doc.json");
  } catch (const DataError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("a number beyond a double is named by its pointer, keys escaped", "[json]") {
  CHECK(error_of(R"({"a/b": {"c~d": [0, 1e999]}})").starts_with("doc.json: /a~1b/c~0d/1: "));
  CHECK(error_of(R"([[1, 2], {"x": -1e400}])").starts_with("doc.json: /1/x: "));
  CHECK_THAT(error_of(R"({"a": 1,)"), Catch::StartsWith("doc.json: not valid JSON at byte"));
  CHECK(error_of(R"({"a": [1e300]})").empty());
}

TEST_CASE("the reader's pointers escape keys the same way", "[json]") {
  CHECK(json_detail::child_pointer("/a~1b", "c~d") == "/a~1b/c~0d");
  CHECK(json_detail::child_pointer("", std::size_t{3}) == "/3");
  const nlohmann::json document = json_detail::parse_json(R"({"x/y": "text"})", "doc.json");
  json_detail::ObjectReader reader(document, "", "doc.json");
  CHECK_THAT(
      [&] {
        try {
          (void)reader.number("x/y", 0.0, 1.0);
        } catch (const DataError& e) {
          return std::string(e.what());
        }
        return std::string();
      }(),
      Catch::StartsWith("doc.json: /x~1y: "));
}

TEST_CASE("a key given twice in one object is refused by its pointer", "[json]") {
  // nlohmann/json would keep the last and drop the first without a word.
  CHECK(error_of(R"({"seed": 1, "seed": 2})").starts_with("doc.json: /seed: the key is given twice"));
  CHECK(error_of(R"({"a": [{"x": 1}, {"y": 2, "y": 3}]})").starts_with("doc.json: /a/1/y: "));
  CHECK(error_of(R"({"a~b": {"c/d": 0, "c/d": 0}})").starts_with("doc.json: /a~0b/c~1d: "));
  // The same key in two objects, or at two depths, is no duplicate.
  CHECK(error_of(R"({"x": {"x": 1}, "y": [{"x": 1}, {"x": 2}]})").empty());
  CHECK(error_of(R"([{"k": 1}, {"k": 1}])").empty());
}

TEST_CASE("a file of another kind given to a JSON reader is named for what it is", "[json]") {
  // The parser's own exception tag never reaches the message.
  CHECK(error_of("t,x,y,z,fx\n0,0,0,0,0\n") ==
        "doc.json: not a JSON document: it is CSV text (its first line: t,x,y,z,fx)");
  CHECK(error_of("\xEF\xBB\xBF\"t\",\"x\"\r\n") ==
        "doc.json: not a JSON document: it is CSV text (its first line: \"t\",\"x\")");
  CHECK(error_of("calligraphy-trace\nversion 1\n")
            .starts_with("doc.json: not a JSON document: it is a calligraphy "
                         "trace file"));
  CHECK(error_of(std::string("\x1f\x8b\x08\x00", 4)).find("gzip-compressed data") != std::string::npos);
  CHECK(error_of("CLGSTORE\x01").find("a corpus store") != std::string::npos);
  CHECK(error_of("\x89HDF\r\n\x1a\n").find("an HDF5 file") != std::string::npos);
  CHECK(error_of("<svg xmlns=\"http://www.w3.org/2000/svg\">").find("markup") != std::string::npos);
  CHECK(error_of(std::string("ab\0cd", 5)).find("binary data") != std::string::npos);
  const std::string long_line = "a" + std::string(100, ',');
  CHECK(error_of(long_line).ends_with(",...)"));
  // JSON that is only malformed keeps the byte and the reason, without the tag.
  const std::string cut = error_of(R"({"a": 1,)");
  CHECK(cut.starts_with("doc.json: not valid JSON at byte 9: "));
  CHECK(cut.find("json.exception") == std::string::npos);
  CHECK(cut.find("parse error at") == std::string::npos);
  CHECK(error_of("tru").find("json.exception") == std::string::npos);
  CHECK(json_detail::non_json_kind(R"({"a": "x,y"})").empty());
  CHECK(json_detail::non_json_kind("[1, 2").empty());
  CHECK(json_detail::non_json_kind("// a comment, then\n{}").empty());
  CHECK(json_detail::parser_reason("[json.exception.out_of_range.406] number overflow parsing '1e999'") ==
        "number overflow parsing '1e999'");
}
