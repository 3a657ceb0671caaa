// write_file_atomically and read_file_for_update (calligraphy/core/atomic_file.hpp), the one way the
// library and the command line write files. Write failures are made with RLIMIT_FSIZE (writes past the
// limit fail with EFBIG, whoever runs the test, root included) and with /dev/full (ENOSPC).
#include "calligraphy/core/atomic_file.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <catch2/catch.hpp>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "temporary_files.hpp"

using namespace calligraphy;
using namespace calligraphy::testing_files;
namespace fs = std::filesystem;

TEST_CASE("write_file_atomically creates and replaces a file, leaving nothing else", "[atomic_file]") {
  TemporaryFolder folder;
  const fs::path target = folder.path / "report.json";
  write_file_atomically(target, std::string_view("first\n"));
  CHECK(contents(target) == "first\n");
  write_file_atomically(target, std::string_view("second, longer\n"));
  CHECK(contents(target) == "second, longer\n");
  write_file_atomically(target, std::string_view(""));
  CHECK(contents(target).empty());
  const std::vector<std::uint8_t> bytes{0, 1, 2, 255};
  write_file_atomically(target, bytes);
  CHECK(contents(target) == std::string("\0\1\2\xff", 4));
  CHECK(folder.names() == std::vector<std::string>{"report.json"});
}

TEST_CASE("write_file_atomically keeps permission bits and symbolic links", "[atomic_file]") {
  TemporaryFolder folder;
  const fs::path target = folder.path / "real.txt";
  const fs::path link = folder.path / "link.txt";
  write_file_atomically(target, std::string_view("old"));
  ::chmod(target.c_str(), 0640);
  fs::create_symlink(target, link);
  write_file_atomically(link, std::string_view("new"));
  CHECK(fs::is_symlink(link));
  CHECK(contents(target) == "new");
  struct stat status {};
  REQUIRE(::stat(target.c_str(), &status) == 0);
  CHECK((status.st_mode & 07777) == 0640);
}

TEST_CASE("a target with the longest name a file system takes is written, alone or in a set",
          "[atomic_file]") {
  // NAME_MAX is 255 bytes: the temporary's and the earlier file's second names beside it must fit too.
  TemporaryFolder folder;
  const std::string longest(255, 'a');
  std::string multibyte(207, 'b');  // then 3-byte characters, one of them where the name is cut
  for (int i = 0; i < 16; ++i) multibyte += "\xe6\xb0\xb8";
  for (const std::string& name : {longest, multibyte}) {
    const fs::path target = folder.path / name;
    write_file_atomically(target, std::string_view("first\n"));
    write_file_atomically(target, std::string_view("second\n"));
    CHECK(contents(target) == "second\n");
    const FileContent set[] = {{target, "third\n"}, {folder.path / "short.csv", "x\n"}};
    write_files_atomically(set);
    CHECK(contents(target) == "third\n");
  }
  CHECK(folder.names() == std::vector<std::string>{longest, multibyte, "short.csv"});
}

TEST_CASE("a dangling symbolic link is kept and the file it names is created", "[atomic_file]") {
  TemporaryFolder folder;
  fs::create_directory(folder.path / "out");
  const fs::path link = folder.path / "link.txt";
  fs::create_symlink("out/new.txt", link);  // relative: read from the link's folder
  CHECK(written_path(link) == folder.path / "out" / "new.txt");
  write_file_atomically(link, std::string_view("new"));
  CHECK(fs::is_symlink(link));
  CHECK(fs::read_symlink(link) == "out/new.txt");
  CHECK(contents(folder.path / "out" / "new.txt") == "new");
  const fs::path loop = folder.path / "loop";
  fs::create_symlink("loop", loop);
  CHECK_THROWS_WITH(write_file_atomically(loop, std::string_view("x")), Catch::Contains(loop.string()));
}

