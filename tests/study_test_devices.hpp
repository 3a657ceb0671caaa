#pragma once
// The device registry of a study test: the library's standard backends, passed to every session and trial
// the test runs (the library never makes a registry of its own).
#include "calligraphy/devices/device_registry.hpp"
#include "calligraphy/study/session_runner.hpp"
#include "calligraphy/trial/trial_spec_runner.hpp"

namespace study_test {

/// The standard registry (standard_device_registry()), built once per test program.
inline const calligraphy::DeviceRegistry& registry() {
  static const calligraphy::DeviceRegistry standard = calligraphy::standard_device_registry();
  return standard;
}

/// Session options whose devices come from `registry()`.
inline calligraphy::SessionRunOptions run_options() {
  calligraphy::SessionRunOptions options;
  options.registry = &registry();
  return options;
}

/// Trial inputs whose device comes from `registry()`, with `writing` (not owned) as the simulated writer's
/// hand maker.
inline calligraphy::TrialRunInputs trial_inputs(calligraphy::TrialHandMaker* writing = nullptr) {
  calligraphy::TrialRunInputs inputs;
  inputs.registry = &registry();
  inputs.hand_maker = writing;
  return inputs;
}

}  // namespace study_test
