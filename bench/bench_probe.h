// bench/bench_probe.h: the probe a benchmark lights with. "procedural" is a sky with a sun
// built in code at the size of Blender's studio probes (1024 x 512), so a benchmark built
// without image readers times the same work; anything else is an image file. Two definitions,
// one per binary: bench_probe_file.cpp reads files (OpenImageIO), bench_probe_procedural.cpp
// refuses them and so links no image library (the GPU bundle's render_bench_portable).
#pragma once

#include "probes/probe.h"

#include <string>

probes::Probe load_bench_probe(const std::string& spec);

// The procedural probe alone (bench_probe_sky.cpp).
probes::Probe procedural_bench_probe();