TEST_CASE("a failed write throws naming the file and keeps the earlier one", "[atomic_file]") {
  TemporaryFolder folder;
  const fs::path target = folder.path / "store.bin";
  write_file_atomically(target, std::string_view("earlier"));
  const std::string large(1 << 16, 'x');
  {
    FileSizeLimit limit(1024);
    CHECK_THROWS_AS(write_file_atomically(target, large), DataError);
    try {
      write_file_atomically(target, large);
    } catch (const DataError& e) {
      CHECK_THAT(e.what(), Catch::Contains(target.string()) && Catch::Contains("too large"));
    }
  }
  CHECK(contents(target) == "earlier");
  CHECK(folder.names() == std::vector<std::string>{"store.bin"});  // the temporary was removed
}

TEST_CASE("a target that is not a regular file is written in place and checked", "[atomic_file]") {
  CHECK_NOTHROW(write_file_atomically("/dev/null", std::string_view("discarded")));
  CHECK_THROWS_WITH(write_file_atomically("/dev/full", std::string_view("lost")),
                    Catch::Contains("/dev/full") && Catch::Contains("No space left on device"));
  TemporaryFolder folder;
  CHECK_THROWS_WITH(write_file_atomically(folder.path, std::string_view("x")),
                    Catch::Contains(folder.path.string()));
  CHECK_THROWS_AS(write_file_atomically(folder.path / "missing" / "file", std::string_view("x")), DataError);
  CHECK(folder.names().empty());
}

TEST_CASE("a pipe reached through /proc/self/fd, as /dev/stdout reaches one, is written in place",
          "[atomic_file]") {
  // The link /proc/self/fd/N of a pipe reads `pipe:[INODE]`, no file name: followed by hand it would name a
  // missing file in /proc/self/fd, to be created there.
  int ends[2] = {-1, -1};
  REQUIRE(::pipe(ends) == 0);
  const std::filesystem::path through = "/proc/self/fd/" + std::to_string(ends[1]);
  CHECK(written_path(through) == through);
  CHECK_NOTHROW(write_file_atomically(through, std::string_view("t,x\n")));
  ::close(ends[1]);
  char got[16] = {};
  CHECK(::read(ends[0], got, sizeof got) == 4);
  CHECK(std::string(got) == "t,x\n");
  ::close(ends[0]);
}

TEST_CASE("write_file_exclusively creates a file whole and never replaces anything", "[atomic_file]") {
  TemporaryFolder folder;
  const fs::path target = folder.path / "identity.json";
  CHECK(write_file_exclusively(target, "first\n"));
  CHECK(contents(target) == "first\n");
  CHECK_FALSE(write_file_exclusively(target, "second\n"));  // there already: kept as it was
  CHECK(contents(target) == "first\n");
  // A symbolic link in its place (dangling or not) is not followed and not replaced.
  const fs::path outside = folder.path / "outside.txt";
  const fs::path link = folder.path / "link.json";
  fs::create_symlink(outside, link);
  CHECK_FALSE(write_file_exclusively(link, "through the link"));
  CHECK_FALSE(fs::exists(outside));
  CHECK(fs::is_symlink(link));
  // Nor a folder.
  fs::create_directory(folder.path / "a-folder");
  CHECK_FALSE(write_file_exclusively(folder.path / "a-folder", "x"));
  CHECK(fs::is_directory(folder.path / "a-folder"));
  CHECK(folder.names() == std::vector<std::string>{"a-folder", "identity.json", "link.json"});
}

TEST_CASE("write_file_exclusively: a failed write is an error and leaves no file", "[atomic_file]") {
  TemporaryFolder folder;
  const fs::path target = folder.path / "identity.json";
  {
    FileSizeLimit limit(1024);
    CHECK_THROWS_WITH(write_file_exclusively(target, std::string(1 << 16, 'x')),
                      Catch::Contains(target.string()) && Catch::Contains("too large"));
  }
  CHECK(folder.names().empty());  // no partial file, no temporary
  CHECK_THROWS_WITH(write_file_exclusively(folder.path / "missing" / "file", "x"),
                    Catch::Contains((folder.path / "missing" / "file").string()));
  CHECK(folder.names().empty());
}

