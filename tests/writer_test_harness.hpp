#pragma once
// Lock-step trials with the writer in reach, for the writer and guidance tests: the loop of
// run_device_trial (device_trial.cpp) on a SimulatedDevice, keeping the writer's log and scoring the
// pen trace. Test helpers, not library API.
#include <cstdint>
#include <string>
#include <vector>

#include "calligraphy/analysis/score.hpp"
#include "calligraphy/devices/simulated_device.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/render/renderer.hpp"
#include "calligraphy/sim/simulated_writer.hpp"
#include "calligraphy/trial/trial.hpp"

namespace calligraphy::testing {

struct WriterTrial {
  TrialMetrics metrics;
  std::vector<TrialSample> trace;
  WriterLog log;
  std::vector<PlannedStroke> plan;
  bool writer_done = false;
};

struct WriterTrialOptions {
  ForceLawParameters force{};
  WriterProfile writer = WriterProfile::novice();
  std::uint64_t seed = 0;
  double rate_hz = 1000.0;
  double max_duration_s = 300.0;
  SafetyChainParameters safety{};
};

/// One character with one 横 from (200, 600) to (800, 600) in data units: 35 mm on the default 60 mm box.
inline Scene horizontal_stroke_scene() {
  Character c;
  c.code_point = U'一';
  Stroke h;
  h.typical_id = 1;
  h.elements = {StrokeElement::line({200, 600}, {800, 600})};
  h.attraction_factors = {1.0, 1.0};
  c.strokes = {h};
  return Scene::lay_out({c});
}

/// The device at `data` (data units of the scene's first character), `z` [m] high, at `time_s` [s], moving
/// in the paper plane at `velocity_m_s`.
inline DeviceState device_state_at(const Scene& scene, const Vec2& data, double z, double time_s = 0.0,
                                   const Vec2& velocity_m_s = Vec2::Zero()) {
  DeviceState s;
  const Vec2 p = scene.characters[0].placement.to_paper(data);
  s.position_m = Vec3(p.x(), p.y(), z);
  s.velocity_m_s = Vec3(velocity_m_s.x(), velocity_m_s.y(), 0.0);
  s.time_s = time_s;
  return s;
}

inline WriterTrial run_writer_trial(const Scene& scene, const WriterTrialOptions& options) {
  SimulatedDeviceParameters device_parameters;
  SimulatedDevice device(device_parameters);
  SimulatedWriter writer(scene, options.writer, options.seed);
  device.attach_hand(&writer);
  device.open();
  RendererOptions render;
  render.rate_hz = options.rate_hz;
  render.safety = options.safety;
  Renderer renderer(scene, options.force, device.info(), render);
  device.enable_forces(true);
  TrialRecorder recorder(scene, true);
  const double dt = 1.0 / options.rate_hz;
  const auto ticks = static_cast<long>(std::ceil(options.max_duration_s * options.rate_hz));
  double end_time = 0.0;
  for (long k = 0; k < ticks; ++k) {
    DeviceState state;
    if (device.read_state(state) != DeviceFault::none) break;  // an open simulated device never faults
    const RenderOutput out = renderer.tick(state);
    if (device.write_force(out.force_n) != DeviceFault::none) break;
    recorder.record(state, out);
    end_time = state.time_s;
    if (out.finished) break;
    writer.observe(out, state);
    if (writer.done()) break;
    device.advance(dt);
  }
  device.attach_hand(nullptr);
  device.close();
  recorder.finish(end_time);
  WriterTrial result;
  result.metrics = recorder.metrics();
  result.trace = recorder.trace();
  result.log = writer.log();
  result.plan = writer.plan();
  result.writer_done = writer.done();
  return result;
}

/// The trace as pen samples for score_trace: pen down when the tip is at or below the paper.
inline std::vector<PenSample> pen_samples(const Scene& scene, const std::vector<TrialSample>& trace) {
  std::vector<PenSample> pen;
  pen.reserve(trace.size());
  for (const TrialSample& s : trace) {
    pen.push_back(PenSample{s.time_s, s.position_m.head<2>(), s.position_m.z() <= scene.layout.paper_z_m});
  }
  return pen;
}

inline Scene scene_of(char32_t c) { return Scene::lay_out({CharacterLibrary::embedded().load(c)}); }

/// The embedded characters in code-point order, split in halves: the first half is the one the
/// writer's constants may be tuned on (docs/writer.md), the second is for tests of the effects.
inline std::vector<char32_t> embedded_half(bool second) {
  const std::vector<char32_t> all = CharacterLibrary::embedded().characters();
  const std::size_t half = all.size() / 2;
  return second ? std::vector<char32_t>(all.begin() + static_cast<long>(half), all.end())
                : std::vector<char32_t>(all.begin(), all.begin() + static_cast<long>(half));
}

}  // namespace calligraphy::testing
