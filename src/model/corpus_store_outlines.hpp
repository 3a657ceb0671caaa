#pragma once
// Internal: the strokes' outlines (SVG path data) in a corpus store record (docs/corpus.md, format 1.2).
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "model/corpus_store_format.hpp"

namespace calligraphy::store {

/// Appends a character's outlines: `paths` empty (none) or one SVG path per stroke. A path of absolute
/// M, L, Q, C and Z, each with its own letter, and whole numbers within kMaxDataCoordinate is stored
/// compactly; any other path as its text. `fail` throws, given what is wrong.
void encode_outlines(BitWriter& out, const std::vector<std::string>& paths, std::size_t stroke_count,
                     const std::function<void(const std::string&)>& fail);

/// Reads what encode_outlines wrote. Returns the paths (empty: none) when `keep`, else only checks them.
/// Each compact path comes back as "M x y Q x y x y ... Z": the same numbers as written, so a parser
/// flattens it into the same polygons. `bad` throws, given what is wrong; a read past the record too.
std::vector<std::string> decode_outlines(BitReader& in, std::size_t stroke_count, bool keep,
                                         const std::function<void(const std::string&)>& bad);

}  // namespace calligraphy::store
