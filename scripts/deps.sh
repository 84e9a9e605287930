#!/bin/sh
# Installs the Debian 12 packages cranesim needs, only if some are missing.
# Runs unattended (CI is root with no terminal); uses sudo when not root.
# `deps.sh fuzz` adds clang and its runtime libraries (libFuzzer, the
# sanitizers) for the fuzzing stage of .ci/run; the Quick start does not need
# them, so they are a separate list.
set -eu
FUZZ_PKGS="clang libclang-rt-14-dev"
PKGS="cmake make gcc g++ pkg-config libode-dev libcjson-dev libplplot-dev plplot-driver-cairo libsundials-dev \
libsdl2-dev libassimp-dev libgl-dev libegl-dev libgles-dev libosmesa6-dev libgl1-mesa-dri \
libegl-mesa0 libimgui-dev libstb-dev xvfb xauth libopenmpi-dev openmpi-bin libnlopt-dev python3"
[ "${1:-}" = "fuzz" ] && PKGS="$PKGS $FUZZ_PKGS"
missing=""
for p in $PKGS; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
[ -z "$missing" ] && exit 0
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"
echo "cranesim: installing missing Debian packages:$missing"
$SUDO apt-get update -q
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends $missing