TEST_CASE("write_file_exclusively removes the temporary a killed writer left", "[atomic_file]") {
  TemporaryFolder folder;
  const fs::path target = folder.path / "identity.json";
  // What a writer stopped by SIGKILL mid-write leaves where the file system has no O_TMPFILE: its named
  // temporary, half written, of a process that is gone (pid 2^22 + 1 is above Linux's pid_max default).
  const fs::path left = folder.path / ".identity.json.tmp-4194305-0";
  {
    std::ofstream half(left);
    half << "{\"format\": \"calli";
  }
  CHECK(write_file_exclusively(target, "whole\n"));
  CHECK(contents(target) == "whole\n");
  CHECK(folder.names() == std::vector<std::string>{"identity.json"});
}

TEST_CASE("write_file_exclusively: of writers racing for one name, exactly one makes it", "[atomic_file]") {
  TemporaryFolder folder;
  const fs::path target = folder.path / "identity.json";
  std::atomic<int> made{0};
  std::vector<std::thread> writers;
  for (int i = 0; i < 8; ++i) {
    writers.emplace_back([&, i] {
      if (write_file_exclusively(target, "writer " + std::to_string(i) + "\n")) made.fetch_add(1);
    });
  }
  for (std::thread& writer : writers) writer.join();
  CHECK(made.load() == 1);
  const std::string text = contents(target);
  CHECK(text.starts_with("writer "));
  CHECK(text.ends_with("\n"));
  CHECK(folder.names() == std::vector<std::string>{"identity.json"});
}

TEST_CASE("read_file_for_update reads regular files only, within a bound", "[atomic_file]") {
  TemporaryFolder folder;
  const fs::path document = folder.path / "doc.md";
  CHECK_FALSE(read_file_for_update(document).has_value());  // does not exist
  write_file_atomically(document, std::string_view("# Title\n"));
  CHECK(read_file_for_update(document) == std::optional<std::string>("# Title\n"));
  CHECK_FALSE(read_file_for_update("/dev/zero").has_value());  // never read: it would not end
  CHECK_THROWS_WITH(read_file_for_update(document, 4), Catch::Contains(document.string()));
}

TEST_CASE("write_files_atomically replaces a set together, or leaves the earlier set whole",
          "[atomic_file]") {
  TemporaryFolder folder;
  const fs::path trials = folder.path / "trials.csv";
  const fs::path strokes = folder.path / "strokes.csv";
  const std::string small(100, 't'), large(4000, 's');
  {
    const FileContent first[] = {{trials, "old trials\n"}, {strokes, "old strokes\n"}};
    write_files_atomically(first);
  }
  CHECK(contents(trials) == "old trials\n");
  CHECK(contents(strokes) == "old strokes\n");

  SECTION("a write that fails after the first file is whole replaces neither") {
    {
      FileSizeLimit limit(1024);  // the first fits, the second cannot be written (EFBIG), as on a full disk
      const FileContent next[] = {{trials, small}, {strokes, large}};
      CHECK_THROWS_WITH(write_files_atomically(next), Catch::Contains("strokes.csv"));
    }
    CHECK(contents(trials) == "old trials\n");
    CHECK(contents(strokes) == "old strokes\n");
    CHECK(folder.names() == std::vector<std::string>{"strokes.csv", "trials.csv"});
  }
  SECTION("a target that is a folder is refused before any file is replaced") {
    fs::create_directory(folder.path / "summary.csv");
    const FileContent next[] = {{trials, small}, {folder.path / "summary.csv", small}};
    CHECK_THROWS_WITH(write_files_atomically(next), Catch::Contains("summary.csv"));
    CHECK(contents(trials) == "old trials\n");
  }
  SECTION("a set that is written whole replaces every file") {
    const FileContent next[] = {{trials, small}, {strokes, large}};
    write_files_atomically(next);
    CHECK(contents(trials) == small);
    CHECK(contents(strokes) == large);
    CHECK(folder.names() == std::vector<std::string>{"strokes.csv", "trials.csv"});
  }
}

