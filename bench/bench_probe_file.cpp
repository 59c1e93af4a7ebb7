#include "bench_probe.h"

#include "probes/load.h"

probes::Probe load_bench_probe(const std::string& spec) {
  if (spec == "procedural") return procedural_bench_probe();
  return probes::load_probe(spec);
}
