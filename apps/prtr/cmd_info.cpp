// prtr info FILE [--mesh MESH] [--transfer TRANSFER] [--verify] [--json]: describe a transfer
// file (.prtx), a compressed file (.prtc), a surface light field's bake (.slf) or its
// compressed file (.slfc), told apart by their magic, and say whether the file is stale
// against the mesh (or, for a compressed file, the bake) it was made from. Exit 1 when stale,
// so scripts and caches can test it; --json prints the same as one JSON object.
#include "commands.h"
#include "common/json.h"

#include "cpca/compressed_file.h"
#include "cpca/metrics.h"
#include "meshes/load.h"
#include "pipeline/slf_file.h"
#include "progress_bar.h"
#include "prt/slf_bake.h"
#include "prt/transfer_file.h"

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

namespace prtr_app {
using common::dump_json;
using common::Json;
// Named rather than anonymous: a unity build compiles every command in one unit.
namespace cmd_info {

enum class FileKind { kTransfer, kCompressed, kSlf, kSlfc };

// The first 8 bytes decide (docs/FORMATS.md: "PRTRXFER", "PRTRCMPR"; prt/slf_bake.h
// "PRTRSLFM", pipeline/slf_file.h "PRTRSLFC"). A file too short or unreadable to have a magic
// goes to the reader its extension suggests, whose message then says what is wrong with it
// (missing, a directory, truncated, ...).
FileKind detect_kind(const std::string& path) {
  char magic[8] = {};
  std::ifstream in(path, std::ios::binary);
  if (in && std::filesystem::is_regular_file(path)) {
    in.read(magic, sizeof magic);
    if (in.gcount() == sizeof magic) {
      if (std::memcmp(magic, "PRTRXFER", 8) == 0) return FileKind::kTransfer;
      if (std::memcmp(magic, "PRTRCMPR", 8) == 0) return FileKind::kCompressed;
      if (std::memcmp(magic, "PRTRSLFM", 8) == 0) return FileKind::kSlf;
      if (std::memcmp(magic, "PRTRSLFC", 8) == 0) return FileKind::kSlfc;
      std::string start;
      for (char c : magic) start += (c >= 0x20 && c < 0x7f) ? c : '.';
      std::string message = path;
      message += ": neither a transfer file (.prtx), a compressed file (.prtc) nor a surface ";
      message += "light field (.slf, .slfc): it starts with \"";
      message += start;
      message += "\"; name a file written by prtr bake, prtr compress or prtr slf";
      throw std::runtime_error(message);
    }
  }
  const std::filesystem::path extension = std::filesystem::path(path).extension();
  if (extension == ".prtc") return FileKind::kCompressed;
  if (extension == ".slf") return FileKind::kSlf;
  if (extension == ".slfc") return FileKind::kSlfc;
  return FileKind::kTransfer;
}

unsigned long long u(std::uint64_t v) {
  return static_cast<unsigned long long>(v);
}

std::string hex16(std::uint64_t h) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", u(h));
  return buf;
}

Json material_json(const prt::Material& m) {
  return Json{{"kind", prt::kMaterialNames.name(m.kind)},
              {"albedo", {m.albedo.x(), m.albedo.y(), m.albedo.z()}},
              {"specular", m.specular},
              {"exponent", m.exponent},
              {"roughness", m.roughness},
              {"f0", m.f0},
              {"masking", prt::kMaskingNames.name(m.masking)}};
}

void print_material(const prt::Material& m) {
  std::printf(
      "material    %s, albedo (%g, %g, %g), specular %g, exponent %g, roughness %g, "
      "f0 %g, masking %s\n",
      prt::kMaterialNames.name(m.kind), m.albedo.x(), m.albedo.y(), m.albedo.z(), m.specular,
      m.exponent, m.roughness, m.f0, prt::kMaskingNames.name(m.masking));
}

// What FILE was checked against (--mesh, --transfer) and whether it is current: printed
// after the description, and in the JSON as "checks".
struct Checks {
  Json json = Json::array();
  std::string stale;  // the first stale check's error, thrown once everything is printed

