// prtr compress TRANSFER --mesh MESH -o FILE: clustered PCA of a bake (LBG or iterative CPCA,
// optional geometry coherence and overdraw-aware reassignment), with a one-screen report.
#include "commands.h"
#include "common/json.h"
#include "compress_flags.h"
#include "flag_checks.h"
#include "mesh_flags.h"
#include "mpi_world.h"

#include "cpca/compress.h"
#include "cpca/compressed_file.h"
#include "meshes/load.h"
#include "pipeline/pipeline.h"
#include "progress_bar.h"
#include "prt/mapped_transfer.h"
#include "prt/transfer_file.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>

namespace prtr_app {
using common::dump_json;
using common::Json;
// Named rather than anonymous: a unity build compiles every command in one unit.
namespace cmd_compress {

struct Options {
  std::string transfer, mesh, output;
  CompressFlags compress;
  MeshFlags mesh_flags;
  bool quiet = false, json = false;
  std::uint64_t block_vertices = 0;  // 0: as many as fit kDefaultBlockBytes
};

// Out of core: the .prtx is mapped, and every pass over it holds one block of rows.
constexpr std::uint64_t kDefaultBlockBytes = std::uint64_t(64) << 20;

Eigen::Index block_rows(const prt::TransferSet& header, std::uint64_t flag) {
  if (flag > 0) return Eigen::Index(flag);
  const std::uint64_t row = std::max<std::uint64_t>(1, header.floats_per_vertex() * 4);
  return Eigen::Index(std::max<std::uint64_t>(1, kDefaultBlockBytes / row));
}

// What the report prints besides the set and the compression's own report.
struct Sizes {
  double raw_bytes = 0, file_bytes = 0, triangles = 0;
};

void check_sizes(const cpca::CompressOptions& c, const Options& o) {
  const prt::TransferSet header = prt::read_transfer_header(o.transfer);
  const std::size_t dimension = header.floats_per_vertex();
  if (std::uint64_t(c.clusters) > header.vertex_count)
    throw UsageError("--clusters " + std::to_string(c.clusters) + " exceeds the " +
                     std::to_string(header.vertex_count) + " vertices of " + o.transfer +
                     "; use at most that many");
  if (std::size_t(c.components) >= dimension)
    throw UsageError("--pcs " + std::to_string(c.components) +
                     " must be below the data dimension " + std::to_string(dimension) + " of " +
                     o.transfer);
}

void print_json(const cpca::CompressedSet& set, const cpca::CompressReport& report,
                const Sizes& sizes) {
  const cpca::TriangleSpan& s = report.span;
  const Json line = {{"clusters", set.cluster_count},
                     {"pcs", set.component_count},
                     {"method", cpca::kClusterMethodNames.name(set.method)},
                     {"pca", cpca::kPcaSolverNames.name(set.solver)},
                     {"alpha", set.alpha},
                     {"overdraw_reduction", set.overdraw_reduction},
                     {"lbg_iterations", report.lbg_iterations},
                     {"cpca_iterations", report.cpca_iterations},
                     {"splits", report.splits},
                     {"lbg_seconds", report.lbg_seconds},
                     {"pca_seconds", report.pca_seconds},
                     {"cpca_seconds", report.cpca_seconds},
                     {"overdraw_seconds", report.overdraw_seconds},
                     {"clustering_seconds", report.clustering_seconds()},
                     {"total_seconds", report.total_seconds},
                     {"average_se", report.error.average_squared_error},
                     {"relative_error", report.error.relative_error},
                     {"max_se", report.error.max_squared_error},
                     {"ratio", report.size.ratio},
                     {"file_bytes", std::uint64_t(sizes.file_bytes)},
                     {"triangles_1", std::uint64_t(s.one)},
                     {"triangles_2", std::uint64_t(s.two)},
                     {"triangles_3", std::uint64_t(s.three)},
                     {"overdraw_moves", std::uint64_t(report.overdraw.moves)}};
  std::printf("%s\n", dump_json(line).c_str());
}

void print_text(const Options& o, const cpca::CompressedSet& set,
                const cpca::CompressReport& report, const Sizes& sizes) {
  const cpca::TriangleSpan& s = report.span;
  std::printf("compressed %s -> %s\n", o.transfer.c_str(), o.output.c_str());
  std::printf("  clusters %d x %d PCs, %s, PCA by %s, alpha %g%s\n", set.cluster_count,
              set.component_count, cpca::kClusterMethodNames.name(set.method),
              cpca::kPcaSolverNames.name(set.solver), set.alpha,
              set.overdraw_reduction ? ", overdraw reduction" : "");
  std::printf("  LBG        %d iterations, %d null clusters split, %.2f s\n", report.lbg_iterations,
              report.splits, report.lbg_seconds);
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
              report.size.ratio, format_bytes(std::uint64_t(sizes.raw_bytes)).c_str(),
              format_bytes(std::uint64_t(sizes.file_bytes)).c_str(),
              sizes.raw_bytes / sizes.file_bytes);
  const double t = sizes.triangles;
  std::printf("  triangles  %.2f%% in 1 cluster, %.2f%% in 2, %.2f%% in 3 (%llu multi-cluster)\n",
              100.0 * double(s.one) / t, 100.0 * double(s.two) / t, 100.0 * double(s.three) / t,
              (unsigned long long)s.multi());
}

void print_report(const Options& o, const cpca::CompressedSet& set,
                  const cpca::CompressReport& report, const prt::TransferSet& transfer,
                  const meshes::Mesh& mesh) {
  const Sizes sizes{double(transfer.vertex_count) * double(transfer.floats_per_vertex()) * 4.0,
                    double(std::filesystem::file_size(o.output)), double(mesh.triangle_count())};
  if (o.json)
    print_json(set, report, sizes);
  else
    print_text(o, set, report, sizes);
}

// The mapped payload as rows in blocks, each block's pages released after a pass; scattered
// rows (a cluster's members) are read, not mapped.
cpca::RowBlocks row_blocks(const prt::MappedTransfer& mapped, std::uint64_t block_vertices) {
  const prt::TransferSet& transfer = mapped.header();
  const Eigen::Map<const cpca::DataMatrix> rows(mapped.payload(),
                                                Eigen::Index(transfer.vertex_count),
                                                Eigen::Index(transfer.floats_per_vertex()));
  return cpca::RowBlocks(
      rows, block_rows(transfer, block_vertices),
      [&mapped](Eigen::Index first, Eigen::Index count) {
        mapped.release(std::uint64_t(first), std::uint64_t(count));
      },
      [&mapped](const std::uint32_t* which, Eigen::Index count, float* out) {
        mapped.read_rows(which, std::size_t(count), out);
      });
}

// Under mpirun: every rank maps the .prtx and runs its share of LBG and the PCA
// (cpca/distribution.h); rank 0 writes the file (atomically) and the report. A rank that
// fails ends the job, so nothing appears at the output.
void mpi_compress(const Options& o, const cpca::CompressOptions& options) {
  if (options.method != cpca::ClusterMethod::kLbg || options.alpha > 0 ||
      options.overdraw_reduction)
    throw UsageError(
        "mpirun prtr compress runs --method lbg with --alpha 0 and no "
        "--overdraw-reduction; run other methods in one process");
  const MpiCoreShare cores;
  const std::unique_ptr<cpca::Distribution> dist = mpi_distribution();
  const bool root = dist->first();
  try {
    const meshes::Mesh mesh = meshes::load_mesh(o.mesh, load_options(o.mesh_flags));
    const prt::MappedTransfer mapped(o.transfer);
    const prt::TransferSet& transfer = mapped.header();
    const cpca::RowBlocks blocks = row_blocks(mapped, o.block_vertices);
    cpca::CompressReport report;
    const cpca::CompressedSet set =
        pipeline::run_compress(transfer, blocks, mesh, o.mesh, options,
                               stderr_reporter(o.quiet || o.json || !root), &report, dist.get());
    if (root) {
      cpca::write_compressed(o.output, set);
      print_report(o, set, report, transfer, mesh);
    }
  } catch (const std::exception& e) {
    mpi_abort(std::string("compress failed: ") + e.what());
  }
  mpi_barrier();
}

}  // namespace cmd_compress

