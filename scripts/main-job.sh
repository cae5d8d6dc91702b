#!/usr/bin/env bash
# The main job: install what is needed, build sgbake, and run it on the bundled default scene.
# Outputs go to out/ (override with SGBAKE_OUT).
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/deps.sh
install_deps build
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DSGBAKE_BUILD_TESTS=OFF -DSGBAKE_BUILD_BENCH=OFF
cmake --build build
out="${SGBAKE_OUT:-out}"
mkdir -p "$out"
./build/src/sgbake tangents meshes/suzanne.obj -o "$out/suzanne_tangents.csv" --stats
echo "wrote $out/suzanne_tangents.csv ($(($(wc -l < "$out/suzanne_tangents.csv") - 1)) corners)"