  void add(bool current, const std::string& against, const std::string& error) {
    json.push_back(Json{{"against", against}, {"status", current ? "current" : "stale"}});
    if (!current && stale.empty()) stale = error;
  }
  void print() const {
    for (const Json& c : json)
      std::printf("status      %s against %s\n", c["status"] == "current" ? "current" : "STALE",
                  c["against"].get<std::string>().c_str());
  }
};

// Prints the JSON object (with the checks) or the checks after the text already printed,
// then reports a stale check as the failure it is.
void finish(bool json, Json j, const Checks& checks) {
  if (json) {
    j["checks"] = checks.json;
    std::printf("%s\n", dump_json(j).c_str());
  } else {
    checks.print();
  }
  if (!checks.stale.empty()) throw std::runtime_error(checks.stale);
}

// True when `mesh_path` still has the content (and vertex count) the file was made from.
bool mesh_is_current(const std::string& mesh_path, std::uint64_t mesh_hash,
                     std::uint64_t vertex_count) {
  const meshes::Mesh mesh = meshes::load_mesh(mesh_path);
  return meshes::content_hash(mesh) == mesh_hash && mesh.vertex_count() == vertex_count;
}

void describe_transfer(const std::string& path, const std::string& mesh, bool verify, bool json) {
  const prt::TransferSet set = verify ? prt::read_transfer(path) : prt::read_transfer_header(path);
  const prt::Material& m = set.material;
  const std::uint64_t file_bytes = std::filesystem::file_size(path);
  Checks checks;
  if (!mesh.empty())
    checks.add(
        mesh_is_current(mesh, set.mesh_hash, set.vertex_count), mesh,
        path + " was baked from a different mesh than " + mesh + "; bake it again with prtr bake");
  if (json) {
    Json j{{"file", path},
           {"format", "prtx"},
           {"bytes", file_bytes},
           {"transfer", prt::kTransferKindNames.name(set.kind)},
           {"order", set.order},
           {"coefficients", set.coefficient_count()},
           {"channels", set.channels},
           {"vertices", set.vertex_count},
           {"samples", set.samples},
           {"bounces", set.bounces},
           {"seed", set.seed},
           {"material", material_json(m)}};
    if (set.kind == prt::TransferKind::kGlossy)
      j["view_fit"] = prt::kViewFitNames.name(set.view_fit);
    j["mesh_hash"] = hex16(set.mesh_hash);
    j["verified"] = verify;
    return finish(true, j, checks);
  }
  std::printf("file        %s (%s)\n", path.c_str(), format_bytes(file_bytes).c_str());
  std::printf("transfer    %s, order %d (%d coefficients), %d channel(s)\n",
              prt::kTransferKindNames.name(set.kind), set.order, set.coefficient_count(),
              set.channels);
  std::printf("vertices    %llu\n", u(set.vertex_count));
  std::printf("bake        %d samples, %d bounce(s), seed %llu\n", set.samples, set.bounces,
              u(set.seed));
  print_material(m);
  if (set.kind == prt::TransferKind::kGlossy)
    std::printf("view fit    %s\n", prt::kViewFitNames.name(set.view_fit));
  std::printf("mesh hash   %016llx\n", u(set.mesh_hash));
  if (verify) std::printf("payload     checksum and values verified\n");
  finish(false, {}, checks);
}

void describe_compressed(const std::string& path, const std::string& mesh,
                         const std::string& transfer, bool verify, bool json) {
  const cpca::CompressedSet set =
      verify ? cpca::read_compressed(path) : cpca::read_compressed_header(path);
  const std::uint64_t file_bytes = std::filesystem::file_size(path);
  // Numbers as the thesis counts them (ch. 3.1.3), then bytes: the raw bake's payload
  // against this file.
  const cpca::SizeMetrics s =
      cpca::size_metrics(set.vertex_count, set.dimension(), std::uint64_t(set.cluster_count),
                         std::uint64_t(set.component_count));
  Checks checks;
  if (!mesh.empty())
    checks.add(mesh_is_current(mesh, set.mesh_hash, set.vertex_count), mesh,
               path + " was made from a different mesh than " + mesh +
                   "; bake it again with prtr bake, then compress with prtr compress");
  if (!transfer.empty()) {
    const prt::TransferSet t = prt::read_transfer_header(transfer);
    const bool current = t.payload_checksum == set.transfer_hash && t.mesh_hash == set.mesh_hash &&
                         t.vertex_count == set.vertex_count && t.order == set.order &&
                         t.channels == set.channels && t.columns() == set.columns;
    checks.add(current, transfer,
               path + " was compressed from a different bake than " + transfer +
                   "; compress it again with prtr compress");
  }
  if (json) {
    const Json j{{"file", path},
                 {"format", "prtc"},
                 {"bytes", file_bytes},
                 {"transfer", set.glossy() ? "glossy" : "diffuse"},
                 {"order", set.order},
                 {"coefficients", set.coefficient_count()},
                 {"channels", set.channels},
                 {"dimension", set.dimension()},
                 {"vertices", set.vertex_count},
                 {"clusters", set.cluster_count},
                 {"components", set.component_count},
                 {"clustering", cpca::kClusterMethodNames.name(set.method)},
                 {"pca_solver", cpca::kPcaSolverNames.name(set.solver)},
                 {"alpha", set.alpha},
                 {"overdraw_reduction", set.overdraw_reduction},
                 {"seed", set.seed},
                 {"iterations", set.iterations},
                 {"mesh", set.mesh_path},
                 {"mesh_hash", hex16(set.mesh_hash)},
                 {"transfer_hash", hex16(set.transfer_hash)},
                 {"raw_numbers", s.raw_numbers},
                 {"compressed_numbers", s.compressed_numbers},
                 {"compression_ratio", s.ratio},
                 {"verified", verify}};
    return finish(true, j, checks);
  }
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
  std::printf("size        %llu numbers raw, %llu compressed: ratio %.2f (thesis formula)\n",
              u(s.raw_numbers), u(s.compressed_numbers), s.ratio);
  std::printf("bytes       %s raw float32, %s this file (ratio %.2f, with cluster ids)\n",
              format_bytes(4 * s.raw_numbers).c_str(), format_bytes(file_bytes).c_str(),
              double(4 * s.raw_numbers) / double(file_bytes));
  if (verify) std::printf("payload     checksums, cluster ids and values verified\n");
  finish(false, {}, checks);
}

// The settings both SLF files record (prt/slf_bake.h), as JSON fields and as text lines.
void slf_shape_json(Json& j, const prt::SlfShape& b) {
  j["atlas_width"] = b.atlas_width;
  j["atlas_height"] = b.atlas_height;
  j["atlas_charts"] = meshes::kAtlasChartsNames.name(b.charts);
  j["directions_azimuth"] = b.grid.azimuth;
  j["directions_polar"] = b.grid.elevation;
  j["directions"] = b.grid.directions();
  j["direction_space"] = prt::kSlfDirectionSpaceNames.name(b.grid.space);
  j["columns"] = b.columns();
  j["rows"] = b.rows;
  j["first_row"] = b.first_row;
  j["rows_stored"] = b.row_count;
  j["spp"] = b.spp;
  j["bounces"] = b.bounces;
  j["light_samples"] = b.light_samples;
  j["bake_seed"] = b.seed;
  j["material"] = material_json(b.material);
  j["mesh_hash"] = hex16(b.mesh_hash);
  j["probe_hash"] = hex16(b.probe_hash);
}

void print_slf_shape(const prt::SlfShape& b) {
  std::printf("atlas       %d x %d texels, %s charts, %llu owned (the rows)\n", b.atlas_width,
              b.atlas_height, std::string(meshes::kAtlasChartsNames.name(b.charts)).c_str(),
              u(b.rows));
  std::printf("directions  %d x %d (azimuth x polar) %s: %d, x 3 channels = %llu floats per row\n",
              b.grid.azimuth, b.grid.elevation,
              b.grid.space == prt::SlfDirectionSpace::kView ? "views over the sphere"
              : b.grid.space == prt::SlfDirectionSpace::kReflected
                  ? "reflected views over the sphere"
                  : "views over each texel's hemisphere",
              b.grid.directions(), u(b.columns()));
  if (b.first_row == 0 && b.row_count == b.rows)
    std::printf("rows        %llu, all of the matrix\n", u(b.row_count));
  else
    std::printf("rows        %llu to %llu of %llu (a part)\n", u(b.first_row),
                u(b.first_row + b.row_count), u(b.rows));
  std::printf(
      "bake        %d spp, %d bounce(s), %d shared light samples a path, seed %llu (path "
      "traced)\n",
      b.spp, b.bounces, b.light_samples, u(b.seed));
  print_material(b.material);
}

// A surface light field's mesh is checked by content alone: its rows are atlas texels.
void check_slf_mesh(Checks& checks, const std::string& path, const std::string& mesh,
                    std::uint64_t mesh_hash) {
  if (mesh.empty()) return;
  checks.add(
      meshes::content_hash(meshes::load_mesh(mesh)) == mesh_hash, mesh,
      path + " was made from a different mesh than " + mesh + "; make it again with prtr slf");
}

void describe_slf(const std::string& path, const std::string& mesh, bool verify, bool json) {
  const prt::SlfShape b = verify ? prt::read_slf(path).shape : prt::read_slf_header(path);
  const std::uint64_t file_bytes = std::filesystem::file_size(path);
  Checks checks;
  check_slf_mesh(checks, path, mesh, b.mesh_hash);
  if (json) {
    Json j{{"file", path}, {"format", "slf"}, {"bytes", file_bytes}};
    slf_shape_json(j, b);
    j["verified"] = verify;
    return finish(true, j, checks);
  }
  std::printf("file        %s (%s)\n", path.c_str(), format_bytes(file_bytes).c_str());
  std::printf("slf         surface light field bake: exit radiance per texel and direction\n");
  print_slf_shape(b);
  std::printf("mesh hash   %016llx\n", u(b.mesh_hash));
  std::printf("probe hash  %016llx\n", u(b.probe_hash));
  if (verify) std::printf("payload     checksum and values verified\n");
  finish(false, {}, checks);
}

// read_slfc reads the whole file (it has no header-only reader), so the payload is always
// verified; the file is small next to its bake.
void describe_slfc(const std::string& path, const std::string& mesh, bool json) {
  const pipeline::CompressedSlf slf = pipeline::read_slfc(path);
  const prt::SlfShape& b = slf.bake;
  const cpca::CompressedSet& set = slf.set;
  const std::uint64_t file_bytes = std::filesystem::file_size(path);
  // The figures prtr slf reports (pipeline::SlfRun): V x D raw, V N + K (N + 1) D compressed.
  const cpca::SizeMetrics s =
      cpca::size_metrics(b.row_count, b.columns(), std::uint64_t(set.cluster_count),
                         std::uint64_t(set.component_count));
  Checks checks;
  check_slf_mesh(checks, path, mesh, b.mesh_hash);
  if (json) {
    Json j{{"file", path}, {"format", "slfc"}, {"bytes", file_bytes}};
    slf_shape_json(j, b);
    j["clusters"] = set.cluster_count;
    j["components"] = set.component_count;
    j["clustering"] = cpca::kClusterMethodNames.name(set.method);
    j["pca_solver"] = cpca::kPcaSolverNames.name(set.solver);
    j["compression_seed"] = set.seed;
    j["iterations"] = set.iterations;
    j["probe"] = slf.probe_name;
    j["mesh"] = slf.mesh_path;
    j["raw_floats"] = s.raw_numbers;
    j["compressed_floats"] = s.compressed_numbers;
    j["compression_ratio"] = s.ratio;
    j["complete"] = slf.complete();
    j["verified"] = true;
    return finish(true, j, checks);
  }
  std::printf("file        %s (%s)\n", path.c_str(), format_bytes(file_bytes).c_str());
  std::printf("slfc        compressed surface light field (clustered PCA of its bake)\n");
  print_slf_shape(b);
  std::printf("clusters    %d, %d PCs each\n", set.cluster_count, set.component_count);
  std::printf("clustering  %s, PCA solver %s, seed %llu, %d iteration(s)\n",
              cpca::kClusterMethodNames.name(set.method), cpca::kPcaSolverNames.name(set.solver),
              u(set.seed), set.iterations);
  std::printf("probe       %s (hash %016llx)\n", slf.probe_name.c_str(), u(b.probe_hash));
  std::printf("mesh        %s (hash %016llx)\n",
              slf.mesh_path.empty() ? "(not recorded)" : slf.mesh_path.c_str(), u(b.mesh_hash));
  std::printf("size        %llu floats raw, %llu compressed: ratio %.2f\n", u(s.raw_numbers),
              u(s.compressed_numbers), s.ratio);
  std::printf("bytes       %s raw float32, %s this file (ratio %.2f, with cluster ids)\n",
              format_bytes(4 * s.raw_numbers).c_str(), format_bytes(file_bytes).c_str(),
              double(4 * s.raw_numbers) / double(file_bytes));
  if (!slf.complete())
    std::printf("note        a part of the matrix (prtr slf --rows): prtr render refuses it\n");
  std::printf("payload     checksums, cluster ids and values verified\n");
  finish(false, {}, checks);
}

}  // namespace cmd_info

