#!/usr/bin/env bash
# The main job on the default input: set up and build, then relight the Stanford bunny
# (glmark2-data) under Blender's "forest" probe (blender-data) as the probe turns once around
# the vertical axis: bake (order 6 glossy grey Phong, 1 bounce) and compress (256 clusters x
# 8 PCs) through the cache, render 24 frames at 1280 x 948, write EXR frames, PNG previews
# and a contact sheet to out/relight/. A second run finds the bake and compression cached.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh --main

mesh=/usr/share/glmark2/models/bunny.obj
probe=/usr/share/blender/datafiles/studiolights/world/forest.exr
./build/prtr relight "$mesh" --probe "$probe" --out out/relight "$@"