TEST_CASE("write_files_atomically replaces a set only while no other writer holds its folder",
          "[atomic_file]") {
  // Another writer in the middle of its renames holds the folder's lock: this set waits, so the two sets
  // are never interleaved file by file.
  TemporaryFolder folder;
  const fs::path trials = folder.path / "trials.csv";
  const fs::path strokes = folder.path / "strokes.csv";
  const FileContent old_set[] = {{trials, "old trials\n"}, {strokes, "old strokes\n"}};
  write_files_atomically(old_set);
  const int other_writer = ::open(folder.path.c_str(), O_RDONLY | O_DIRECTORY);
  REQUIRE(other_writer >= 0);
  REQUIRE(::flock(other_writer, LOCK_EX) == 0);
  std::atomic<bool> done{false};
  std::thread writer([&] {
    const FileContent new_set[] = {{trials, "new trials\n"}, {strokes, "new strokes\n"}};
    write_files_atomically(new_set);
    done = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  CHECK_FALSE(done);
  CHECK(contents(trials) == "old trials\n");
  CHECK(contents(strokes) == "old strokes\n");
  ::close(other_writer);  // the other writer is done
  writer.join();
  CHECK(done);
  CHECK(contents(trials) == "new trials\n");
  CHECK(contents(strokes) == "new strokes\n");
}

namespace {

// A journal as the set writer words it (include/calligraphy/core/atomic_file.hpp): the format tag, one line
// "TARGET\tKEPT\tTEMPORARY" per file, and the FNV-1a checksum of what precedes it. What a forger who read
// the format would write.
std::string journal_text(const std::vector<std::string>& lines, bool good_checksum = true) {
  std::string text = "calligraphy-set-journal 3\n";
  for (const std::string& line : lines) text.append(line).append("\n");
  std::uint64_t hash = 14695981039346656037ULL;
  for (const char c : text) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 1099511628211ULL;
  }
  if (!good_checksum) hash ^= 1;
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(hash));
  return text + "checksum " + hex + "\n";
}

std::vector<std::string> names_in(const fs::path& folder) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(folder)) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

void plant(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

// A writer that no longer runs (a process id above Linux's largest) left "trials.csv" replaced and
// "strokes.csv" not yet: its temporary and the journal naming both are in `folder`.
const char* const kDead = "4999999-0";

void killed_between_renames(const fs::path& folder) {
  plant(folder / "trials.csv", "new trials\n");
  plant(folder / "strokes.csv", "old strokes\n");
  plant(folder / (std::string(".strokes.csv.tmp-") + kDead), "new strokes\n");
  plant(folder / ".calligraphy-set-4999999-1.journal",
        journal_text({std::string("trials.csv\t\t.trials.csv.tmp-") + kDead,
                      std::string("strokes.csv\t\t.strokes.csv.tmp-") + kDead}));
}

}  // namespace

TEST_CASE("a killed set's journal completes its own set, in its own folder only", "[atomic_file]") {
  TemporaryFolder folder;
  const fs::path original = folder.path / "tables";
  fs::create_directory(original);
  killed_between_renames(original);
  SECTION("the next set in the folder completes it first") {
    write_file_atomically(original / "other.csv", std::string_view("x\n"));  // one file: no set, no journal
    CHECK(contents(original / "strokes.csv") == "old strokes\n");
    const FileContent next[] = {{original / "other.csv", "y\n"}};
    write_files_atomically(next);
    CHECK(contents(original / "strokes.csv") == "new strokes\n");
    CHECK(contents(original / "trials.csv") == "new trials\n");
    CHECK(names_in(original) == std::vector<std::string>{"other.csv", "strokes.csv", "trials.csv"});
  }
  SECTION("a copy of the folder completes the copy, and the original stays as it was") {
    const fs::path copy = folder.path / "copy";
    fs::copy(original, copy);
    const FileContent next[] = {{copy / "other.csv", "y\n"}};
    write_files_atomically(next);
    CHECK(contents(copy / "strokes.csv") == "new strokes\n");
    CHECK(contents(original / "strokes.csv") == "old strokes\n");
    CHECK(contents(original / (std::string(".strokes.csv.tmp-") + kDead)) == "new strokes\n");
    CHECK(fs::exists(original / ".calligraphy-set-4999999-1.journal"));
  }
}

