#pragma once
/// \file simulated_writer.hpp
/// A simulated writer for tests and experiments, closed-loop (docs/writer.md has the model, every
/// constant and its source):
///  - Hand: an impedance F = k (x_d - x) + b (x_d' - x') + noise + tremor (the noise grows with the
///    force, Harris & Wolpert 1998) holds the stylus; x_d moves in minimum-jerk segments (Flash & Hogan
///    1985) along the writer's own, biased copy (offset, mis-scale, per-attempt jitter) of what a person
///    sees of each stroke: its median, cut into legs at its corners, each corner cut inside; the pen is
///    lifted short of or past the end the display shows (a cited end scatter), with no follow-through.
///  - Vision: the writer sees its pen and the display a visuomotor delay late (120 ms; Miall, Weir,
///    Wolpert & Stein 1993; Saunders & Knill 2005: corrections across the path within 117 ms),
///    corrects x_d towards the reference stroke when the seen error exceeds its tolerance, and paces
///    itself by the seen error with the steering law's local form v = (W - 2|e|) / tau (Accot & Zhai
///    1997): a pen that guidance holds on the stroke is written faster.
///  - Errors (per profile): strokes out of order, backwards, a lift in the middle of a stroke, a touch
///    outside the character's box, hesitations.
///  - Responses: a resistance it feels against its intended motion for a reaction time (the renderer's
///    resistance of Fig. 4 and its off-stroke resistance under guidance) makes it break the attempt off
///    and write the stroke the display hints, forwards, with less bias, and from then on follow the
///    hint; seeing its stroke cleared after a lift in the middle, or a stroke it wrote in turn not taken by
///    the display, makes it write the stroke again.
///    Without guidance nothing refuses a stroke out of order, and the writer keeps to its own order.
/// All randomness is seeded: the plan (which strokes go out of order or backwards) is drawn at
/// construction, the other errors at the start of each attempt, the hand's noise from a stream of its
/// own; the same seed, profile, scene and servo rate give the same trial.
#include <cstdint>
#include <memory>
#include <vector>

#include "calligraphy/devices/hand_port.hpp"
#include "calligraphy/devices/simulated_device.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/render/renderer.hpp"
#include "calligraphy/sim/writer_log.hpp"
#include "calligraphy/trial/writer_profile.hpp"

namespace calligraphy {

/// A stroke in the order the writer means to write them.
struct PlannedStroke {
  std::size_t character = 0;     ///< character index in the scene
  std::size_t stroke = 0;        ///< stroke index within the character
  std::size_t scene_stroke = 0;  ///< stroke index over the scene
  bool reversed = false;         ///< the writer means to write it from its end
};

class SimulatedWriter final : public HandModel {
 public:
  /// `scene` must outlive the writer. Throws InvalidArgument for a bad profile.
  SimulatedWriter(const Scene& scene, const WriterProfile& profile, std::uint64_t seed);
  ~SimulatedWriter() override;
  SimulatedWriter(SimulatedWriter&&) noexcept;
  SimulatedWriter& operator=(SimulatedWriter&&) noexcept;
  SimulatedWriter(const SimulatedWriter&) = delete;
  SimulatedWriter& operator=(const SimulatedWriter&) = delete;

  /// The hand's force on the stylus [N] at `time_s` [s], between the last `observe` and the next.
  Vec3 hand_force(double time_s, const Vec3& position_m, const Vec3& velocity_m_s) override;
  /// Feedback after each servo tick: what the display shows (active stroke, state, a stroke cleared)
  /// and the force the hand feels (`output.force_n`), and where the pen is (the device state). Times
  /// must not decrease.
  void observe(const RenderOutput& output, const DeviceState& pen);
  /// True when the writer has finished (its plan written, or the display finished) or given up.
  [[nodiscard]] bool done() const noexcept;
  /// The hand's target x_d at `time_s` [m]: the motor command issued at the last `observe` (the plan's
  /// point and velocity then), held to first order until the next (for tests).
  [[nodiscard]] Vec3 target(double time_s) const;

  /// What the writer did so far.
  [[nodiscard]] const WriterLog& log() const noexcept;
  /// The order and directions in which the writer means to write, drawn from the profile at
  /// construction (the reference order when the profile makes no order or direction errors).
  [[nodiscard]] const std::vector<PlannedStroke>& plan() const noexcept;
  [[nodiscard]] const WriterProfile& profile() const noexcept;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace calligraphy
