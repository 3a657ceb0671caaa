// A program built against the installed package loads any hanzi-writer-data character with no data folder,
// no store path and no environment: the store of the whole corpus is in the installed library. With the
// install prefix as its argument it also checks that the store is installed with its licence and notice,
// and that the installed file is the store the library holds.
#include <cstdio>
#include <exception>
#include <filesystem>

#include "calligraphy/model/character_library.hpp"
#include "calligraphy/model/corpus_store.hpp"
#include "calligraphy/model/scene.hpp"

int main(int argc, char** argv) {
  using namespace calligraphy;
  try {
    const CharacterLibrary standard = CharacterLibrary::standard();
    const CharacterLibrary embedded = CharacterLibrary::embedded();
    const std::vector<char32_t> all = standard.characters();
    if (all.size() != 9574) {
      std::fprintf(stderr, "the standard set has %zu characters, not 9574\n", all.size());
      return 1;
    }
    // Every 997th character that is not embedded: spread over the store, none named here.
    std::size_t loaded = 0;
    for (std::size_t i = 0; i < all.size(); i += 997) {
      if (embedded.contains(all[i])) continue;
      const Character character = standard.load(all[i]);
      for (const Stroke& stroke : character.strokes) {
        if (stroke.median.size() < 2 || stroke.elements.empty()) {
          std::fprintf(stderr, "%s: a stroke without its median or elements\n", character.source.c_str());
          return 1;
        }
      }
      const Scene scene = Scene::lay_out({character});
      if (scene.stroke_count() != character.strokes.size()) return 1;
      ++loaded;
    }
    std::printf("bundled store: %zu characters, %zu loaded from %s\n", all.size(), loaded,
                CorpusStore::bundled().name().c_str());
    if (argc > 1) {
      const std::filesystem::path folder = std::filesystem::path(argv[1]) / "share/calligraphy/corpus";
      for (const char* name : {"ARPHICPL.TXT", "NOTICE.md"}) {
        if (!std::filesystem::is_regular_file(folder / name)) {
          std::fprintf(stderr, "%s is not installed\n", (folder / name).c_str());
          return 1;
        }
      }
      const CorpusStore file = CorpusStore::open(folder / "hanzi-writer-data-2.0.1.clg");
      if (file.info().file_bytes != CorpusStore::bundled().info().file_bytes ||
          file.characters() != CorpusStore::bundled().characters()) {
        std::fprintf(stderr, "the installed store is not the one the library holds\n");
        return 1;
      }
      std::printf("installed: %s (%zu bytes) with ARPHICPL.TXT and NOTICE.md\n", folder.c_str(),
                  file.info().file_bytes);
    }
    return loaded > 0 ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bundled_store: %s\n", e.what());
    return 1;
  }
}