TEST_CASE("a journal that is not the writer's own is refused, named, and left as it is", "[atomic_file]") {
  TemporaryFolder folder;
  const fs::path tables = folder.path / "tables";
  const fs::path outside = folder.path / "outside";
  fs::create_directory(tables);
  fs::create_directory(outside);
  plant(outside / "victim.csv", "precious\n");
  plant(outside / (std::string(".victim.csv.tmp-") + kDead), "forged\n");
  plant(tables / (std::string(".victim.csv.tmp-") + kDead), "forged\n");
  const fs::path journal = tables / ".calligraphy-set-4999999-1.journal";
  const std::string victim = (outside / "victim.csv").string();
  const std::string temporary = std::string(".victim.csv.tmp-") + kDead;
  const std::string forged = GENERATE_COPY(
      journal_text({"../outside/victim.csv\t\t" + temporary}),  // climbs out
      journal_text({victim + "\t\t" + temporary}),              // absolute
      journal_text({"link/victim.csv\t\t" + temporary}),        // a folder link leaving
      journal_text({"victim-link.csv\t\t" + temporary}),        // a target that is a link
      journal_text({"victim.csv\t\t../outside/" + temporary}),  // a temporary elsewhere
      journal_text({"victim.csv\t\t.other.tmp-1-0"}),           // not this writer's name
      journal_text({"victim.csv\t\t" + temporary}, false),      // checksum differs
      victim + "\t\t" + (outside / temporary).string() + "\n",  // the old format
      std::string("calligraphy-set-journal 9\nvictim.csv\t\t" + temporary + "\n"));  // another version
  fs::create_directory_symlink(outside, tables / "link");
  fs::create_symlink(outside / "victim.csv", tables / "victim-link.csv");
  plant(journal, forged);
  const FileContent next[] = {{tables / "trials.csv", "new trials\n"},
                              {tables / "strokes.csv", "new strokes\n"}};
  CHECK_THROWS_WITH(write_files_atomically(next),
                    Catch::Contains(journal.string()) && Catch::Contains("refused"));
  CHECK(contents(outside / "victim.csv") == "precious\n");
  CHECK(contents(journal) == forged);
  CHECK_FALSE(fs::exists(tables / "trials.csv"));
  CHECK(names_in(tables) ==
        std::vector<std::string>{journal.filename().string(), temporary, "link", "victim-link.csv"});
}

