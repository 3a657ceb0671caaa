#pragma once
/// \file checked.hpp
/// `Checked<T>`: a value of a parameter struct whose `validate()` passed, so that what it is handed to takes
/// it as it is instead of checking it again. A trial's values are checked once, where they are stated (a
/// command line's options, a JSON specification, a protocol), and travel in this type to the force: the
/// runner, the trial session and the renderer each take a `Checked` value and check nothing they are given
/// so (docs/architecture.md, "Checked once"). The unchecked overloads that applications call check once and
/// go on with the checked value.
#include <type_traits>
#include <utility>

namespace calligraphy {

/// A `T` that passed `T::validate`. Only three things make one:
/// - `check`, which runs `validate` (the one check);
/// - `derive`, a value made from a checked value by a function that cannot make an invalid one (the
///   function's precondition, stated where it is used; builds with assertions on verify it);
/// - `part`, a member of a checked value whose `validate` checks that member whole.
/// Immutable: a change is a new value, checked or derived again.
template <typename T>
class Checked {
 public:
  using value_type = T;

  /// `value` after `value.validate(context...)`; throws what that throws (InvalidArgument naming the field).
  template <typename... Context>
  [[nodiscard]] static Checked check(T value, const Context&... context) {
    value.validate(context...);
    return Checked(std::move(value));
  }

  /// The value `make(value())` returns, checked by construction: `make` must turn every valid `T` into a
  /// valid result (its own property, tested where it is defined). Builds without NDEBUG validate the
  /// result all the same, so that a derivation that breaks its promise fails in the sanitizer builds.
  template <typename Make>
  [[nodiscard]] auto derive(Make&& make) const
      -> Checked<std::remove_cvref_t<std::invoke_result_t<Make, const T&>>> {
    using Result = std::remove_cvref_t<std::invoke_result_t<Make, const T&>>;
    Result result = std::forward<Make>(make)(value_);
#ifndef NDEBUG
    result.validate();
#endif
    return Checked<Result>(std::move(result));
  }

  /// The member `member` of the value. Precondition: `T::validate` validates that member whole (calls its
  /// own `validate`), so that it holds a valid value.
  template <typename Member>
  [[nodiscard]] Checked<Member> part(Member T::*member) const {
    return Checked<Member>(value_.*member);
  }

  [[nodiscard]] const T& value() const noexcept { return value_; }
  [[nodiscard]] const T& operator*() const noexcept { return value_; }
  [[nodiscard]] const T* operator->() const noexcept { return &value_; }

 private:
  explicit Checked(T value) : value_(std::move(value)) {}
  template <typename>
  friend class Checked;

  T value_;
};

}  // namespace calligraphy
