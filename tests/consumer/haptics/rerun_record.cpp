// A haptic application reads a trial record and runs it again with the installed haptics component alone
// (trial/recorded_trial.hpp): the record written by `calligraphy trial --json` is read by the library's one
// reader, its characters laid out from the installed library are the recorded ones (their SHA-256), and the
// record runs again on the simulated device with its force law, safety chain and passivity controller. The
// simulated writer (calligraphy::research's sim) wrote it, and this program does not link it: without a
// hand maker the re-run is refused naming sim's `recorded_writing`; with a hand of the application's own,
// two runs give the same trace bit for bit, and the trial that runs is the recorded one: its record, made
// again from what ran, is the same text. A record whose force law and safety chain differ from what its
// specification alone makes (written and read back) runs with them: what ran is that record, and the
// forces differ.
// Usage: rerun_record RECORD.json
#include <bit>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "calligraphy/core/checked.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/devices/device_registry.hpp"
#include "calligraphy/devices/hand_port.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/trial/hand.hpp"
#include "calligraphy/trial/recorded_trial.hpp"
#include "calligraphy/trial/trial_spec_runner.hpp"

namespace {

using namespace calligraphy;

// The application's own hand: a spring [N/m] that holds the stylus at a point on the paper, for a fixed
// number of ticks, then finishes. Deterministic: no clock, no random draw.
class SpringHand final : public TrialHand, public HandModel {
 public:
  SpringHand(HandPort& port, Vec3 target_m) : port_(port), target_m_(std::move(target_m)) {
    port_.attach_hand(this);
  }
  Vec3 hand_force(double /*time_s*/, const Vec3& position_m, const Vec3& velocity_m_s) override {
    return 200.0 * (target_m_ - position_m) - 5.0 * velocity_m_s;
  }
  void observe(const RenderOutput& /*output*/, const DeviceState& /*pen*/) override { ++ticks_; }
  [[nodiscard]] bool stopped() const noexcept override { return finished(); }
  [[nodiscard]] bool finished() const noexcept override { return ticks_ >= kTicks; }
  void advance(double dt_s) override { port_.advance(dt_s); }
  void release() noexcept override { port_.attach_hand(nullptr); }

 private:
  static constexpr int kTicks = 3000;
  HandPort& port_;
  Vec3 target_m_;
  int ticks_ = 0;
};

class SpringHandMaker final : public TrialHandMaker {
 public:
  std::unique_ptr<TrialHand> make_hand(HapticDevice& device, const Scene& scene, std::uint64_t) override {
    // The first point of the first stroke's median, 1 mm into the paper (z < 0: pen down).
    const Vec2 start = scene.characters.front().strokes.front().centre_line.points_m.front();
    return std::make_unique<SpringHand>(*device.hand_port(), Vec3(start.x(), start.y(), -0.001));
  }
  void after_trial(TrialResult&) override {}
};

bool same_trace(const TrialResult& a, const TrialResult& b) {
  if (a.trace.size() != b.trace.size()) return false;
  for (std::size_t i = 0; i < a.trace.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      if (std::bit_cast<std::uint64_t>(a.trace[i].position_m[k]) !=
              std::bit_cast<std::uint64_t>(b.trace[i].position_m[k]) ||
          std::bit_cast<std::uint64_t>(a.trace[i].force_n[k]) !=
              std::bit_cast<std::uint64_t>(b.trace[i].force_n[k]))
        return false;
    }
    if (std::bit_cast<std::uint64_t>(a.trace[i].time_s) != std::bit_cast<std::uint64_t>(b.trace[i].time_s))
      return false;
  }
  return true;
}

int fail(const std::string& what) {
  std::fprintf(stderr, "rerun_record: %s\n", what.c_str());
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) return fail("usage: rerun_record RECORD.json");
  try {
    const RecordedTrial recorded = read_recorded_trial_file(argv[1]);
    if (!recorded.writer)
      return fail("expected a record the simulated writer wrote (calligraphy trial --json)");

    std::vector<Character> characters;
    for (char32_t c : decode_utf8(recorded.spec.characters))
      characters.push_back(CharacterLibrary::standard().load(c));
    const Scene scene = Scene::lay_out(characters, recorded.layout);
    if (!scene_is_recorded_one(scene, recorded.scene_sha256))
      return fail("the characters laid out here are not the recorded ones");
    const Checked<TrialSpec> spec = Checked<TrialSpec>::check(recorded.spec);
    const DeviceRegistry registry = standard_device_registry();

    // Without a hand maker, the record the simulated writer wrote is refused, naming what to give.
    TrialRunInputs bare;
    bare.registry = &registry;
    try {
      (void)rerun_trial(recorded, spec, scene, bare);
      return fail("a re-run without a hand maker was not refused");
    } catch (const InvalidArgument& e) {
      if (std::string(e.what()).find("recorded_writing") == std::string::npos)
        return fail(std::string("the refusal does not name recorded_writing: ") + e.what());
    }

    const auto rerun = [&](const RecordedTrial& record) {
      SpringHandMaker maker;
      TrialRunInputs inputs;
      inputs.registry = &registry;
      inputs.hand_maker = &maker;
      return rerun_trial(record, Checked<TrialSpec>::check(record.spec), scene, inputs);
    };
    const std::vector<TrialRun> runs{rerun(recorded), rerun(recorded)};
    const TrialRun& run = runs.front();
    if (!run.simulated_writer || run.result.end != TrialEnd::writer_finished ||
        run.result.trace.size() < 1000)
      return fail(std::string("the re-run did not run the application's hand to its end: ") +
                  to_string(run.result.end));
    if (!same_trace(runs[0].result, runs[1].result)) return fail("two re-runs gave different traces");

    // What ran, recorded again: the record's text, every double to the bit.
    const auto ran_record = [&](const RecordedTrial& record, const TrialRun& ran) {
      return recorded_trial_json(recorded_trial(record.spec, ran.options, &*record.writer, scene));
    };
    if (ran_record(recorded, run) != recorded_trial_json(recorded)) {
      return fail("the trial that ran is not the recorded one:\n" + ran_record(recorded, run) +
                  "\nagainst the record's\n" + recorded_trial_json(recorded));
    }

    // A record with a softer paper, more friction and a tighter force slew than its specification makes,
    // written and read back: it runs with them, and the forces differ.
    RecordedTrial altered = recorded;
    altered.force_law.paper_stiffness_n_per_m *= 0.75;
    altered.force_law.friction_coefficient = 0.21;
    altered.safety.max_force_change_n_per_tick = 0.125;
    altered = read_recorded_trial(recorded_trial_json(altered), "altered record");
    const TrialRun altered_run = rerun(altered);
    if (ran_record(altered, altered_run) != recorded_trial_json(altered))
      return fail("the altered record's force law or safety chain is not what ran");
    if (same_trace(altered_run.result, run.result)) return fail("the altered record gave the same trace");
    std::printf(
        "rerun_record: %s re-run on \"%s\" (%zu ticks, twice the same); what ran is the record, and an "
        "altered record runs as altered\n",
        argv[1], recorded.spec.device.c_str(), run.result.trace.size());
    return 0;
  } catch (const std::exception& e) {
    return fail(e.what());
  }
}
