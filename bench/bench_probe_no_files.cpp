#include "bench_probe.h"

#include <stdexcept>

probes::Probe load_bench_probe(const std::string& spec) {
  if (spec == "procedural") return procedural_bench_probe();
  throw std::invalid_argument("--probe " + spec +
                              ": this build reads no image files (no OpenImageIO); use "
                              "--probe procedural");
}