Runner add_info_command(CLI::App& app) {
  using namespace cmd_info;
  struct Options {
    std::string path, mesh, transfer;
    bool verify = false, json = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "info",
      "Describe a transfer (.prtx), compressed (.prtc) or surface light field (.slf, .slfc) file");
  cmd->add_option("FILE", opt->path, "Transfer, compressed or surface light field file")
      ->required();
  cmd->add_option("--mesh", opt->mesh, "Check the file against this mesh (stale or current)");
  cmd->add_option("--transfer", opt->transfer,
                  "Check a compressed file against this transfer file (stale or current)");
  cmd->add_flag("--verify", opt->verify,
                "Also read the payload and check its checksums and values (a .slfc always is)");
  cmd->add_flag("--json", opt->json, "Print the description as one JSON object");

  return [opt] {
    const Options& o = *opt;
    const FileKind kind = detect_kind(o.path);
    if (kind == FileKind::kCompressed)
      return describe_compressed(o.path, o.mesh, o.transfer, o.verify, o.json);
    if (!o.transfer.empty()) {
      throw UsageError("--transfer applies to compressed files (.prtc), and " + o.path +
                       " is not one; use --mesh to check it against its mesh");
    }
    switch (kind) {
      case FileKind::kSlf:
        return describe_slf(o.path, o.mesh, o.verify, o.json);
      case FileKind::kSlfc:
        return describe_slfc(o.path, o.mesh, o.json);
      default:
        return describe_transfer(o.path, o.mesh, o.verify, o.json);
    }
  };
}

}  // namespace prtr_app
