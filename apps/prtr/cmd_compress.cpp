// prtr compress TRANSFER --mesh MESH -o FILE: clustered PCA of a bake (LBG or iterative CPCA,
// optional geometry coherence and overdraw-aware reassignment), with a one-screen report.
#include "commands.h"

#include "cpca/compress.h"
#include "cpca/compressed_file.h"
#include "meshes/load.h"
#include "pipeline.h"
#include "progress_bar.h"
#include "prt/transfer_file.h"

#include <cstdio>
#include <filesystem>
#include <string>

namespace prtr_app {

Runner add_compress_command(CLI::App& app) {
  struct Options {
    std::string transfer, mesh, output, method = "lbg", pca = "power";
    cpca::CompressOptions compress;
    bool quiet = false, json = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "compress", "Compress a bake with clustered PCA (CPCA) into a .prtc file for rendering");
  cmd->add_option("TRANSFER", opt->transfer, "Transfer file from prtr bake (.prtx)")->required();
  cmd->add_option("--mesh", opt->mesh, "The mesh that was baked (checked against the bake)")
      ->required();
  cmd->add_option("-o,--output", opt->output, "Compressed file to write (.prtc)")->required();
  cmd->add_option("--clusters", opt->compress.clusters, "Number of clusters K")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--pcs", opt->compress.components, "Principal components per cluster N")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--method", opt->method,
                  "lbg: LBG then PCA per cluster; iterative: Sloan et al. 2003 iterative CPCA")
      ->check(CLI::IsMember({"lbg", "iterative"}))
      ->capture_default_str();
  cmd->add_option("--alpha", opt->compress.alpha,
                  "Geometry-coherence weight (thesis eq. 9-10; 0 = off, the thesis used 0.05)")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
  cmd->add_flag("--overdraw-reduction", opt->compress.overdraw_reduction,
                "Move border vertices to neighbouring clusters to cut multi-cluster triangles");
  cmd->add_option("--overdraw-tolerance", opt->compress.overdraw.tolerance,
                  "Largest error increase per move, in units of the Average SE")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
  cmd->add_option("--pca", opt->pca, "power: power iteration (SLF paper); eigen: Eigen's solver")
      ->check(CLI::IsMember({"power", "eigen"}))
      ->capture_default_str();
  cmd->add_option("--seed", opt->compress.seed, "Seed of the hyper-box initialisation")
      ->capture_default_str();
  cmd->add_option("--threshold", opt->compress.lbg_threshold,
                  "LBG stops when the energy ratio (E_{i-1} - E_i) / E_{i-1} falls below this")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  cmd->add_option("--max-iterations", opt->compress.lbg_max_iterations, "LBG iteration cap")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  cmd->add_flag("--json", opt->json, "Print the report as one JSON line instead");
  cmd->add_flag("-q,--quiet", opt->quiet, "No progress bar");

