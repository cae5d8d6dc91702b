#!/usr/bin/env bash
# The main job: install what is needed, build sgbake, and bake the bundled default scene
# (meshes/default_scene.json: Suzanne with a height map and a triplanar layer) into out/
# (override with SGBAKE_OUT), plus the mesh's MikkTSpace tangent frames as CSV.
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/deps.sh
install_deps build
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DSGBAKE_BUILD_TESTS=OFF -DSGBAKE_BUILD_BENCH=OFF
cmake --build build
out="${SGBAKE_OUT:-out}"
mkdir -p "$out"
./build/src/sgbake bake meshes/default_scene.json --out-dir "$out" --stats
./build/src/sgbake tangents meshes/suzanne.obj -o "$out/suzanne_tangents.csv"
echo "wrote $out/suzanne_tangents.csv ($(($(wc -l < "$out/suzanne_tangents.csv") - 1)) corners)"
