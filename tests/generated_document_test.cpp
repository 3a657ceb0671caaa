// read_generated_document: the Markdown file `bench nearest --markdown FILE` updates is read only when
// it is a regular file of bounded size; anything else is refused with an error naming the path.
#include "eval/generated_document.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <string>

#include "calligraphy/core/errors.hpp"

using calligraphy::InvalidArgument;
using calligraphy::cli::kMaxGeneratedDocumentBytes;
using calligraphy::cli::read_generated_document;
using Catch::Matchers::Contains;

namespace {

struct TemporaryFolder {
  std::filesystem::path folder;
  TemporaryFolder() {
    static int made = 0;  // unique within the process; the process id makes it unique across processes
    folder = std::filesystem::temp_directory_path() /
             ("calligraphy_generated_document_" + std::to_string(::getpid()) + "_" + std::to_string(made++));
    std::filesystem::create_directories(folder);
  }
  ~TemporaryFolder() {
    std::error_code ignored;
    std::filesystem::remove_all(folder, ignored);
  }
  std::string write(const std::string& name, const std::string& bytes) const {
    const std::filesystem::path path = folder / name;
    std::ofstream(path, std::ios::binary) << bytes;
    return path.string();
  }
};

}  // namespace

TEST_CASE("read_generated_document returns a regular file's bytes unchanged", "[generated_document]") {
  const TemporaryFolder temporary;
  const std::string bytes = std::string("# Title\r\n\nline with a NUL ") + '\0' + " and UTF-8 \xe6\xb0\xb8\n";
  const std::string path = temporary.write("doc.md", bytes);
  CHECK(read_generated_document(path) == bytes);

  const std::filesystem::path link = temporary.folder / "link.md";
  std::filesystem::create_symlink(path, link);
  CHECK(read_generated_document(link.string()) == bytes);
}

TEST_CASE("read_generated_document treats a missing file as an empty document", "[generated_document]") {
  const TemporaryFolder temporary;
  CHECK(read_generated_document((temporary.folder / "new.md").string()).empty());
}

TEST_CASE("read_generated_document refuses what is not a regular file, naming it", "[generated_document]") {
  const TemporaryFolder temporary;
  SECTION("an endless device") {
    REQUIRE(std::filesystem::exists("/dev/zero"));
    CHECK_THROWS_AS(read_generated_document("/dev/zero"), InvalidArgument);
    CHECK_THROWS_WITH(read_generated_document("/dev/zero"),
                      Contains("'/dev/zero'") && Contains("not a regular file"));
  }
  SECTION("a directory") {
    const std::string folder = temporary.folder.string();
    CHECK_THROWS_WITH(read_generated_document(folder), Contains("'" + folder + "'"));
  }
  SECTION("a FIFO, which would block a reader") {
    const std::string fifo = (temporary.folder / "pipe.md").string();
    REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
    CHECK_THROWS_WITH(read_generated_document(fifo),
                      Contains("'" + fifo + "'") && Contains("not a regular file"));
  }
}

TEST_CASE("read_generated_document refuses a file above the size limit", "[generated_document]") {
  const TemporaryFolder temporary;
  const std::string at_limit = temporary.write("at_limit.md", std::string(100, 'a'));
  CHECK(read_generated_document(at_limit, 100).size() == 100);
  const std::string above = temporary.write("above.md", std::string(101, 'a'));
  CHECK_THROWS_AS(read_generated_document(above, 100), InvalidArgument);
  CHECK_THROWS_WITH(read_generated_document(above, 100),
                    Contains("'" + above + "'") && Contains("100 bytes"));

  // The default limit, on a sparse file that takes no disk space.
  const std::string huge = temporary.write("huge.md", "");
  std::filesystem::resize_file(huge, kMaxGeneratedDocumentBytes + 1);
  CHECK_THROWS_WITH(read_generated_document(huge), Contains("'" + huge + "'") && Contains("larger than"));
}
