#!/usr/bin/env bash
# The main job on the default input: set up, build, then run the deepest stage that exists
# on the Stanford bunny (glmark2-data) and Blender's "forest" probe (blender-data).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh

mesh=/usr/share/glmark2/models/bunny.obj
probe=/usr/share/blender/datafiles/studiolights/world/forest.exr

./build/prtr mesh "$mesh"
echo
./build/prtr probe "$probe" --order 6
echo
./build/prtr gl-info
