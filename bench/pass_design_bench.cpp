// Pass-designing CPCA methods against original CPCA on a real bake: clustering time, Average
// SE (and its ratio to original CPCA's) and average triangle overdraw, every overdraw counted
// by cpca::overdraw -- for original CPCA with the best existing super-cluster strategy (ILS,
// supercluster_search.h), for patch-first and joint with the passes they were designed for
// (cpca::designed_passes).
// Usage: pass_design_bench TRANSFER MESH [K,...] [PER_PASS,...] [ROW,...] [MAX_STEPS]
//   ROW: original | patch-first | joint:LAMBDA[:CAP] | patch-joint:LAMBDA[:CAP] (CAP: the
//   search's overdraw cap, joint_search.h) | patch-eps[:EPS] (the epsilon constraint against
//   the original row before it at the same K)     (defaults: 64,128,192,256
//   3,16 original,patch-first,joint:0.5)
#include "cpca/compress.h"
#include "cpca/joint_search.h"
#include "cpca/patch_first.h"
#include "cpca/supercluster.h"
#include "cpca/supercluster_strategy.h"
#include "meshes/load.h"
#include "prt/transfer_file.h"

#include <cstdint>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

namespace {

std::vector<std::string> split_on(const std::string& text, char separator) {
  std::vector<std::string> items;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, separator)) items.push_back(item);
  return items;
}
std::vector<std::string> split(const std::string& text) {
  return split_on(text, ',');
}

struct Row {
  double seconds = 0, se = 0, overdraw = 0;
};

Row run(const cpca::DataMatrix& x, const cpca::Geometry& g, cpca::CompressOptions o,
        const std::string& row, int per_pass, double reference_se,
        std::vector<std::uint32_t>& reference_clusters) {
  o.clusters_per_pass = per_pass;
  if (row == "original") {
    o.method = cpca::ClusterMethod::kLbg;
  } else if (row == "patch-first") {
    o.method = cpca::ClusterMethod::kPatchFirst;
  } else if (row.rfind("patch-eps", 0) == 0) {
    // Against the original row's Average SE when it ran first (as prtr overdraw passes it),
    // so the time is the method's own; else the method compresses the original itself.
    o.method = cpca::ClusterMethod::kPatchEpsilon;
    const auto fields = split_on(row, ':');
    if (fields.size() > 1) o.error_slack = std::stod(fields[1]);
    o.error_target = reference_se;
    if (reference_se > 0) o.reference_clusters = reference_clusters;
  } else {
    o.method = row.rfind("patch-joint", 0) == 0 ? cpca::ClusterMethod::kPatchJoint
                                                : cpca::ClusterMethod::kJoint;
    const auto fields = split_on(row, ':');
    o.lambda = std::stod(fields.at(1));
    if (fields.size() > 2) o.overdraw_cap = std::stod(fields[2]);
  }
  cpca::CompressReport report;
  const cpca::CompressedSet set = cpca::compress(x, o, &g, &report);
  if (row == "original") reference_clusters = set.cluster_of;
  Row r;
  r.seconds = report.clustering_seconds() + report.pca_seconds;
  r.se = cpca::error_metrics(x, set).average_squared_error;
  cpca::SuperClusters groups;
  if (o.method == cpca::ClusterMethod::kLbg) {
    cpca::SuperClusterInput input;
    input.cluster_of = set.cluster_of;
    input.triangles = g.triangles;
    input.cluster_count = set.cluster_count;
    input.per_pass = per_pass;
    groups = cpca::group_clusters("ils", input);
  } else {
    groups = cpca::designed_passes(set, per_pass);
  }
  r.overdraw = cpca::overdraw(set.cluster_of, g.triangles, groups).average_overdraw;
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s TRANSFER MESH [K,...] [PER_PASS,...] [ROW,...]\n", argv[0]);
    return 2;
  }
  const prt::TransferSet t = prt::read_transfer(argv[1]);
  const meshes::Mesh mesh = meshes::load_mesh(argv[2]);
  cpca::Geometry g;
  g.positions = mesh.positions;
  for (const meshes::Triangle& tri : mesh.triangles)
    g.triangles.push_back({tri[0], tri[1], tri[2]});
  const cpca::DataMatrix x = Eigen::Map<const cpca::DataMatrix>(
      t.data.data(), Eigen::Index(t.vertex_count), Eigen::Index(t.floats_per_vertex()));
  const auto ks = split(argc > 3 ? argv[3] : "64,128,192,256");
  const auto per_passes = split(argc > 4 ? argv[4] : "3,16");
  const auto rows = split(argc > 5 ? argv[5] : "original,patch-first,joint:0.5");
  cpca::CompressOptions o;
  o.layout = {t.order, t.channels, t.columns()};
  o.components = 8;
  if (argc > 6) o.cpca_max_iterations = std::stoi(argv[6]);  // iterative CPCA and search steps
  std::printf("| K | per pass | row | clustering s | Average SE | SE / original | overdraw |\n");
  std::printf("| ---: | ---: | --- | ---: | ---: | ---: | ---: |\n");
  for (const std::string& k : ks) {
    o.clusters = std::stoi(k);
    double original_se = 0;
    std::vector<std::uint32_t> original_clusters;
    for (const std::string& per_pass : per_passes)
      for (const std::string& row : rows) {
        const Row r = run(x, g, o, row, std::stoi(per_pass), original_se, original_clusters);
        if (row == "original") original_se = r.se;
        std::printf("| %s | %s | %s | %.2f | %.4e | %.3f | %.3f |\n", k.c_str(), per_pass.c_str(),
                    row.c_str(), r.seconds, r.se, original_se > 0 ? r.se / original_se : 0.0,
                    r.overdraw);
        std::fflush(stdout);
      }
  }
  return 0;
}
