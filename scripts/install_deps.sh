#!/usr/bin/env bash
# Installs Calibench's build and test dependencies from Debian 12 packages. Idempotent: packages
# already present are skipped, so a second run does nothing. Works as root or through sudo.
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build ccache pkg-config git
  libeigen3-dev libopencv-dev libopencv-contrib-dev libpcl-dev nlohmann-json3-dev libcli11-dev
  libyaml-cpp-dev libtinyxml2-dev libsqlite3-dev libzstd-dev liblz4-dev libbz2-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libglfw3-dev libimgui-dev libegl-dev libgl-dev libgles-dev libosmesa6-dev
  xvfb xauth fonts-dejavu-core
  libcairo2-dev libjs-chart.js chromium poppler-utils liburdfdom-tools
  pybind11-dev python3-dev python3-numpy python3-pytest python3-matplotlib help2man
)
# Only for the robustness scripts: scripts/fuzz.sh (libFuzzer) and scripts/sanitize.sh (valgrind);
# and for scripts/package.sh (the .deb checked by lintian).
case "${1:-}" in
  --fuzz) PACKAGES+=(clang-14 libclang-rt-14-dev) ;;
  --sanitize) PACKAGES+=(valgrind) ;;
  --package) PACKAGES+=(dpkg-dev lintian fakeroot) ;;
esac

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#PACKAGES[@]} packages already installed"
  exit 0
fi

if [ "$(id -u)" -eq 0 ]; then
  SUDO=()
elif command -v sudo >/dev/null; then
  SUDO=(sudo)
else
  echo "install_deps: need root or sudo to install: ${missing[*]}" >&2
  exit 1
fi

echo "install_deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${SUDO[@]}" apt-get update -qq
"${SUDO[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}"