TEST_CASE("a set over several folders keeps a journal in each, and a killed one completes folder by folder",
          "[atomic_file]") {
  TemporaryFolder folder;
  const fs::path tables = folder.path / "tables";
  const fs::path figures = folder.path / "figures";
  fs::create_directory(tables);
  fs::create_directory(figures);
  SECTION("a set over two sibling folders leaves no journal, temporary or second name in either") {
    plant(tables / "trials.csv", "old trials\n");
    const FileContent files[] = {{tables / "trials.csv", "new trials\n"}, {figures / "plot.svg", "<svg/>\n"}};
    write_files_atomically(files);
    CHECK(names_in(tables) == std::vector<std::string>{"trials.csv"});
    CHECK(names_in(figures) == std::vector<std::string>{"plot.svg"});
    CHECK(names_in(folder.path) == std::vector<std::string>{"figures", "tables"});
  }
  SECTION("killed between the folders: each folder's journal is completed by the next set in that folder") {
    // figures/ was replaced and its journal removed; tables/ holds its own journal, a whole temporary and a
    // file not yet replaced (as a writer killed after its first folder and a rename of the next leaves them).
    plant(figures / "plot.svg", "new plot\n");
    killed_between_renames(tables);
    const FileContent in_figures[] = {{figures / "other.svg", "x\n"}};
    write_files_atomically(in_figures);  // another folder: tables/ stays as it was, journal and all
    CHECK(contents(tables / "strokes.csv") == "old strokes\n");
    CHECK(fs::exists(tables / ".calligraphy-set-4999999-1.journal"));
    const FileContent in_tables[] = {{tables / "other.csv", "y\n"}};
    write_files_atomically(in_tables);
    CHECK(contents(tables / "trials.csv") == "new trials\n");
    CHECK(contents(tables / "strokes.csv") == "new strokes\n");
    CHECK(names_in(tables) == std::vector<std::string>{"other.csv", "strokes.csv", "trials.csv"});
    CHECK(contents(figures / "plot.svg") == "new plot\n");
  }
  SECTION("a journal naming a file in a subfolder is refused, even one below its own folder") {
    const fs::path sub = tables / "sub";
    fs::create_directory(sub);
    plant(sub / "victim.csv", "precious\n");
    plant(sub / (std::string(".victim.csv.tmp-") + kDead), "forged\n");
    const std::string forged = journal_text({std::string("sub/victim.csv\t\t.victim.csv.tmp-") + kDead});
    plant(tables / ".calligraphy-set-4999999-1.journal", forged);
    const FileContent next[] = {{tables / "trials.csv", "new trials\n"}};
    CHECK_THROWS_WITH(write_files_atomically(next), Catch::Contains("refused"));
    CHECK(contents(sub / "victim.csv") == "precious\n");
    CHECK(contents(tables / ".calligraphy-set-4999999-1.journal") == forged);
  }
}

TEST_CASE("a set is written only in its own folder: a link in a member's place is refused, a hard link kept",
          "[atomic_file]") {
  TemporaryFolder folder;
  const fs::path tables = folder.path / "tables";
  const fs::path outside = folder.path / "outside";
  fs::create_directory(tables);
  fs::create_directory(outside);
  const fs::path victim = outside / "precious.txt";
  plant(victim, "keep me\n");
  plant(tables / "strokes.csv", "old strokes\n");
  SECTION("a symbolic link, to a file or dangling, is refused naming it before anything is replaced") {
    for (const fs::path& target : {victim, outside / "not-there.txt"}) {
      INFO("the link points at " << target.string());
      fs::remove(tables / "trials.csv");
      fs::create_symlink(target, tables / "trials.csv");
      const FileContent next[] = {{tables / "strokes.csv", "new strokes\n"},
                                  {tables / "trials.csv", "new\n"}};
      CHECK_THROWS_WITH(write_files_atomically(next), Catch::Contains((tables / "trials.csv").string()) &&
                                                          Catch::Contains("symbolic link"));
      CHECK(contents(victim) == "keep me\n");
      CHECK_FALSE(fs::exists(outside / "not-there.txt"));
      CHECK(contents(tables / "strokes.csv") == "old strokes\n");
      CHECK(fs::is_symlink(tables / "trials.csv"));
      CHECK(names_in(tables) == std::vector<std::string>{"strokes.csv", "trials.csv"});
    }
  }
  SECTION("a member hard-linked to a file elsewhere gets the new file; the other name keeps the old one") {
    fs::create_hard_link(victim, tables / "trials.csv");
    const FileContent next[] = {{tables / "trials.csv", "new trials\n"}};
    write_files_atomically(next);
    CHECK(contents(tables / "trials.csv") == "new trials\n");
    CHECK(contents(victim) == "keep me\n");
    CHECK(fs::hard_link_count(victim) == 1);
  }
}
