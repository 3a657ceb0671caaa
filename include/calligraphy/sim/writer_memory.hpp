#pragma once
/// \file writer_memory.hpp
/// A simulated writer's motor memory across trials and sessions, a model (docs/writer.md, "Memory"): per
/// typical stroke (paper section 3.1) a skill of shape and direction and a skill of timing (speed and
/// pauses), per character a skill of its stroke order, each the sum of a fast and a slow state updated after
/// every trial by the two-state model of Smith, Ghazizadeh & Shadmehr (2006, PLoS Biol 4(6):e179):
///
///     x_f <- A_f x_f + B_f e,   x_s <- A_s x_s + B_s e,   x = clamp(x_f + x_s, 0, 1),
///
/// with the error the writer itself experiences e = (1 - x)(1 - h): guidance that does a share h of the
/// correction removes that share of the error the writer learns from (error-based learning with robotic
/// assistance, Emken, Benitez, Sideris, Bobrow & Reinkensmeyer 2007, J Neurophysiol 97:3997). h comes from
/// the physics of the two springs acting on the pen, g K / (g K + k) for the fixture's g K against the hand's
/// k, and it is counted apart across the stroke (shape, order, direction) and along it (timing): a fixture
/// pulls towards the nearest point and so takes no timing, a moving target pulls along and takes no shape
/// (study/guidance_share.hpp). Practice of a character trains the typical strokes it holds, so a character
/// not practised starts from what its typical strokes learned elsewhere (transfer). Between sessions (hours
/// or days) the fast state is gone and the slow one kept: long-term retention follows the slow state (Joiner
/// & Smith 2008, J Neurophysiol 100:2948). The skills move a profile from the writer's own towards the
/// skilled writer's. Deterministic: the same trials give the same memory, so a resumed session rebuilds it
/// from its records.
#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "calligraphy/core/parameter_table.hpp"
#include "calligraphy/core/schema.hpp"
#include "calligraphy/trial/writer_profile.hpp"

