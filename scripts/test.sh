#!/usr/bin/env bash
# Runs every test: installs dependencies, builds with warnings as errors and runs the Catch2 and
# pytest suites through CTest, then again under AddressSanitizer + UndefinedBehaviorSanitizer, then the
# servo-loop tests under ThreadSanitizer, then builds the fuzzers and replays their inputs, then
# installs the library and builds a separate project against it with find_package(calligraphy).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
jobs=$(nproc)

echo "== Layering and docs checks"
python3 scripts/check-layering.py .
bash scripts/check-docs.sh

echo "== Release build, warnings as errors"
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DCALLIGRAPHY_WARNINGS_AS_ERRORS=ON \
  -DCALLIGRAPHY_BUILD_PYTHON=ON -DCALLIGRAPHY_BUILD_TESTS=ON >/dev/null
cmake --build build -j "$jobs"
ctest --test-dir build --output-on-failure -j "$jobs"

echo "== AddressSanitizer + UndefinedBehaviorSanitizer"
# The trainer's window (Mesa, X11) and the report in Chromium are left to the Release stage: under our
# sanitizers they test other programs' code, and they are the slowest tests at -O0. (-O1 would be faster,
# but GCC 12 then warns maybe-uninitialized inside std::function in Catch2's main.)
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=Debug \
  -DCALLIGRAPHY_SANITIZE=address,undefined -DCALLIGRAPHY_WARNINGS_AS_ERRORS=ON -DCALLIGRAPHY_BUILD_BENCH=OFF \
  -DCALLIGRAPHY_BUILD_PYTHON=OFF -DCALLIGRAPHY_BUILD_TRAINER=OFF >/dev/null
cmake --build build-asan -j "$jobs"
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 ctest --test-dir build-asan --output-on-failure \
  -j "$jobs" -E "study_report_chromium"

echo "== ThreadSanitizer: the servo loop and its log queue"
# -Wno-tsan: GCC warns that TSan does not model atomic_thread_fence (the OpenHaptics seqlock uses it);
# those tests are not run here.
cmake -S . -B build-tsan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCALLIGRAPHY_SANITIZE=thread \
  -DCMAKE_CXX_FLAGS=-Wno-tsan -DCALLIGRAPHY_WARNINGS_AS_ERRORS=ON -DCALLIGRAPHY_BUILD_TOOLS=OFF \
  -DCALLIGRAPHY_BUILD_BENCH=OFF -DCALLIGRAPHY_BUILD_PYTHON=OFF -DCALLIGRAPHY_BUILD_EXAMPLES=OFF >/dev/null
cmake --build build-tsan -j "$jobs" --target calligraphy_tests
TSAN_OPTIONS=halt_on_error=1 build-tsan/bin/calligraphy_tests "[servo],[log_queue]"

echo "== Fuzzers (clang, libFuzzer): build, and replay their seeds and every input that ever failed"
# A replay, not a fuzzing run (docs/corpus.md has those): it keeps the fuzz targets building as sources
# move, and every seed and regression input passing.
cmake -S . -B build-fuzz -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCALLIGRAPHY_BUILD_FUZZERS=ON \
  -DCALLIGRAPHY_BUILD_TESTS=OFF -DCALLIGRAPHY_BUILD_BENCH=OFF -DCALLIGRAPHY_BUILD_PYTHON=OFF \
  -DCALLIGRAPHY_BUILD_EXAMPLES=OFF -DCALLIGRAPHY_BUILD_TOOLS=OFF -DCALLIGRAPHY_BUILD_TRAINER=OFF >/dev/null
cmake --build build-fuzz -j "$jobs" --target character_data_fuzzer corpus_store_fuzzer
build-fuzz/bin/character_data_fuzzer -runs=0 data/hanzi-writer-data tests/data/hostile
build-fuzz/bin/corpus_store_fuzzer -runs=0 fuzz/seeds tests/data/store_regressions

echo "== install + find_package(calligraphy) from another project"
rm -rf build/stage build/consumer
cmake --install build --prefix build/stage >/dev/null
cmake -S tests/consumer -B build/consumer -G Ninja -DCMAKE_PREFIX_PATH="$PWD/build/stage" >/dev/null
cmake --build build/consumer
build/consumer/consumer
echo "== all tests passed"
