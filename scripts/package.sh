#!/usr/bin/env bash
# Builds the Debian package calibench_<version>_amd64.deb (CPack, packaging/CMakeLists.txt) from
# this checkout and reports lintian's findings:
#   scripts/package.sh            -> build/calibench_<version>_amd64.deb
#   scripts/package.sh --verify   the same, then installs it with apt into a fresh Debian 12 root
#                                 (debootstrap, as root, needs the network) and runs it there
set -euo pipefail
cd "$(dirname "$0")/.."
verify=0
[ "${1:-}" = "--verify" ] && verify=1

bash scripts/install_deps.sh --package
BUILD_DIR=${CALIBENCH_BUILD_DIR:-build}
JOBS=${CALIBENCH_JOBS:-$(nproc)}
cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$BUILD_DIR" -j "$JOBS"
rm -f "$BUILD_DIR"/calibench_*_amd64.deb
(cd "$BUILD_DIR" && cpack -G DEB >/dev/null)
deb=$(ls "$BUILD_DIR"/calibench_*_amd64.deb)
echo "package: $deb ($(du -h "$deb" | cut -f1))"
dpkg-deb --field "$deb" Package Version Depends | sed 's/^/  /'
echo "lintian:"
lintian --tag-display-limit 0 "$deb" | sed 's/^/  /' || true

[ $verify -eq 1 ] || exit 0
# A fresh Debian 12 (minbase: no compiler, no -dev package), the package installed by apt with
# the dependencies it declares, then what a user runs first.
root=${CALIBENCH_VERIFY_ROOT:-/tmp/calibench-debian12-root}
if [ ! -x "$root/usr/bin/apt-get" ]; then
  command -v debootstrap >/dev/null || apt-get install -y -qq debootstrap
  debootstrap --variant=minbase bookworm "$root" http://deb.debian.org/debian
fi
cp "$deb" "$root/tmp/"
for fs in proc dev; do mountpoint -q "$root/$fs" || mount --bind "/$fs" "$root/$fs"; done
trap 'umount "$root/proc" "$root/dev" 2>/dev/null || true' EXIT
chroot "$root" /bin/bash -euxc "
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends /tmp/$(basename "$deb") >/tmp/apt.log
  cd /tmp
  calibench --version
  calibench demo --out /tmp/demo --no-gui | tail -4
  python3 -c 'import calibench, numpy; r = calibench.calibrate(\"/tmp/demo\"); print(r); print(calibench.__file__)'
  test -f /usr/share/man/man1/calibench.1.gz && test -f /usr/share/bash-completion/completions/calibench
  echo 'installed package: ok'
"
