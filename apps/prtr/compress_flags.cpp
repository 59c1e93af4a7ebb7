#include "compress_flags.h"

#include "commands.h"
#include "cpca/compressed.h"
#include "flag_checks.h"

namespace prtr_app {

void add_compress_flags(CLI::App* cmd, CompressFlags& f, CompressFlagSet set) {
  cpca::CompressOptions& o = f.compress;
  const bool per_row = set == CompressFlagSet::kPerRow;
  f.per_row = per_row;
  if (!per_row) {
    add_checked_option(cmd, "--clusters", o.clusters, "Number of CPCA clusters K",
                       integer_in(1, 65536));
  }
  add_checked_option(cmd, "--pcs", o.components, "Principal components per cluster N",
                     integer_in(0, 1 << 20));
  if (!per_row) {
    cmd->add_option("--method", f.method,
                    "lbg: LBG then PCA per cluster; iterative: Sloan et al. 2003 iterative CPCA; "
                    "patch-first: one METIS patch per pass, CPCA inside each; joint: local "
                    "search on Average SE + lambda x overdraw; patch-joint: that search "
                    "started from patch-first; patch-eps: from patch-first, the least overdraw "
                    "with Average SE <= (1 + --epsilon) x original CPCA's")
        ->check(CLI::IsMember(cpca::kClusterMethodNames.names()))
        ->capture_default_str();
  }
  cmd->add_option("--alpha", o.alpha,
                  "Geometry-coherence weight (thesis eq. 9-10; 0 = off, the thesis used 0.05)")
      ->check(number_in(0.0, 1e6))
      ->capture_default_str();
  if (!per_row) {
    cmd->add_flag("--overdraw-reduction", o.overdraw_reduction,
                  "Move border vertices to neighbouring clusters to cut multi-cluster triangles");
  }
  add_checked_option(
      cmd, "--overdraw-tolerance", o.overdraw.tolerance,
      "Overdraw reduction: largest error increase per move, in units of the Average SE",
      number_in(0.0, 1e6));
  f.epsilon = add_checked_option(
      cmd, "--epsilon", o.error_slack,
      "patch-eps: Average SE allowed above original CPCA's at the same K, as a fraction (0 = no "
      "worse than the original)",
      number_in(0.0, 1e6));
  if (set != CompressFlagSet::kCompress) return;
  cmd->add_option("--pca", f.pca, "power: power iteration (SLF paper); eigen: Eigen's solver")
      ->check(CLI::IsMember(cpca::kPcaSolverNames.names()))
      ->capture_default_str();
  add_checked_option(cmd, "--seed", o.seed, "Seed of the hyper-box initialisation",
                     unsigned_integer());
  add_checked_option(cmd, "--threshold", o.lbg_threshold,
                     "LBG stops when the energy ratio (E_{i-1} - E_i) / E_{i-1} falls below this",
                     number_in(0.0, 1.0));
  add_checked_option(cmd, "--max-iterations", o.lbg_max_iterations, "LBG iteration cap",
                     integer_in(1, 100000));
  f.per_pass = add_checked_option(cmd, "--clusters-per-pass", o.clusters_per_pass,
                                  "patch-first / joint: clusters one render pass holds (16 at the "
                                  "default budget for order 6 and 8 PCs, 3 at the thesis's)",
                                  integer_in(1, 1 << 20));
  f.lambda = add_checked_option(cmd, "--lambda", o.lambda,
                                "joint: overdraw weight, in units of the start's Average SE per "
                                "unit of average overdraw (0 = iterative CPCA)",
                                number_in(0.0, 1e6));
  f.cap = cmd->add_option("--overdraw-cap", o.overdraw_cap,
                          "joint: no vertex move may raise the average overdraw above this "
                          "(0 = no cap; else >= 1), so a small --lambda spends the allowance "
                          "on error")
              ->check(number_in(0.0, 1e6))
              ->capture_default_str();
}

namespace {

bool given(const CLI::Option* option) {
  return option && option->count() > 0;
}

}  // namespace

cpca::CompressOptions resolve_compress_flags(const CompressFlags& f) {
  cpca::CompressOptions o = f.compress;
  o.method = cpca::kClusterMethodNames.parse(f.method);
  o.solver = cpca::kPcaSolverNames.parse(f.pca);
  const bool joint =
      o.method == cpca::ClusterMethod::kJoint || o.method == cpca::ClusterMethod::kPatchJoint;
  const bool epsilon = o.method == cpca::ClusterMethod::kPatchEpsilon;
  const bool designed = joint || epsilon || o.method == cpca::ClusterMethod::kPatchFirst;
  if (given(f.per_pass) && !designed)
    throw UsageError(
        "--clusters-per-pass applies to --method patch-first, joint, patch-joint or patch-eps "
        "only");
  if (given(f.lambda) && !joint)
    throw UsageError("--lambda applies to --method joint or patch-joint only");
  if (given(f.cap) && !joint)
    throw UsageError("--overdraw-cap applies to --method joint or patch-joint only");
  if (o.overdraw_cap > 0 && o.overdraw_cap < 1)
    throw UsageError("--overdraw-cap " + std::to_string(o.overdraw_cap) +
                     " is below 1, the least average overdraw there is: use 0 (no cap) or >= 1");
  if (given(f.epsilon) && !epsilon && !f.per_row)
    throw UsageError("--epsilon applies to --method patch-eps only");
  if ((joint || epsilon) && (o.alpha > 0 || o.overdraw_reduction))
    throw UsageError("--method " + f.method +
                     " weighs overdraw itself (--lambda): drop --alpha and --overdraw-reduction");
  return o;
}

}  // namespace prtr_app
