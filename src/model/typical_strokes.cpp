// The table of the 39 typical strokes. IDs are part of the data format: never renumber.
// Sources: GF 2001-2001 (25 turning strokes), the 6 flat strokes, 8 common variants, and the Unicode
// CJK Strokes block (U+31C0-U+31E5, Unicode 16) for acronyms and code points. Directions are degrees
// in the y-up data frame.
#include "calligraphy/model/typical_strokes.hpp"

#include <array>
#include <cctype>
#include <cmath>
#include <limits>
#include <string>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/unicode.hpp"

namespace calligraphy {
namespace {

using P = StrokePieceTemplate;

constexpr P piece(double start, double end, double start_tol, double end_tol, bool hook = false,
                  double min_length = 0.0, double max_length = std::numeric_limits<double>::infinity()) {
  return piece_template(start, end, start_tol, end_tol, hook, min_length, max_length);
}
constexpr P piece(double start, double end, double tol = 20.0) { return piece(start, end, tol, tol); }
constexpr P hook_piece(double direction, double tol = 25.0) {
  return piece(direction, direction, tol, tol, true);
}

// Nominal directions of Kai-style medians (measured over hanzi-writer-data, docs/classification.md):
// horizontals rise about 10 degrees, verticals lean to about -95.
constexpr double E = 10, S = -95;
constexpr P kHookLeft = hook_piece(150);  // 钩 after a vertical: up and to the left

// Element templates, corner to corner (one entry per piece). Tolerances are one standard deviation.
constexpr P kH[] = {piece(E, E, 15)};
constexpr P kS[] = {piece(-85, -95, 20, 10)};
constexpr P kP[] = {piece(-125, -140, 25, 12)};
constexpr P kD[] = {piece(-38, -50, 12, 18, false, 0, 250)};
constexpr P kN[] = {piece(-55, -20, 25, 15, false, 280)};
constexpr P kT[] = {piece(35, 35, 25)};
constexpr P kHZ[] = {piece(E, E), piece(-105, -105, 12, 15)};
constexpr P kHP[] = {piece(E, E), piece(-125, -140, 15, 20, false, 300)};
constexpr P kHG[] = {piece(E, E), piece(-130, -133, 8, 15, false, 0, 250)};
constexpr P kHZG[] = {piece(E, E), piece(S, S),
                      piece(150, 150, 25, 25, true, 80)};  // hook ≥ 80: shorter is a tick
constexpr P kHZT[] = {piece(E, E), piece(S, S), hook_piece(45)};
constexpr P kHZW[] = {piece(E, E), piece(S, 0, 25)};
constexpr P kHZZ[] = {piece(E, E), piece(S, S, 20, 20, true), piece(E, E)};
constexpr P kHXG[] = {piece(E, E), piece(-60, -30, 25), hook_piece(90)};
constexpr P kHZWG[] = {piece(E, E), piece(S, -10, 30), hook_piece(90)};
constexpr P kHPWG[] = {piece(E, E), piece(-120, -120, 20, 20, true), piece(-45, -90, 25), hook_piece(160)};
constexpr P kHZZP[] = {piece(E, E), piece(-110, -110, 20, 20, true), piece(E, E, 20, 20, true),
                       piece(-120, -130, 25)};
constexpr P kHZZZG[] = {piece(E, E), piece(-120, -120, 20, 20, true), piece(E, E, 20, 20, true),
                        piece(-105, -120, 25), kHookLeft};
constexpr P kHZZZ[] = {piece(E, E), piece(S, S), piece(E, E), piece(S, S)};
constexpr P kST[] = {piece(S, S), piece(30, 30, 12, 12, true)};
constexpr P kSZ[] = {piece(S, S), piece(E, E, 10)};
constexpr P kSG[] = {piece(-85, -95, 20, 10), hook_piece(155)};
constexpr P kSW[] = {piece(S, 0, 25)};
constexpr P kSWG[] = {piece(S, 0, 25), hook_piece(90)};
constexpr P kSZP[] = {piece(S, S), piece(E, E), piece(-120, -120)};
constexpr P kSZZ[] = {piece(S, S), piece(E, E), piece(S, S)};
constexpr P kSZWG[] = {piece(S, S), piece(E, E), piece(-105, -105), kHookLeft};
constexpr P kPD[] = {piece(-100, -105), piece(-35, -45)};
constexpr P kPZ[] = {piece(-120, -120, 25), piece(15, 15)};
constexpr P kXG[] = {piece(-70, -50, 25), hook_piece(80)};
constexpr P kWG[] = {piece(-55, -100, 15, 25), hook_piece(155)};
constexpr P kSP[] = {piece(S, -125, 15, 12)};
constexpr P kD2[] = {piece(-105, -105, 8, 15, false, 0, 250)};
constexpr P kCD[] = {piece(-40, -45, 15, 15, false, 220)};
constexpr P kBXG[] = {piece(-45, 0, 25), hook_piece(115)};
constexpr P kPP[] = {piece(-165, -165, 20)};
constexpr P kTN[] = {piece(E, -15, 20, 20, false, 350)};
constexpr P kPG[] = {piece(-125, -125, 25), kHookLeft};
constexpr P kSWZ[] = {piece(S, 180, 25)};

constexpr std::array<TypicalStroke, 39> kTable = {{
    {1, "H", "横", "héng", U'\u31D0', false, kH, 1.0, 1.0},
    {2, "S", "竖", "shù", U'\u31D1', false, kS, 1.0, 1.0},
    {3, "P", "撇", "piě", U'\u31D2', false, kP, 1.0, 1.0},
    {4, "D", "点", "diǎn", U'\u31D4', false, kD, 1.0, 1.0},
    {5, "N", "捺", "nà", U'\u31CF', false, kN, 1.0, 1.0},
    {6, "T", "提", "tí", U'\u31C0', false, kT, 1.0, 1.0},
    {7, "HZ", "横折", "héng zhé", U'\u31D5', true, kHZ, 1.0, 1.5},
    {8, "HP", "横撇", "héng piě", U'\u31C7', true, kHP, 1.0, 1.5},
    {9, "HG", "横钩", "héng gōu", U'\u31D6', true, kHG, 1.0, 1.5},
    {10, "HZG", "横折钩", "héng zhé gōu", U'\u31C6', true, kHZG, 1.0, 1.5},
    {11, "HZT", "横折提", "héng zhé tí", U'\u31CA', true, kHZT, 1.0, 1.5},
    {12, "HZW", "横折弯", "héng zhé wān", U'\u31CD', true, kHZW, 1.0, 1.5},
    {13, "HZZ", "横折折", "héng zhé zhé", U'\u31C5', true, kHZZ, 1.0, 1.5},
    {14, "HXG", "横斜钩", "héng xié gōu", U'\u31E4', true, kHXG, 1.0, 1.5},
    {15, "HZWG", "横折弯钩", "héng zhé wān gōu", U'\u31C8', true, kHZWG, 1.0, 1.5},
    {16, "HPWG", "横撇弯钩", "héng piě wān gōu", U'\u31CC', true, kHPWG, 1.0, 1.5},
    {17, "HZZP", "横折折撇", "héng zhé zhé piě", U'\u31CB', true, kHZZP, 1.0, 1.5},
    {18, "HZZZG", "横折折折钩", "héng zhé zhé zhé gōu", U'\u31E1', true, kHZZZG, 1.0, 1.5},
    {19, "HZZZ", "横折折折", "héng zhé zhé zhé", U'\u31CE', true, kHZZZ, 1.0, 1.5},
    {20, "ST", "竖提", "shù tí", U'\u31D9', true, kST, 1.0, 1.5},
    {21, "SZ", "竖折", "shù zhé", U'\u31D7', true, kSZ, 1.0, 1.5},
    {22, "SG", "竖钩", "shù gōu", U'\u31DA', true, kSG, 1.0, 1.5},
    {23, "SW", "竖弯", "shù wān", U'\u31C4', true, kSW, 1.0, 1.5},
    {24, "SWG", "竖弯钩", "shù wān gōu", U'\u31DF', true, kSWG, 1.0, 1.5},
    {25, "SZP", "竖折撇", "shù zhé piě", U'\u31E5', true, kSZP, 1.0, 1.5},
    {26, "SZZ", "竖折折", "shù zhé zhé", U'\u31DE', true, kSZZ, 1.0, 1.5},
    {27, "SZWG", "竖折折钩", "shù zhé zhé gōu", U'\u31C9', true, kSZWG, 1.0, 1.5},
    {28, "PD", "撇点", "piě diǎn", U'\u31DB', true, kPD, 1.0, 1.5},
    {29, "PZ", "撇折", "piě zhé", U'\u31DC', true, kPZ, 1.0, 1.5},
    {30, "XG", "斜钩", "xié gōu", U'\u31C2', true, kXG, 1.0, 1.5},
    {31, "WG", "弯钩", "wān gōu", U'\u31C1', true, kWG, 1.0, 1.5},
    {32, "SP", "竖撇", "shù piě", U'\u31D3', false, kSP, 1.0, 1.0},
    {33, "D2", "左点", "zuǒ diǎn", 0, false, kD2, 1.0, 1.0},
    {34, "CD", "长点", "cháng diǎn", 0, false, kCD, 1.0, 1.0},
    {35, "BXG", "卧钩", "wò gōu", U'\u31C3', true, kBXG, 1.0, 1.5},
    {36, "PP", "平撇", "píng piě", 0, false, kPP, 1.0, 1.0},
    {37, "TN", "提捺", "tí nà", U'\u31DD', false, kTN, 1.0, 1.0},
    {38, "PG", "撇钩", "piě gōu", U'\u31E2', true, kPG, 1.0, 1.5},
    {39, "SWZ", "竖弯左", "shù wān zuǒ", U'\u31D8', true, kSWZ, 1.0, 1.5},
}};

}  // namespace

std::span<const TypicalStroke> typical_strokes() { return kTable; }

const TypicalStroke& typical_stroke(int id) {
  if (id < 1 || id > static_cast<int>(kTable.size())) {
    throw InvalidArgument("typical stroke ID " + std::to_string(id) + " is outside 1-39");
  }
  return kTable[static_cast<std::size_t>(id - 1)];
}

std::optional<int> typical_stroke_id(std::string_view acronym) {
  for (const auto& t : kTable) {
    if (t.acronym == acronym) return t.id;
  }
  return std::nullopt;
}

std::optional<int> typical_stroke_id_by_name(std::string_view name) {
  std::string upper(name);
  for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  for (const auto& t : kTable) {
    if (upper == t.acronym || name == t.name_zh || (t.unicode != 0 && name == encode_utf8(t.unicode)))
      return t.id;
  }
  return std::nullopt;
}

}  // namespace calligraphy