  return [opt] {
    Options& o = *opt;
    o.compress.method =
        o.method == "iterative" ? cpca::ClusterMethod::kIterative : cpca::ClusterMethod::kLbg;
    o.compress.solver =
        o.pca == "eigen" ? cpca::PcaSolver::kEigen : cpca::PcaSolver::kPowerIteration;

    const prt::TransferSet header = prt::read_transfer_header(o.transfer);
    const std::size_t dimension = header.floats_per_vertex();
    if (std::uint64_t(o.compress.clusters) > header.vertex_count)
      throw UsageError("--clusters " + std::to_string(o.compress.clusters) + " exceeds the " +
                       std::to_string(header.vertex_count) + " vertices of " + o.transfer +
                       "; use at most that many");
    if (std::size_t(o.compress.components) >= dimension)
      throw UsageError("--pcs " + std::to_string(o.compress.components) +
                       " must be below the data dimension " + std::to_string(dimension) + " of " +
                       o.transfer);
    const meshes::Mesh mesh = meshes::load_mesh(o.mesh);
    const prt::TransferSet transfer = prt::read_transfer(o.transfer);
    cpca::CompressReport report;
    const cpca::CompressedSet set =
        run_compress(transfer, mesh, o.mesh, o.compress, o.quiet || o.json, &report);
    cpca::write_compressed(o.output, set);

    const double raw_bytes = double(transfer.data.size()) * 4.0;
    const double file_bytes = double(std::filesystem::file_size(o.output));
    const cpca::TriangleSpan& s = report.span;
    const double triangles = double(mesh.triangle_count());
    if (o.json) {
      std::printf(
          "{\"clusters\":%d,\"pcs\":%d,\"method\":\"%s\",\"pca\":\"%s\",\"alpha\":%g,"
          "\"overdraw_reduction\":%s,\"lbg_iterations\":%d,\"cpca_iterations\":%d,\"splits\":%d,"
          "\"lbg_seconds\":%.4f,\"pca_seconds\":%.4f,\"cpca_seconds\":%.4f,"
          "\"overdraw_seconds\":%.4f,\"clustering_seconds\":%.4f,\"total_seconds\":%.4f,"
          "\"average_se\":%.9g,\"relative_error\":%.9g,\"max_se\":%.9g,\"ratio\":%.4f,"
          "\"file_bytes\":%.0f,\"triangles_1\":%llu,\"triangles_2\":%llu,\"triangles_3\":%llu,"
          "\"overdraw_moves\":%llu}\n",
          set.cluster_count, set.component_count, cpca::cluster_method_name(set.method),
          cpca::pca_solver_name(set.solver), set.alpha, set.overdraw_reduction ? "true" : "false",
          report.lbg_iterations, report.cpca_iterations, report.splits, report.lbg_seconds,
          report.pca_seconds, report.cpca_seconds, report.overdraw_seconds,
          report.clustering_seconds(), report.total_seconds, report.error.average_squared_error,
          report.error.relative_error, report.error.max_squared_error, report.size.ratio,
          file_bytes, (unsigned long long)s.one, (unsigned long long)s.two,
          (unsigned long long)s.three, (unsigned long long)report.overdraw.moves);
      return;
    }
    std::printf("compressed %s -> %s\n", o.transfer.c_str(), o.output.c_str());
    std::printf("  clusters %d x %d PCs, %s, PCA by %s, alpha %g%s\n", set.cluster_count,
                set.component_count, cpca::cluster_method_name(set.method),
                cpca::pca_solver_name(set.solver), set.alpha,
                set.overdraw_reduction ? ", overdraw reduction" : "");
    std::printf("  LBG        %d iterations, %d null clusters split, %.2f s\n",
                report.lbg_iterations, report.splits, report.lbg_seconds);
    if (set.method == cpca::ClusterMethod::kIterative)
      std::printf("  iterative  %d iterations, %.2f s\n", report.cpca_iterations,
                  report.cpca_seconds);
    std::printf("  PCA        %.2f s (%d power iterations)\n", report.pca_seconds,
                report.power_iterations);
    if (set.overdraw_reduction)
      std::printf("  overdraw   %llu vertices moved in %d sweeps, %.2f s\n",
                  (unsigned long long)report.overdraw.moves, report.overdraw.sweeps,
                  report.overdraw_seconds);
    std::printf("  time       %.2f s clustering, %.2f s in all\n", report.clustering_seconds(),
                report.total_seconds);
    std::printf("  error      Average SE %.6g, relative %.4e, worst vertex %.6g\n",
                report.error.average_squared_error, report.error.relative_error,
                report.error.max_squared_error);
    std::printf("  size       %.2fx by the thesis formula; %s -> %s on disk (%.1fx)\n",
                report.size.ratio, format_bytes(std::uint64_t(raw_bytes)).c_str(),
                format_bytes(std::uint64_t(file_bytes)).c_str(), raw_bytes / file_bytes);
    std::printf("  triangles  %.2f%% in 1 cluster, %.2f%% in 2, %.2f%% in 3 (%llu multi-cluster)\n",
                100.0 * double(s.one) / triangles, 100.0 * double(s.two) / triangles,
                100.0 * double(s.three) / triangles, (unsigned long long)s.multi());
  };
}

}  // namespace prtr_app
