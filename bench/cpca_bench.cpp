// cpca_bench [TRANSFER.prtx] [CLUSTERS...]: clustering time of LBG against one assignment
// step (the GEMM of all points against all centroids) measured in the same run, and the
// per-cluster PCA by power iteration against Eigen's solver on the same clusters.
// Ratios, not absolute times, are what to compare across machines.
#include "cpca/assignment.h"
#include "cpca/cluster_pca.h"
#include "cpca/compress.h"
#include "prt/transfer_file.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;

template <class F>
double seconds(F&& f) {
  const auto t = Clock::now();
  f();
  return std::chrono::duration<double>(Clock::now() - t).count();
}

template <class F>
double median_seconds(int runs, F&& f) {
  std::vector<double> s;
  for (int i = 0; i < runs; ++i) s.push_back(seconds(f));
  std::sort(s.begin(), s.end());
  return s[s.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  const std::string path = argc > 1 ? argv[1] : "out/bunny.prtx";
  std::vector<int> ks;
  for (int i = 2; i < argc; ++i) ks.push_back(std::atoi(argv[i]));
  if (ks.empty()) ks = {64, 128, 192, 256};
  const prt::TransferSet t = prt::read_transfer(path);
  const Eigen::Map<const cpca::DataMatrix> x(t.data.data(), Eigen::Index(t.vertex_count),
                                             Eigen::Index(t.floats_per_vertex()));
  const Eigen::VectorXf norms = x.rowwise().squaredNorm();
  std::printf("%s: %lld vertices x %lld dimensions\n", path.c_str(), (long long)x.rows(),
              (long long)x.cols());
  std::printf(
      "| K | one step s | LBG s | iterations | LBG / step | PCA power s | PCA eigen s | power / "
      "eigen | Average SE power | Average SE eigen |\n");
  std::printf("| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n");
  for (int k : ks) {
    cpca::CompressOptions o;
    o.clusters = k;
    o.components = 8;
    o.layout = {t.order, t.channels, t.columns()};
    cpca::CompressReport report;
    cpca::CompressedSet set = cpca::compress(x, o, nullptr, &report);
    const cpca::DataMatrix means = Eigen::Map<const cpca::DataMatrix>(
        set.means.data(), set.cluster_count, Eigen::Index(set.dimension()));
    const double step = median_seconds(3, [&] {
      const cpca::DataMatrix d = cpca::squared_distances(x, norms, means);
      (void)cpca::argmin_rows(d);
    });
    std::vector<double> e_power, e_eigen;
    const double power =
        seconds([&] { e_power = cpca::fit_cluster_pca(x, set, cpca::PcaSolver::kPowerIteration); });
    const double eigen =
        seconds([&] { e_eigen = cpca::fit_cluster_pca(x, set, cpca::PcaSolver::kEigen); });
    double sp = 0, se = 0;
    for (double v : e_power) sp += v;
    for (double v : e_eigen) se += v;
    std::printf("| %d | %.3f | %.2f | %d | %.1f | %.2f | %.2f | %.2f | %.5e | %.5e |\n", k, step,
                report.lbg_seconds, report.lbg_iterations, report.lbg_seconds / step, power, eigen,
                power / eigen, sp / double(x.rows()), se / double(x.rows()));
    std::fflush(stdout);
  }
}
