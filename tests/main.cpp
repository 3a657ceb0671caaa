#define CATCH_CONFIG_RUNNER
#include <spdlog/cfg/env.h>
#include <spdlog/spdlog.h>

#include <catch2/catch.hpp>

int main(int argc, char* argv[]) {
  // The devices log their start-up and close (what is verified, packet counters): useful in programs,
  // noise in test output. Only errors are shown; SPDLOG_LEVEL=info (or debug) shows everything.
  spdlog::set_level(spdlog::level::err);
  spdlog::cfg::load_env_levels();
  return Catch::Session().run(argc, argv);
}
