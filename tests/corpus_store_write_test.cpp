// write_corpus_store writes like every other output (write_file_atomically): an earlier store is kept
// whole when the new one cannot be written, and no temporary file is ever left beside it.
#include <catch2/catch.hpp>
#include <filesystem>
#include <string>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/model/corpus_store.hpp"
#include "temporary_files.hpp"

using namespace calligraphy;
using namespace calligraphy::testing_files;

namespace {

std::vector<Character> load(std::u32string_view characters) {
  const CharacterLibrary library = CharacterLibrary::embedded();
  std::vector<Character> out;
  for (char32_t c : characters) out.push_back(library.load(c));
  return out;
}

}  // namespace

TEST_CASE("write_corpus_store replaces a store whole and leaves nothing else", "[store_write]") {
  TemporaryFolder folder("calligraphy_store_write");
  const auto path = folder.path / "corpus.clg";
  write_corpus_store(path, load(U"十"));
  write_corpus_store(path, load(U"永十"));
  CHECK(CorpusStore::open(path).characters() == std::vector<char32_t>{U'十', U'永'});
  CHECK(folder.names() == std::vector<std::string>{"corpus.clg"});
}

TEST_CASE("a store that cannot be written keeps the earlier one and leaves no temporary", "[store_write]") {
  TemporaryFolder folder("calligraphy_store_write");
  const auto path = folder.path / "corpus.clg";
  write_corpus_store(path, load(U"十"));
  const std::string earlier = contents(path);
  const std::vector<Character> larger = load(U"永鼎说我");
  {
    const FileSizeLimit limit(earlier.size());  // the larger store fails part-way through its write
    CHECK_THROWS_WITH(write_corpus_store(path, larger), Catch::Contains(path.string()));
  }
  CHECK(contents(path) == earlier);
  CHECK(folder.names() == std::vector<std::string>{"corpus.clg"});

  // Characters it cannot encode: refused before the file is touched.
  const std::vector<Character> twice = load(U"十十");
  CHECK_THROWS_AS(write_corpus_store(path, twice), InvalidArgument);
  CHECK(contents(path) == earlier);

  // A folder that does not exist: an error naming the path, and nothing created.
  const auto missing = folder.path / "missing" / "corpus.clg";
  CHECK_THROWS_WITH(write_corpus_store(missing, larger), Catch::Contains(missing.string()));
  CHECK(folder.names() == std::vector<std::string>{"corpus.clg"});
}
