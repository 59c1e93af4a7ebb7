#!/usr/bin/env bash
# The main job on the default input: set up, build, then run the deepest stage that exists
# on the Stanford bunny (glmark2-data) and Blender's "forest" probe (blender-data): for now,
# print both inputs' facts and the probe's SH lighting, and bake the bunny to out/bunny.prtx.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh

mesh=/usr/share/glmark2/models/bunny.obj
probe=/usr/share/blender/datafiles/studiolights/world/forest.exr

./build/prtr mesh "$mesh"
echo
./build/prtr probe "$probe" --order 6
echo
mkdir -p out
./build/prtr bake "$mesh" -o out/bunny.prtx --kind glossy --order 6 --samples 1024 --bounces 1
echo
./build/prtr gl-info
