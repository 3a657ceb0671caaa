// The strokes' outlines in a corpus store record: hanzi-writer-data's `strokes` (Make Me a Hanzi's SVG
// paths, absolute commands and whole data units) delta-coded like the medians; anything else kept as text.
#include "model/corpus_store_outlines.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <optional>

#include "calligraphy/model/character_library.hpp"

namespace calligraphy::store {
namespace {

// |x| of a compact point: the bound every outline path's coordinates are held to (parse_svg_path).
constexpr auto kMaxOutlineCoordinate = static_cast<std::int64_t>(kMaxDataCoordinate);

struct CompactPath {
  std::vector<std::uint64_t> codes;       // each command's index in kOutlineCommands
  std::vector<std::int64_t> coordinates;  // x, y, x, y, ...
};

// The path as commands and whole numbers, or nothing when it is not in the compact form.
std::optional<CompactPath> compact_form(const std::string& path) {
  CompactPath compact;
  std::size_t at = 0;
  const auto skip = [&] {
    while (at < path.size() && (path[at] == ',' || std::isspace(static_cast<unsigned char>(path[at])))) ++at;
  };
  while (skip(), at < path.size()) {
    const char command = path[at++];
    const char* known = std::find(std::begin(kOutlineCommands), std::end(kOutlineCommands), command);
    if (known == std::end(kOutlineCommands)) return std::nullopt;
    if (compact.codes.empty() != (command == 'M')) return std::nullopt;  // one M, first
    compact.codes.push_back(static_cast<std::uint64_t>(known - std::begin(kOutlineCommands)));
    for (int i = 0; i < 2 * outline_command_points(command); ++i) {
      skip();
      std::int64_t value = 0;
      const char* begin = path.data() + at;
      const auto [end, error] = std::from_chars(begin, path.data() + path.size(), value);
      if (error != std::errc() || end == begin || std::abs(value) > kMaxOutlineCoordinate)
        return std::nullopt;
      // "7." or "7e2" is a number the compact form would not give back as written.
      if (end != path.data() + path.size() && (*end == '.' || *end == 'e' || *end == 'E'))
        return std::nullopt;
      at = static_cast<std::size_t>(end - path.data());
      compact.coordinates.push_back(value);
    }
  }
  if (compact.codes.empty() || compact.codes.size() >= (std::size_t{1} << kOutlineCountExtensionBits))
    return std::nullopt;
  return compact;
}

int delta_width(const std::vector<std::int64_t>& xy, std::size_t axis) {
  int width = 0;
  for (std::size_t i = 2 + axis; i < xy.size(); i += 2)
    width = std::max(width, bit_width(zigzag(xy[i] - xy[i - 2])));
  return width;
}

}  // namespace

void encode_outlines(BitWriter& out, const std::vector<std::string>& paths, std::size_t stroke_count,
                     const std::function<void(const std::string&)>& fail) {
  if (!paths.empty() && paths.size() != stroke_count) {
    fail("has " + std::to_string(paths.size()) + " outlines for " + std::to_string(stroke_count) +
         " strokes");
  }
  out.put(paths.empty() ? 0 : 1, 1);
  for (std::size_t s = 0; s < paths.size(); ++s) {
    const std::optional<CompactPath> compact = compact_form(paths[s]);
    out.put(compact ? 0 : 1, 1);
    if (!compact) {
      if (paths[s].size() > kMaxOutlinePathBytes)
        fail("stroke " + std::to_string(s + 1) + ": outline path of " + std::to_string(paths[s].size()) +
             " bytes (at most 1,048,575)");
      out.put(paths[s].size(), kOutlineTextLengthBits);
      for (const char c : paths[s]) out.put(static_cast<unsigned char>(c), 8);
      continue;
    }
    const std::size_t count = compact->codes.size();
    if (count < kOutlineCountEscape) {
      out.put(count, kOutlineCountBits);
    } else {
      out.put(kOutlineCountEscape, kOutlineCountBits);
      out.put(count, kOutlineCountExtensionBits);
    }
    for (const std::uint64_t code : compact->codes) out.put(code, kOutlineCommandBits);
    const std::vector<std::int64_t>& xy = compact->coordinates;  // at least the M's point
    const int start_width = std::max(bit_width(zigzag(xy[0])), bit_width(zigzag(xy[1])));
    out.put(static_cast<std::uint64_t>(start_width), 5);
    out.put(zigzag(xy[0]), start_width);
    out.put(zigzag(xy[1]), start_width);
    if (xy.size() <= 2) continue;
    const int width_x = delta_width(xy, 0);
    const int width_y = delta_width(xy, 1);
    out.put(static_cast<std::uint64_t>(width_x), 5);
    out.put(static_cast<std::uint64_t>(width_y), 5);
    for (std::size_t i = 2; i < xy.size(); i += 2) {
      out.put(zigzag(xy[i] - xy[i - 2]), width_x);
      out.put(zigzag(xy[i + 1] - xy[i - 1]), width_y);
    }
  }
}

std::vector<std::string> decode_outlines(BitReader& in, std::size_t stroke_count, bool keep,
                                         const std::function<void(const std::string&)>& bad) {
  const auto get = [&](int bits) {
    std::uint64_t v = 0;
    if (!in.get(bits, v)) bad("outlines end early at bit " + std::to_string(in.bit_position()));
    return v;
  };
  std::vector<std::string> paths;
  if (get(1) == 0) return paths;
  for (std::size_t s = 0; s < stroke_count; ++s) {
    const std::string where = "stroke " + std::to_string(s + 1) + ": outline ";
    std::string path;
    if (get(1) == 1) {
      const std::size_t length = get(kOutlineTextLengthBits);
      if (length > in.remaining() / 8) bad(where + "text longer than the record");
      if (keep) path.reserve(length);
      for (std::size_t i = 0; i < length; ++i) {
        const char c = static_cast<char>(get(8));
        if (keep) path.push_back(c);
      }
      if (keep) paths.push_back(std::move(path));
      continue;
    }
    std::size_t count = get(kOutlineCountBits);
    if (count == kOutlineCountEscape) {
      count = get(kOutlineCountExtensionBits);
      if (count < kOutlineCountEscape) bad(where + "command count not minimal");
    }
    if (count == 0) bad(where + "without a command");
    std::vector<char> commands(count);
    std::size_t points = 0;
    for (std::size_t i = 0; i < count; ++i) {
      const std::uint64_t code = get(kOutlineCommandBits);
      if (code >= std::size(kOutlineCommands))
        bad(where + "command code " + std::to_string(code) + " unknown");
      commands[i] = kOutlineCommands[code];
      if ((i == 0) != (commands[i] == 'M')) bad(where + "does not begin with its one M");
      points += static_cast<std::size_t>(outline_command_points(commands[i]));
    }
    std::int64_t x = 0;
    std::int64_t y = 0;
    const auto check = [&] {
      if (std::abs(x) > kMaxOutlineCoordinate || std::abs(y) > kMaxOutlineCoordinate)
        bad(where + "point out of range");
    };
    const int start_width = static_cast<int>(get(5));
    x = unzigzag(get(start_width));
    y = unzigzag(get(start_width));
    check();
    int width_x = 0;
    int width_y = 0;
    if (points > 1) {
      width_x = static_cast<int>(get(5));
      width_y = static_cast<int>(get(5));
    }
    std::size_t point = 0;
    for (const char command : commands) {
      if (keep) {
        if (!path.empty()) path.push_back(' ');
        path.push_back(command);
      }
      for (int i = 0; i < outline_command_points(command); ++i, ++point) {
        if (point > 0) {
          x += unzigzag(get(width_x));
          y += unzigzag(get(width_y));
          check();
        }
        if (keep) {
          path.push_back(' ');
          path.append(std::to_string(x));
          path.push_back(' ');
          path.append(std::to_string(y));
        }
      }
    }
    if (keep) paths.push_back(std::move(path));
  }
  return paths;
}

}  // namespace calligraphy::store
