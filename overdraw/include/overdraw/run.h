// overdraw/run.h: the overdraw benchmark (thesis tables 5.2-5.17, ch. 5) as a
// library: a plan in, an OverdrawReport out (overdraw/report.h renders it). prtr overdraw
// only parses flags into a plan and prints the report; other drivers (a viewer, a research
// sweep) build their own plans.
//
// For every cluster count K and method row it compresses the bake through the shared cache
// (pipeline/pipeline.h, which also keeps each compression's clustering time and errors, so a
// cached row reports what was measured), then for every register budget and super-cluster
// strategy it measures one row: the exact average triangle overdraw (cpca::overdraw), the
// multipass render with that grouping, a check that the triangles GL counted equal the
// prediction (a mismatch is a bug and stops the run), the work counters of one frame and the
// image RMSE against the uncompressed render. Timing comes last and is interleaved: `rounds`
// rounds, each visiting every row in turn for warm-up + frames frames, so that load from
// other processes on a shared machine falls on all rows alike rather than on whichever rows
// ran while it lasted; each row reports the median and quartiles of all its timed frames,
// and the run the least-squares line of GL time and FPS against overdraw. Per K, the
// single-pass and decoupled paths show what the overdraw costs.
#pragma once

#include "overdraw/report.h"

#include "cpca/compress.h"
#include "pipeline/reporter.h"
#include "prt/bake.h"
#include "render/gl_context.h"

#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace overdraw {

// A plan that cannot run as given (unknown name, a size the data does not allow); the
// message names the flag that sets the field. Other errors are failures of the run.
class PlanError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

// One method row: the thesis's four, and iterative CPCA with both (ours). A new clustering
// method is one more line in kMethods (overdraw_run.cpp) and, if the cache must tell it
// apart, a field here that compress_row copies into cpca::CompressOptions.
struct MethodPreset {
  const char* name;
  const char* summary;
  bool coherence, overdraw_reduction, iterative;
  // Methods that design the passes while clustering (cpca/patch_first.h, joint_search.h)
  // compress once per budget, for that budget's clusters per pass, and are drawn in cluster
  // order (cpca::designed_passes) instead of by the super-cluster strategies.
  cpca::ClusterMethod designed = cpca::ClusterMethod::kLbg;
  double lambda = 0, overdraw_cap = 0;
  bool designs_passes() const { return designed != cpca::ClusterMethod::kLbg; }
};
// PlanError listing the names for an unknown one.
const MethodPreset& find_method(const std::string& name);
std::string method_names();  // "original, overdraw-reduction, ..."

struct OverdrawPlan {
  std::string mesh, probe;
  std::string transfer;  // a bake of the mesh; empty: bake with `bake` through the cache
  prt::BakeOptions bake;
  std::string cache;                    // directory of cached bakes and compressions
  bool recompress = false;              // ignore cached compressions (still writes them)
  std::vector<int> clusters;            // K
  std::vector<std::string> methods;     // MethodPreset names
  std::vector<std::string> strategies;  // cpca::group_clusters names
  std::vector<std::string> budgets;     // "default", "thesis" or a vec4 count
  // Everything but K, method, alpha and overdraw reduction, which the rows set; `alpha` is
  // the coherence rows' weight.
  cpca::CompressOptions compress;
  int frames = 10, warmup = 2, width = 1280, height = 948;
  int rounds = 3;  // interleaved timing rounds over all rows
  double degrees_per_frame = 1.0;
  // Image errors: pooled over image_rotations environment rotations about +Y, evenly spaced
  // from image_degrees.
  double image_degrees = 37.0;
  int image_rotations = 12;
  bool modes = true;            // single-pass / decoupled / uncompressed timings
  pipeline::Reporter reporter;  // the bake's progress and notes; cache repairs (warnings)
  render::GlSelection gl;       // the backend every row renders on
  std::string pictures;         // directory for the cluster and overdraw pictures; empty: none
  std::function<void(const std::string&)> note;  // one-line events (may be empty)
  std::function<void(const std::string&, std::uint64_t, std::uint64_t)> progress;
};

// Checks names and sizes that need no data (PlanError); run_overdraw calls it first.
void validate(const OverdrawPlan& plan);

OverdrawReport run_overdraw(const OverdrawPlan& plan);

// The budget whose rows the plot and the pictures show: "thesis" when measured, else the
// first (plot) or last (pictures) budget.
std::string plot_budget(const std::vector<std::string>& budgets);

}  // namespace overdraw
