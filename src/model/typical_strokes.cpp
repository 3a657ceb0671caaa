// The table of the 39 typical strokes. IDs are part of the data format: never renumber.
// Sources: GF 2001-2001 (25 turning strokes), the 6 flat strokes, Unicode CJK Strokes block,
// REFERENCE.md section 3. Directions are degrees in the y-up data frame.
#include "calligraphy/typical_strokes.hpp"

#include <array>
#include <string>

#include "calligraphy/errors.hpp"

namespace calligraphy {
namespace {

using P = StrokePieceTemplate;
constexpr double E = 0, S = -90, SW = -135, SE = -45, NE = 40, N = 90, NW = 135, W = 180, ESE = -20, WSW = -160;

// Element templates, corner to corner (one entry per piece).
constexpr P kH[] = {{E, E, false}};
constexpr P kS[] = {{S, S, false}};
constexpr P kP[] = {{-120, -140, false}};
constexpr P kD[] = {{SE, SE, true}};
constexpr P kN[] = {{-55, ESE, false}};
constexpr P kT[] = {{NE, NE, false}};
constexpr P kHZ[] = {{E, E, false}, {S, S, false}};
constexpr P kHP[] = {{E, E, false}, {SW, SW, false}};
constexpr P kHG[] = {{E, E, false}, {SW, SW, true}};
constexpr P kHZG[] = {{E, E, false}, {S, S, false}, {NW, NW, true}};
constexpr P kHZT[] = {{E, E, false}, {S, S, false}, {NE, NE, true}};
constexpr P kHZW[] = {{E, E, false}, {S, E, false}};
constexpr P kHZZ[] = {{E, E, false}, {S, S, true}, {E, E, false}};
constexpr P kHXG[] = {{E, E, false}, {SE, S, false}, {N, N, true}};
constexpr P kHZWG[] = {{E, E, false}, {S, E, false}, {N, N, true}};
constexpr P kHPWG[] = {{E, E, false}, {SW, SW, true}, {SE, S, false}, {NW, NW, true}};
constexpr P kHZZP[] = {{E, E, false}, {SW, SW, true}, {E, E, false}, {SW, SW, false}};
constexpr P kHZZZG[] = {{E, E, false}, {SW, SW, true}, {E, E, false}, {S, SW, false}, {NW, NW, true}};
constexpr P kHZZZ[] = {{E, E, false}, {S, S, false}, {E, E, false}, {S, S, false}};
constexpr P kST[] = {{S, S, false}, {NE, NE, true}};
constexpr P kSZ[] = {{S, S, false}, {E, E, false}};
constexpr P kSG[] = {{S, S, false}, {NW, NW, true}};
constexpr P kSW[] = {{S, E, false}};
constexpr P kSWG[] = {{S, E, false}, {N, N, true}};
constexpr P kSZP[] = {{S, S, false}, {E, E, false}, {SW, SW, false}};
constexpr P kSZZ[] = {{S, S, false}, {E, E, false}, {S, S, false}};
constexpr P kSZWG[] = {{S, S, false}, {E, E, false}, {S, SW, false}, {NW, NW, true}};
constexpr P kPD[] = {{SW, SW, false}, {SE, SE, false}};
constexpr P kPZ[] = {{SW, SW, false}, {NE, E, false}};
constexpr P kXG[] = {{SE, -70, false}, {N, N, true}};
constexpr P kWG[] = {{S, -100, false}, {NW, NW, true}};
constexpr P kSP[] = {{S, SW, false}};
constexpr P kD2[] = {{-60, -60, true}};
constexpr P kCD[] = {{SE, SE, false}};
constexpr P kBXG[] = {{SE, E, false}, {NW, NW, true}};
constexpr P kPP[] = {{WSW, WSW, false}};
constexpr P kTN[] = {{E, ESE, false}};
constexpr P kPG[] = {{SW, SW, false}, {NW, NW, true}};
constexpr P kSWZ[] = {{S, W, false}};

constexpr std::array<TypicalStroke, 39> kTable = {{
    {1, "H", "横", "héng", U'\u31D0', false, kH, 1.0},
    {2, "S", "竖", "shù", U'\u31D1', false, kS, 1.0},
    {3, "P", "撇", "piě", U'\u31D2', false, kP, 1.0},
    {4, "D", "点", "diǎn", U'\u31D4', false, kD, 1.0},
    {5, "N", "捺", "nà", U'\u31CF', false, kN, 1.0},
    {6, "T", "提", "tí", U'\u31C0', false, kT, 1.0},
    {7, "HZ", "横折", "héng zhé", U'\u31D5', true, kHZ, 1.0},
    {8, "HP", "横撇", "héng piě", U'\u31C7', true, kHP, 1.0},
    {9, "HG", "横钩", "héng gōu", U'\u31D6', true, kHG, 1.0},
    {10, "HZG", "横折钩", "héng zhé gōu", U'\u31C6', true, kHZG, 1.0},
    {11, "HZT", "横折提", "héng zhé tí", U'\u31CA', true, kHZT, 1.0},
    {12, "HZW", "横折弯", "héng zhé wān", U'\u31CD', true, kHZW, 1.0},
    {13, "HZZ", "横折折", "héng zhé zhé", U'\u31C5', true, kHZZ, 1.0},
    {14, "HXG", "横斜钩", "héng xié gōu", U'\u31E4', true, kHXG, 1.0},
    {15, "HZWG", "横折弯钩", "héng zhé wān gōu", U'\u31C8', true, kHZWG, 1.0},
    {16, "HPWG", "横撇弯钩", "héng piě wān gōu", U'\u31CC', true, kHPWG, 1.0},
    {17, "HZZP", "横折折撇", "héng zhé zhé piě", U'\u31CB', true, kHZZP, 1.0},
    {18, "HZZZG", "横折折折钩", "héng zhé zhé zhé gōu", U'\u31E1', true, kHZZZG, 1.0},
    {19, "HZZZ", "横折折折", "héng zhé zhé zhé", U'\u31CE', true, kHZZZ, 1.0},
    {20, "ST", "竖提", "shù tí", U'\u31D9', true, kST, 1.0},
    {21, "SZ", "竖折", "shù zhé", U'\u31D7', true, kSZ, 1.0},
    {22, "SG", "竖钩", "shù gōu", U'\u31DA', true, kSG, 1.0},
    {23, "SW", "竖弯", "shù wān", U'\u31C4', true, kSW, 1.0},
    {24, "SWG", "竖弯钩", "shù wān gōu", U'\u31DF', true, kSWG, 1.0},
    {25, "SZP", "竖折撇", "shù zhé piě", U'\u31E5', true, kSZP, 1.0},
    {26, "SZZ", "竖折折", "shù zhé zhé", U'\u31DE', true, kSZZ, 1.0},
    {27, "SZWG", "竖折折钩", "shù zhé zhé gōu", U'\u31C9', true, kSZWG, 1.0},
    {28, "PD", "撇点", "piě diǎn", U'\u31DB', true, kPD, 1.0},
    {29, "PZ", "撇折", "piě zhé", U'\u31DC', true, kPZ, 1.0},
    {30, "XG", "斜钩", "xié gōu", U'\u31C2', true, kXG, 1.0},
    {31, "WG", "弯钩", "wān gōu", U'\u31C1', true, kWG, 1.0},
    {32, "SP", "竖撇", "shù piě", U'\u31D3', false, kSP, 1.0},
    {33, "D2", "左点", "zuǒ diǎn", 0, false, kD2, 1.0},
    {34, "CD", "长点", "cháng diǎn", 0, false, kCD, 1.0},
    {35, "BXG", "卧钩", "wò gōu", U'\u31C3', true, kBXG, 1.0},
    {36, "PP", "平撇", "píng piě", 0, false, kPP, 1.0},
    {37, "TN", "提捺", "tí nà", U'\u31DD', false, kTN, 1.0},
    {38, "PG", "撇钩", "piě gōu", U'\u31E2', true, kPG, 1.0},
    {39, "SWZ", "竖弯左", "shù wān zuǒ", U'\u31D8', false, kSWZ, 1.0},
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

}  // namespace calligraphy
