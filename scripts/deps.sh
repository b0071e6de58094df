#!/usr/bin/env bash
# Installs the Debian packages edgeslam needs. Idempotent: does nothing when all are present.
set -euo pipefail
packages=(
  build-essential cmake ninja-build pkg-config ccache clang-format python3 util-linux
  clang libclang-rt-14-dev
  libopencv-dev libeigen3-dev libceres-dev
  libgrpc++-dev libprotobuf-dev protobuf-compiler protobuf-compiler-grpc
  libgtest-dev libgmock-dev libbenchmark-dev
  libspdlog-dev libfmt-dev libcli11-dev nlohmann-json3-dev libyaml-cpp-dev libzstd-dev
  libcpp-httplib-dev libsqlite3-dev
  openssl zlib1g-dev
  chromium
)
missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
# node and npm may come from elsewhere (e.g. NodeSource's nodejs bundles npm): Debian's only when absent.
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then missing+=(nodejs npm); fi
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
if [ ${#missing[@]} -gt 0 ]; then
  echo "deps: installing ${missing[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
# The web viewer's libraries (three.js, uPlot; embedded into the binary) and the browser test's
# driver (puppeteer-core), pinned by web/package-lock.json.
web_dir="$(dirname "$0")/../web"
if [ ! -d "$web_dir/node_modules" ]; then
  echo "deps: npm ci in web/"
  (cd "$web_dir" && npm ci --no-audit --no-fund --loglevel=error)
fi
