#!/usr/bin/env bash
# Installs every build, test and data dependency from Debian 12 packages (run as root).
# Idempotent: packages already present are skipped by apt-get; `apt-get update` runs only
# when the package lists are missing or older than a day.
set -euo pipefail

packages=(
  build-essential cmake ninja-build git ca-certificates
  clang libclang-rt-14-dev            # sanitizer and fuzzer builds
  libeigen3-dev libspdlog-dev catch2 nlohmann-json3-dev libbenchmark-dev
  libcli11-dev zlib1g-dev libssl-dev # command-line parsing, CRC-32, SHA-256
  libhdf5-dev libdeflate-dev python3-h5py  # trial traces as HDF5, inflated by libdeflate (h5py: tests read them as others do)
  libusb-1.0-0-dev libhidapi-dev     # Phantom backend (optional at configure time)
  pkg-config lib2geom-dev            # lib2geom column of `bench nearest` (optional at configure time)
  pybind11-dev python3-dev python3-numpy python3-pytest
  python3-setuptools python3-wheel python3-venv python3-pip     # the Python wheel and its install into a venv
  python3-pandas python3-matplotlib python3-tqdm python3-mypy   # Python tables, figures, stubgen
  python3-scipy python3-statsmodels   # calligraphy.statistics: tests, intervals, mixed models, power
  python3-dask python3-distributed    # parallel experiments from Python
  python3-jsonschema                  # tests: the published JSON Schemas checked by an independent validator
  r-base-core r-cran-lme4 r-cran-lmertest r-cran-emmeans r-cran-pbkrtest  # the study's mixed models and ANCOVA (R, run by calligraphy.statistics)
  zinnia-utils libzinnia-dev tegaki-zinnia-simplified-chinese     # an independent handwriting recogniser (legibility metric; optional)
  fonts-arphic-ukai                   # a CJK font for calligraphy.plot
  nodejs npm                          # npm pack for hanzi-writer-data
  chromium                            # the study report loaded headless (tests/study; optional, skipped without)
  libglfw3-dev libimgui-dev libstb-dev libgl-dev libx11-dev  # the trainer window (optional at configure time)
  libgl1-mesa-dri fonts-arphic-ukai   # OpenGL without a GPU (llvmpipe), the Chinese font it shows
  xvfb xauth xdotool                  # the trainer's tests on a virtual X server
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# npm may come from another installation (nvm, a distribution image); don't fight it.
if command -v npm >/dev/null 2>&1; then
  missing=("${missing[@]/npm}"); missing=("${missing[@]/nodejs}")
fi
filtered=()
for p in "${missing[@]}"; do [ -n "$p" ] && filtered+=("$p"); done

if [ "${#filtered[@]}" -eq 0 ]; then
  echo "install-deps: all packages present"
  exit 0
fi

export DEBIAN_FRONTEND=noninteractive
lists=/var/lib/apt/lists
if [ -z "$(find "$lists" -maxdepth 1 -name '*Packages*' -mtime -1 2>/dev/null | head -n 1)" ]; then
  apt-get update -qq
fi
echo "install-deps: installing ${filtered[*]}"
apt-get install -y -qq --no-install-recommends "${filtered[@]}" >/dev/null
echo "install-deps: done"
