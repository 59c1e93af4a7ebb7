// apps/prtr/compress_flags.h: the CPCA flags (--clusters, --pcs, --method, --alpha,
// --overdraw-reduction, --overdraw-tolerance; and for prtr compress --pca, --seed,
// --threshold, --max-iterations, --clusters-per-pass, --lambda, --overdraw-cap; --epsilon for
// all), registered with
// one help text by every command that compresses: prtr compress, and prtr relight / overdraw
// through the cache.
#pragma once

#include "cpca/compress.h"

#include <CLI/CLI.hpp>

#include <string>

namespace prtr_app {

struct CompressFlags {
  cpca::CompressOptions compress;  // the defaults shown in --help
  std::string method = "lbg", pca = "power";
  // Set when registered, so that resolving can tell a given flag from its default.
  CLI::Option *lambda = nullptr, *per_pass = nullptr, *cap = nullptr, *epsilon = nullptr;
  bool per_row = false;  // registered for prtr overdraw, whose rows choose the method
};

// Which commands register which flags: prtr compress all of them; relight the ones a cached
// pipeline run varies (its --seed is the bake's); overdraw only those its method rows do not
// set (K, method and overdraw reduction come from --clusters and --rows).
enum class CompressFlagSet { kCompress, kPipeline, kPerRow };
void add_compress_flags(CLI::App* command, CompressFlags& flags, CompressFlagSet set);

// The options the flags describe (names parsed by cpca's own parsers). UsageError (exit 2)
// for flags the method does not take.
cpca::CompressOptions resolve_compress_flags(const CompressFlags& flags);

}  // namespace prtr_app
