// Corpus store timings: open, load one character on demand, a scene of 4 characters,
// and for comparison the same character parsed from JSON and fitted. Uses the store named by the
// environment variable CALLIGRAPHY_STORE (e.g. from `calligraphy corpus build --out FILE`), else a
// store of the embedded default characters written to a temporary file.
// Run a Release build: CALLIGRAPHY_STORE=/tmp/corpus.clg build/bin/store_bench --benchmark_repetitions=10
//   --benchmark_report_aggregates_only=true   (the median row is the figure to quote)
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "calligraphy/model/character_library.hpp"
#include "calligraphy/model/corpus_store.hpp"
#include "calligraphy/model/scene.hpp"

namespace {

using namespace calligraphy;

std::filesystem::path store_path() {
  if (const char* path = std::getenv("CALLIGRAPHY_STORE")) return path;
  static const std::filesystem::path temporary = [] {
    const CharacterLibrary library = CharacterLibrary::embedded();
    std::vector<Character> characters;
    for (char32_t c : library.characters()) characters.push_back(library.load(c));
    const auto path = std::filesystem::temp_directory_path() / "calligraphy_store_bench.clg";
    write_corpus_store(path, characters);
    return path;
  }();
  return temporary;
}

const CorpusStore& store() {
  static const CorpusStore opened = CorpusStore::open(store_path());
  return opened;
}

// Characters spread over the whole store, so that loads do not all hit one cache line.
std::vector<char32_t> sample_characters(std::size_t count) {
  const auto all = store().characters();
  std::vector<char32_t> out;
  for (std::size_t k = 0; k < count && !all.empty(); ++k) out.push_back(all[(k * 7919) % all.size()]);
  return out;
}

void store_open(benchmark::State& state) {
  const auto path = store_path();
  for (auto _ : state) benchmark::DoNotOptimize(CorpusStore::open(path));
  state.counters["file_bytes"] = static_cast<double>(std::filesystem::file_size(path));
}

void store_load_one(benchmark::State& state) {
  const auto characters = sample_characters(256);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(store().load(characters[i]));
    i = (i + 1) % characters.size();
  }
  state.counters["characters_in_store"] = static_cast<double>(store().size());
}

void json_load_one(benchmark::State& state) {  // the embedded JSON, parsed and fitted, for comparison
  const CharacterLibrary library = CharacterLibrary::embedded();
  const auto characters = library.characters();
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(library.load(characters[i]));
    i = (i + 1) % characters.size();
  }
}

// Resident set size from /proc/self/statm [bytes]; 0 where unavailable.
std::size_t resident_bytes() {
  std::ifstream statm("/proc/self/statm");
  std::size_t pages = 0;
  std::size_t resident = 0;
  statm >> pages >> resident;
  return resident * 4096;
}

template <typename T>
std::size_t vector_bytes(const std::vector<T>& v) {
  return v.capacity() * sizeof(T);
}

// Bytes of a scene's model data: the objects and every vector's heap block (allocator overhead not counted).
std::size_t scene_bytes(const Scene& scene) {
  std::size_t bytes = sizeof(Scene) + vector_bytes(scene.characters);
  for (const auto& c : scene.characters) {
    bytes += vector_bytes(c.strokes);
    for (const auto& s : c.strokes) {
      bytes += vector_bytes(s.elements) + vector_bytes(s.attraction_factors) + vector_bytes(s.median_m);
    }
  }
  return bytes;
}

void scene_of_four_from_store(benchmark::State& state) {
  const std::vector<char32_t> text = {U'永', U'字', U'八', U'法'};
  std::vector<char32_t> wanted;
  for (char32_t c : text) wanted.push_back(store().contains(c) ? c : sample_characters(4)[wanted.size()]);
  // RSS growth of a fresh open + 4 loads + lay_out, once, outside the timing (page granularity).
  const std::size_t rss_before = resident_bytes();
  const CorpusStore fresh = CorpusStore::open(store_path());
  std::vector<Character> once;
  for (char32_t c : wanted) once.push_back(fresh.load(c));
  const Scene first = Scene::lay_out(once);
  state.counters["rss_delta_bytes"] =
      static_cast<double>(resident_bytes() - std::min(rss_before, resident_bytes()));
  benchmark::DoNotOptimize(first);
  std::size_t bytes = 0;
  for (auto _ : state) {
    std::vector<Character> characters;
    for (char32_t c : wanted) characters.push_back(store().load(c));
    const Scene scene = Scene::lay_out(characters);
    bytes = scene_bytes(scene);
    benchmark::DoNotOptimize(scene);
  }
  state.counters["scene_model_bytes"] = static_cast<double>(bytes);
}

}  // namespace

BENCHMARK(store_open)->Unit(benchmark::kMicrosecond);
BENCHMARK(store_load_one)->Unit(benchmark::kMicrosecond);
BENCHMARK(json_load_one)->Unit(benchmark::kMicrosecond);
BENCHMARK(scene_of_four_from_store)->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