Runner add_compress_command(CLI::App& app) {
  using namespace cmd_compress;
  auto opt = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "compress", "Compress a bake with clustered PCA (CPCA) into a .prtc file for rendering");
  cmd->add_option("TRANSFER", opt->transfer, "Transfer file from prtr bake (.prtx)")->required();
  cmd->add_option("--mesh", opt->mesh, "The mesh that was baked (checked against the bake)")
      ->required();
  cmd->add_option("-o,--output", opt->output, "Compressed file to write (.prtc)")->required();
  add_compress_flags(cmd, opt->compress, CompressFlagSet::kCompress);
  add_mesh_flags(cmd, opt->mesh_flags);
  cmd->add_flag("--json", opt->json, "Print the report as one JSON line instead");
  cmd->add_flag("-q,--quiet", opt->quiet, "No progress bar");
  cmd->add_option("--block-vertices", opt->block_vertices,
                  "Vertices per block of the out-of-core passes (0: 64 MiB of rows; rounded "
                  "up to a multiple of 256); the result does not depend on it")
      ->check(integer_in(0, 1LL << 40))
      ->capture_default_str();

  return [opt] {
    const Options& o = *opt;
    check_outputs({{"-o", o.output}}, {{"TRANSFER", o.transfer}, {"--mesh", o.mesh}});
    const cpca::CompressOptions options = resolve_compress_flags(o.compress);
    check_sizes(options, o);
    if (mpi_world().size > 1) return mpi_compress(o, options);
    const meshes::Mesh mesh = meshes::load_mesh(o.mesh, load_options(o.mesh_flags));
    const prt::MappedTransfer mapped(o.transfer);
    const prt::TransferSet& transfer = mapped.header();
    const cpca::RowBlocks blocks = row_blocks(mapped, o.block_vertices);
    cpca::CompressReport report;
    const cpca::CompressedSet set = pipeline::run_compress(
        transfer, blocks, mesh, o.mesh, options, stderr_reporter(o.quiet || o.json), &report);
    cpca::write_compressed(o.output, set);
    print_report(o, set, report, transfer, mesh);
  };
}

}  // namespace prtr_app