namespace calligraphy {

/// How a simulated writer learns from trial to trial: not at all (each trial written from its profile) or by
/// the two-state memory of this header. One spelling everywhere (EnumTable): the CLI's `--writer-learning`,
/// session.json, the study tables and Python.
enum class WriterLearning : std::uint8_t { none, two_state };

template <>
struct EnumTable<WriterLearning> {
  static constexpr std::string_view name = "WriterLearning";
  static constexpr std::array<EnumEntry<WriterLearning>, 2> entries{{
      {WriterLearning::none, "none", "each trial written from the subject's profile"},
      {WriterLearning::two_state, "two-state",
       "a memory per typical stroke and character, rebuilt from the saved trials"},
  }};
};

/// The retention factors A and learning rates B of the two-state model, per trial. Defaults: the values
/// Smith, Ghazizadeh & Shadmehr (2006) simulate force-field adaptation with. Ranges:
/// `ParameterTable<TwoStateRates>`, the one definition.
struct TwoStateRates {
  double fast_retention = 0.92;   ///< A_f, in [0, 1)
  double fast_learning = 0.03;    ///< B_f, in (0, 1]
  double slow_retention = 0.996;  ///< A_s, in [0, 1), > A_f
  double slow_learning = 0.004;   ///< B_s, in (0, 1], < B_f
  /// Throws InvalidArgument naming the field when a value is out of its table range, or the slow state
  /// retains no more than the fast one (A_s <= A_f) or learns no slower (B_s >= B_f).
  void validate() const;
};

template <>
struct ParameterTable<TwoStateRates> {
  static constexpr std::string_view name = "TwoStateRates";
  [[nodiscard]] static std::span<const ParameterField<TwoStateRates>> fields() noexcept;
};
/// The table's schema (schema.hpp), its rules `validate`'s.
template <>
struct SchemaOf<TwoStateRates> {
  static const Schema& get();
};

/// One skill: a fast and a slow state; the skill is their sum, in [0, 1].
struct SkillMemory {
  double fast = 0.0;
  double slow = 0.0;
  [[nodiscard]] double skill() const noexcept;
};

/// A writer's memory: skills by typical stroke ID (1-39) and by character.
struct WriterMemory {
  std::map<int, SkillMemory> typical_strokes;  ///< shape and direction of each typical stroke written
  std::map<int, SkillMemory> stroke_timing;    ///< timing (speed, pauses) of each typical stroke written
  std::map<char32_t, SkillMemory> characters;  ///< stroke order of each character written
};

/// The shares h of a trial's correction its guidance took (study/guidance_share.hpp): across the stroke,
/// which the shape and order skills learn with, and along it, which the timing skill learns with. Each in
/// [kMinAssistanceShare, 1]: negative for an error a repulsive field enlarged.
struct AssistanceShares {
  double shape = 0.0;
  double timing = 0.0;
  /// The share of the timing a guide demonstrated by moving the pen along the stroke in time (a replay's
  /// teacher, a timing guide's moving target), in [0, 1]: the writer feels the time course done and learns
  /// it as an error it perceives (use-dependent learning from guided movement, Diedrichsen et al. 2010).
  double timing_demonstration = 0.0;
};

/// The share of its timing error a writer perceives without a demonstration: the display's reference has no
/// time course, so vision shows its own pace and pauses but not the target's (assumed 0.5, the share of the
/// feedback the trace alone gives in writer_learning.hpp; docs/writer.md, "What a demonstration teaches").
inline constexpr double kSeenTimingShare = 0.5;

/// A writer's skills for one trial, each in [0, 1]: the mean over its strokes' typical strokes (shape,
/// timing) and over its characters (order).
struct WriterSkills {
  double shape = 0.0;
  double order = 0.0;
  double timing = 0.0;
};

/// The share of the correction a guiding spring of stiffness `gain` x `guidance_stiffness_n_per_m` takes
/// from a hand of stiffness `hand_stiffness_n_per_m`: g K / (g K + k), in [0, 1). Throws InvalidArgument for
/// a gain outside [0, 1] or a stiffness that is negative or (for the hand) not > 0.
[[nodiscard]] double guidance_assistance_share(double gain, double guidance_stiffness_n_per_m,
                                               double hand_stiffness_n_per_m);

/// The lowest assistance share `practise` takes: -9, an error enlarged tenfold (a guard on the fast state's
/// step B_f e; error amplification with the default field enlarges it at most threefold, guidance_share.hpp).
inline constexpr double kMinAssistanceShare = -9.0;

/// One trial of practice: every memory decays by its retention (A_f, A_s); then each typical stroke of
/// `typical_ids` (one per stroke of the trial's characters; a stroke type written twice learns twice) and
/// each character of `characters` learns from the error e = (1 - x)(1 - h), h the shape share for shape and
/// order; timing from e = (1 - x)(kSeenTimingShare (1 - h) + d), h the timing share and d the timing
/// demonstration (in [0, 1]): a share in (0, 1] is the correction guidance took, a negative
/// share an error a repulsive field enlarged by the factor 1 - share (error augmentation: Emken &
/// Reinkensmeyer 2005, IEEE TNSRE 13:33). Throws InvalidArgument for a share outside [kMinAssistanceShare, 1]
/// or bad rates.
void practise(WriterMemory& memory, const std::vector<int>& typical_ids, const std::u32string& characters,
              const AssistanceShares& shares, const TwoStateRates& rates = {});

/// The passing of hours or days between sessions: every fast state is set to 0, slow states are kept.
void consolidate(WriterMemory& memory);

/// The shape skill of a trial: the mean skill of its typical strokes (0 for a stroke type never written).
[[nodiscard]] double shape_skill(const WriterMemory& memory, const std::vector<int>& typical_ids);
/// The timing skill of a trial: the mean timing skill of its typical strokes (0 for one never written).
[[nodiscard]] double timing_skill(const WriterMemory& memory, const std::vector<int>& typical_ids);
/// The order skill of a trial: the mean skill of its characters.
[[nodiscard]] double order_skill(const WriterMemory& memory, const std::u32string& characters);
/// All three for a trial of `characters` with strokes `typical_ids`.
[[nodiscard]] WriterSkills writer_skills(const WriterMemory& memory, const std::vector<int>& typical_ids,
                                         const std::u32string& characters);

/// The profile a writer starting from `own` writes with at `skills`, each field moving linearly from `own`'s
/// to `skilled`'s: by the shape skill its bias (offset, scale error, jitter), corner cutting and spatial
/// errors (lifts in a stroke, touches outside); by the timing skill its writing speed and hesitations; by the
/// order skill its order and backwards error rates. Throws InvalidArgument for a skill outside [0, 1] and
/// what `validate` throws.
[[nodiscard]] WriterProfile learned_profile(const WriterProfile& own, const WriterProfile& skilled,
                                            const WriterSkills& skills);

/// The numeric fields `learned_profile` changes, by name (`set_writer_parameter` keys), in order.
[[nodiscard]] const std::vector<std::string>& learned_profile_fields();

}  // namespace calligraphy
