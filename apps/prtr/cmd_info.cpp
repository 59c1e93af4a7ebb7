// prtr info FILE [--mesh MESH] [--transfer TRANSFER] [--verify]: describe a transfer file
// (.prtx) or a compressed file (.prtc), told apart by their magic, and say whether the file
// is stale against the mesh (or, for a compressed file, the bake) it was made from. Exit 1
// when stale, so scripts and caches can test it.
#include "commands.h"

#include "cpca/compressed_file.h"
#include "cpca/metrics.h"
#include "meshes/load.h"
#include "progress_bar.h"
#include "prt/transfer_file.h"

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

namespace prtr_app {
// Named rather than anonymous: a unity build compiles every command in one unit.
namespace cmd_info {

enum class FileKind { kTransfer, kCompressed };

// The first 8 bytes decide (docs/FORMATS.md: "PRTRXFER", "PRTRCMPR"). A file too short or
// unreadable to have a magic goes to the reader its extension suggests, whose message then
// says what is wrong with it (missing, a directory, truncated, ...).
FileKind detect_kind(const std::string& path) {
  char magic[8] = {};
  std::ifstream in(path, std::ios::binary);
  if (in && std::filesystem::is_regular_file(path)) {
    in.read(magic, sizeof magic);
    if (in.gcount() == sizeof magic) {
      if (std::memcmp(magic, "PRTRXFER", 8) == 0) return FileKind::kTransfer;
      if (std::memcmp(magic, "PRTRCMPR", 8) == 0) return FileKind::kCompressed;
      std::string start;
      for (char c : magic) start += (c >= 0x20 && c < 0x7f) ? c : '.';
      throw std::runtime_error(path + ": neither a transfer file (.prtx) nor a compressed file " +
                               "(.prtc): it starts with \"" + start +
                               "\"; name a file written by prtr bake or prtr compress");
    }
  }
  return std::filesystem::path(path).extension() == ".prtc" ? FileKind::kCompressed
                                                            : FileKind::kTransfer;
}

void print_status(bool current, const std::string& against) {
  std::printf("status      %s against %s\n", current ? "current" : "STALE", against.c_str());
}

// True when `mesh_path` still has the content (and vertex count) the file was made from.
bool mesh_is_current(const std::string& mesh_path, std::uint64_t mesh_hash,
                     std::uint64_t vertex_count) {
  const meshes::Mesh mesh = meshes::load_mesh(mesh_path);
  return meshes::content_hash(mesh) == mesh_hash && mesh.vertex_count() == vertex_count;
}

void describe_transfer(const std::string& path, const std::string& mesh, bool verify) {
  const prt::TransferSet set = verify ? prt::read_transfer(path) : prt::read_transfer_header(path);
  const prt::Material& m = set.material;
  std::printf("file        %s (%s)\n", path.c_str(),
              format_bytes(std::filesystem::file_size(path)).c_str());
  std::printf("transfer    %s, order %d (%d coefficients), %d channel(s)\n",
              prt::kTransferKindNames.name(set.kind), set.order, set.coefficient_count(),
              set.channels);
  std::printf("vertices    %llu\n", static_cast<unsigned long long>(set.vertex_count));
  std::printf("bake        %d samples, %d bounce(s), seed %llu\n", set.samples, set.bounces,
              static_cast<unsigned long long>(set.seed));
  std::printf(
      "material    %s, albedo (%g, %g, %g), specular %g, exponent %g, roughness %g, "
      "f0 %g, masking %s\n",
      prt::kMaterialNames.name(m.kind), m.albedo.x(), m.albedo.y(), m.albedo.z(), m.specular,
      m.exponent, m.roughness, m.f0, prt::kMaskingNames.name(m.masking));
  if (set.kind == prt::TransferKind::kGlossy)
    std::printf("view fit    %s\n", prt::kViewFitNames.name(set.view_fit));
  std::printf("mesh hash   %016llx\n", static_cast<unsigned long long>(set.mesh_hash));
  if (verify) std::printf("payload     checksum and values verified\n");
  if (!mesh.empty()) {
    const bool current = mesh_is_current(mesh, set.mesh_hash, set.vertex_count);
    print_status(current, mesh);
    if (!current) {
      throw std::runtime_error(path + " was baked from a different mesh than " + mesh +
                               "; bake it again with prtr bake");
    }
  }
}

void describe_compressed(const std::string& path, const std::string& mesh,
                         const std::string& transfer, bool verify) {
  const cpca::CompressedSet set =
      verify ? cpca::read_compressed(path) : cpca::read_compressed_header(path);
  const std::uint64_t file_bytes = std::filesystem::file_size(path);
  const auto u = [](std::uint64_t v) { return static_cast<unsigned long long>(v); };
  std::printf("file        %s (%s)\n", path.c_str(), format_bytes(file_bytes).c_str());
  std::printf(
      "compressed  clustered PCA of %s transfer, order %d (%d coefficients), %d channel(s)\n",
      set.glossy() ? "glossy" : "diffuse", set.order, set.coefficient_count(), set.channels);
  std::printf("dimension   %llu floats per vertex\n", u(set.dimension()));
  std::printf("vertices    %llu\n", u(set.vertex_count));
  std::printf("clusters    %d, %d PCs each\n", set.cluster_count, set.component_count);
  std::printf("clustering  %s, PCA solver %s, alpha %g, overdraw reduction %s\n",
              cpca::kClusterMethodNames.name(set.method), cpca::kPcaSolverNames.name(set.solver),
              set.alpha, set.overdraw_reduction ? "on" : "off");
  std::printf("run         seed %llu, %d iteration(s)\n", u(set.seed), set.iterations);
  std::printf("mesh        %s\n", set.mesh_path.empty() ? "(not recorded)" : set.mesh_path.c_str());
  std::printf("mesh hash   %016llx\n", u(set.mesh_hash));
  std::printf("transfer    hash %016llx\n", u(set.transfer_hash));

  // Numbers as the thesis counts them (ch. 3.1.3), then bytes: the raw bake's payload
  // against this file.
  const cpca::SizeMetrics s =
      cpca::size_metrics(set.vertex_count, set.dimension(), std::uint64_t(set.cluster_count),
                         std::uint64_t(set.component_count));
  std::printf("size        %llu numbers raw, %llu compressed: ratio %.2f (thesis formula)\n",
              u(s.raw_numbers), u(s.compressed_numbers), s.ratio);
  std::printf("bytes       %s raw float32, %s this file (ratio %.2f, with cluster ids)\n",
              format_bytes(4 * s.raw_numbers).c_str(), format_bytes(file_bytes).c_str(),
              double(4 * s.raw_numbers) / double(file_bytes));
  if (verify) std::printf("payload     checksums, cluster ids and values verified\n");

  std::string stale;  // what is stale, for the error after all statuses are printed
  if (!mesh.empty()) {
    const bool current = mesh_is_current(mesh, set.mesh_hash, set.vertex_count);
    print_status(current, mesh);
    if (!current) {
      stale = path + " was made from a different mesh than " + mesh +
              "; bake it again with prtr bake, then compress with prtr compress";
    }
  }
  if (!transfer.empty()) {
    const prt::TransferSet t = prt::read_transfer_header(transfer);
    const bool current = t.payload_checksum == set.transfer_hash && t.mesh_hash == set.mesh_hash &&
                         t.vertex_count == set.vertex_count && t.order == set.order &&
                         t.channels == set.channels && t.columns() == set.columns;
    print_status(current, transfer);
    if (!current && stale.empty()) {
      stale = path + " was compressed from a different bake than " + transfer +
              "; compress it again with prtr compress";
    }
  }
  if (!stale.empty()) throw std::runtime_error(stale);
}

}  // namespace cmd_info

Runner add_info_command(CLI::App& app) {
  using namespace cmd_info;
  struct Options {
    std::string path, mesh, transfer;
    bool verify = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* cmd =
      app.add_subcommand("info", "Describe a transfer (.prtx) or compressed (.prtc) file");
  cmd->add_option("FILE", opt->path, "Transfer or compressed file")->required();
  cmd->add_option("--mesh", opt->mesh, "Check the file against this mesh (stale or current)");
  cmd->add_option("--transfer", opt->transfer,
                  "Check a compressed file against this transfer file (stale or current)");
  cmd->add_flag("--verify", opt->verify,
                "Also read the payload and check its checksums and values");

  return [opt] {
    if (detect_kind(opt->path) == FileKind::kCompressed) {
      describe_compressed(opt->path, opt->mesh, opt->transfer, opt->verify);
      return;
    }
    if (!opt->transfer.empty()) {
      throw UsageError("--transfer applies to compressed files (.prtc), and " + opt->path +
                       " is a transfer file; use --mesh to check a bake");
    }
    describe_transfer(opt->path, opt->mesh, opt->verify);
  };
}

}  // namespace prtr_app
