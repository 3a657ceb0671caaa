// Checked<T> (calligraphy/core/checked.hpp): only a value that passed its validate() is held, a derived
// value carries the check of its source, and a part the check of its whole.
#include "calligraphy/core/checked.hpp"

#include <catch2/catch.hpp>
#include <stdexcept>
#include <type_traits>

using calligraphy::Checked;

namespace {

struct Band {
  double low = 0.0;
  double high = 1.0;
  void validate() const {
    if (!(low <= high)) throw std::invalid_argument("Band: low > high");
  }
};

struct Pair {
  Band band;
  int count = 1;
  void validate(int most = 10) const {
    band.validate();
    if (count < 1 || count > most) throw std::invalid_argument("Pair: count");
  }
};

int validations = 0;
struct Counted {
  void validate() const { ++validations; }
};

}  // namespace

TEST_CASE("a Checked value is made only by its check, which refuses what validate refuses", "[checked]") {
  static_assert(!std::is_constructible_v<Checked<Band>, Band>);
  static_assert(!std::is_default_constructible_v<Checked<Band>>);
  CHECK_THROWS_WITH(Checked<Band>::check(Band{2.0, 1.0}), "Band: low > high");
  const auto band = Checked<Band>::check(Band{0.25, 0.5});
  CHECK(band->low == 0.25);
  CHECK((*band).high == 0.5);
  // The check's context goes to validate.
  CHECK_THROWS_WITH(Checked<Pair>::check(Pair{{}, 11}), "Pair: count");
  CHECK_THROWS_WITH(Checked<Pair>::check(Pair{{}, 3}, 2), "Pair: count");
  CHECK(Checked<Pair>::check(Pair{{}, 3}, 5)->count == 3);
}

TEST_CASE("derived values and parts are not validated again in a build without assertions", "[checked]") {
  validations = 0;
  const auto counted = Checked<Counted>::check(Counted{});
  CHECK(validations == 1);
  const Checked<Counted> copy = counted;  // a copy is the same checked value
  (void)copy;
  const auto again = counted.derive([](const Counted& c) { return c; });
  (void)again;
#ifdef NDEBUG
  CHECK(validations == 1);
#else
  CHECK(validations == 2);  // assertions on: a derivation's result is verified
#endif
  const auto pair = Checked<Pair>::check(Pair{{0.0, 2.0}, 4});
  const Checked<Band> part = pair.part(&Pair::band);
  CHECK(part->high == 2.0);
  const auto widened = part.derive([](Band b) {
    b.high += 1.0;  // keeps low <= high: valid by construction
    return b;
  });
  CHECK(widened->high == 3.0);
}
