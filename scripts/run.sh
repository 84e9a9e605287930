#!/bin/sh
# Quick start 1: install dependencies, build everything, run `cranesim drive`
# on the built-in default crane and sandbox (headless if there is no display).
set -eu
cd "$(dirname "$0")/.."
sh scripts/deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)"
exec ./build/cranesim drive "$@"
