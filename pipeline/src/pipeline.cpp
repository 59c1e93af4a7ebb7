#include "pipeline/pipeline.h"

#include "common/atomic_file.h"
#include "common/format_bytes.h"
#include "common/hash.h"
#include "common/json.h"
#include "cpca/compressed_file.h"
#include "prt/transfer_file.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace pipeline {
using common::dump_json;
using common::Json;
namespace fs = std::filesystem;

cpca::Geometry geometry_of(const meshes::Mesh& mesh) {
  cpca::Geometry g;
  g.positions = mesh.positions;
  g.triangles.reserve(mesh.triangles.size());
  for (const meshes::Triangle& t : mesh.triangles) g.triangles.push_back({t[0], t[1], t[2]});
  return g;
}

prt::TransferSet run_bake(const meshes::Mesh& mesh, const std::string& mesh_name,
                          prt::BakeOptions options, const Reporter& reporter,
                          prt::BakeStats* stats) {
  const prt::BakeEstimate estimate = prt::estimate_bake(mesh, options);
  const std::uint64_t available = prt::available_memory();
  if (available > 0 && estimate.bytes > available) {
    throw std::runtime_error("baking " + mesh_name + " needs about " +
                             common::format_bytes(estimate.bytes) + " but only " +
                             common::format_bytes(available) +
                             " is available; lower --order or --samples, use --bounces 0, "
                             "or --kind diffuse");
  }
  char line[256];
  std::snprintf(line, sizeof line,
                "bake: %zu vertices, %s order %d, %d samples, %d bounce(s); about %s of "
                "memory, %.1f M shadow rays, roughly %.0f s",
                mesh.vertex_count(), prt::kTransferKindNames.name(options.kind), options.order,
                options.samples, options.bounces, common::format_bytes(estimate.bytes).c_str(),
                double(estimate.rays) / 1e6, estimate.seconds);
  reporter.tell(line);
  options.progress = [&reporter](const prt::BakeProgress& p) {
    reporter.report(p.pass == 0 ? "shadow pass" : "bounce " + std::to_string(p.pass), p.done,
                    p.total);
  };
  prt::TransferSet set = prt::bake(mesh, options, stats);
  reporter.end_step();
  return set;
}

cpca::CompressedSet run_compress(const prt::TransferSet& transfer, const meshes::Mesh& mesh,
                                 const std::string& mesh_path, cpca::CompressOptions options,
                                 const Reporter& reporter, cpca::CompressReport* report) {
  const Eigen::Map<const cpca::DataMatrix> data(transfer.data.data(),
                                                Eigen::Index(transfer.vertex_count),
                                                Eigen::Index(transfer.floats_per_vertex()));
  return run_compress(transfer, cpca::RowBlocks(data), mesh, mesh_path, options, reporter, report);
}

cpca::CompressedSet run_compress(const prt::TransferSet& transfer, const cpca::RowBlocks& data,
                                 const meshes::Mesh& mesh, const std::string& mesh_path,
                                 cpca::CompressOptions options, const Reporter& reporter,
                                 cpca::CompressReport* report, cpca::Distribution* distribution) {
  if (meshes::content_hash(mesh) != transfer.mesh_hash ||
      mesh.vertex_count() != transfer.vertex_count)
    throw std::runtime_error("the transfer was not baked from " + mesh_path +
                             " (mesh hash or vertex count differ); bake it again with prtr bake");
  const std::string absolute = fs::absolute(mesh_path).lexically_normal().string();
  if (absolute.size() > cpca::kMaxMeshPathBytes)
    throw std::runtime_error(mesh_path + ": path longer than " +
                             std::to_string(cpca::kMaxMeshPathBytes) +
                             " bytes; move the mesh to a shorter path");
  options.layout = {transfer.order, transfer.channels, transfer.columns()};
  const cpca::Geometry geometry = geometry_of(mesh);
  cpca::CompressedSet set = cpca::compress(
      data, options, &geometry, report,
      [&](const std::string& stage, double f) {
        reporter.report(stage == "lbg"    ? "LBG clustering"
                        : stage == "pca"  ? "PCA per cluster"
                        : stage == "cpca" ? "iterative CPCA"
                                          : "overdraw reduction",
                        std::uint64_t(f * 1000), 1000);
      },
      distribution);
  reporter.end_step();
  set.mesh_hash = transfer.mesh_hash;
  set.transfer_hash = transfer.payload_checksum;
  set.mesh_path = absolute;
  return set;
}

fs::path default_cache_dir() {
  if (const char* dir = std::getenv("PRTR_CACHE"); dir && *dir) return dir;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return fs::path(xdg) / "prtr";
  if (const char* home = std::getenv("HOME"); home && *home)
    return fs::path(home) / ".cache" / "prtr";
  return fs::path("prtr-cache");
}

namespace {

std::string hex(std::uint64_t h) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

std::uint64_t hash_text(const std::string& text) {
  return common::fnv1a(text.data(), text.size());
}

// The reference clustering patch-eps weighs its patches by ("none" when it computes its own,
// which then depends only on the rest of the key).
std::string reference_hash(const std::vector<std::uint32_t>& clusters) {
  if (clusters.empty()) return "none";
  return hex(common::fnv1a(clusters.data(), clusters.size() * sizeof(std::uint32_t)));
}

void prepare(const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec)
    throw std::runtime_error("cache directory " + dir.string() + " cannot be created (" +
                             ec.message() + "); pass --cache DIR or set PRTR_CACHE");
}

// A bake or compression killed mid-write leaves its temporary (up to the size of a whole
// bake) in the cache; nothing else would ever remove it.
void sweep(const fs::path& dir, const Reporter& reporter) {
  for (const fs::path& file : common::sweep_stale_temporaries(dir))
    reporter.warn("removed " + file.string() + ", left by an interrupted run");
}

// A compression's summary is one JSON object (see pipeline/pipeline.h). Anything else -- a missing
// file, text that does not parse, a missing key, a value that is not a finite number -- is damage.
CompressionSummary read_summary(const fs::path& path) {
  const auto damaged = [&](const std::string& why) {
    return std::runtime_error("its summary " + path.string() + " is missing or damaged (" + why +
                              ")");
  };
  std::ifstream in(path, std::ios::binary);
  if (!in) throw damaged("cannot be opened");
  const Json json = Json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (!json.is_object()) throw damaged("not a JSON object");
  const auto number = [&](const char* key) {
    const auto it = json.find(key);
    if (it == json.end() || !it->is_number() || !std::isfinite(it->get<double>())) {
      throw damaged(std::string("no finite number '") + key + "'");
    }
    return it->get<double>();
  };
  return {number("clustering_seconds"), number("average_se"), number("relative_error")};
}

void write_summary(const fs::path& path, const CompressionSummary& s) {
  Json json;
  json["clustering_seconds"] = s.clustering_seconds;
  json["average_se"] = s.average_se;
  json["relative_error"] = s.relative_error;
  const std::string text = dump_json(json) + "\n";
  common::write_file_atomically(path, text.data(), text.size());
}

void discard(const fs::path& entry, const std::exception& why, const Reporter& reporter) {
  reporter.warn("cache entry " + entry.string() + " is unusable (" + why.what() +
                "); removing and rebuilding it");
  std::error_code ec;
  fs::remove(entry, ec);
}

// The first setting a cached bake's header disagrees with, or "".
std::string header_mismatch(const prt::TransferSet& t, const prt::BakeOptions& o) {
  const prt::Material& a = t.material;
  const prt::Material& b = o.material;
  if (t.kind != o.kind) return std::string("kind ") + prt::kTransferKindNames.name(t.kind);
  if (t.order != o.order) return "order " + std::to_string(t.order);
  if (t.samples != o.samples) return std::to_string(t.samples) + " samples";
  if (t.bounces != o.bounces) return std::to_string(t.bounces) + " bounces";
  if (t.seed != o.seed) return "seed " + std::to_string(t.seed);
  if (t.kind == prt::TransferKind::kGlossy && t.view_fit != o.view_fit)
    return std::string("view fit ") + prt::kViewFitNames.name(t.view_fit);
  if (a.kind != b.kind || a.albedo != b.albedo || a.specular != b.specular ||
      a.exponent != b.exponent || a.roughness != b.roughness || a.f0 != b.f0 ||
      a.masking != b.masking)
    return std::string("another material (") + prt::kMaterialNames.name(a.kind) + ")";
  return {};
}

}  // namespace

CacheResult cached_bake(const meshes::Mesh& mesh, const std::string& mesh_name,
                        const prt::BakeOptions& o, const fs::path& cache_dir,
                        const Reporter& reporter, BakeCheck check) {
  std::ostringstream key;
  key.precision(9);
  const prt::Material& m = o.material;
  // The version names the baker's algorithm: bump it whenever the same inputs bake to other
  // numbers (v2: rays start on the face they leave through; v3: the view fit, Smith masking
  // and views clamped to the horizon), so old entries are not reused. The mesh hash covers
  // positions and triangles only; the normals (a file's own, or split at creases) go in too,
  // since the same positions bake to other numbers under other normals (v4).
  const std::uint64_t normals_hash =
      common::fnv1a(mesh.normals.data(), mesh.normals.size() * sizeof(meshes::Vec3));
  key << "bake v4 mesh " << hex(meshes::content_hash(mesh)) << " normals " << hex(normals_hash)
      << " kind " << int(o.kind) << " order " << o.order << " samples " << o.samples << " bounces "
      << o.bounces << " seed " << o.seed << " ray_offset " << o.ray_offset << " material "
      << int(m.kind) << ' ' << m.albedo.x() << ' ' << m.albedo.y() << ' ' << m.albedo.z() << ' '
      << m.specular << ' ' << m.exponent << ' ' << m.roughness << ' ' << m.f0 << " masking "
      << int(m.masking) << " view " << int(o.view_fit);
  CacheResult r{cache_dir / ("bake-" + hex(hash_text(key.str())) + ".prtx"), false};
  sweep(cache_dir, reporter);
  if (fs::exists(r.path)) {
    try {
      // With kPayload the whole file, checksum included: a header check alone let a damaged
      // payload through to every later run that reads it.
      const prt::TransferSet entry = check == BakeCheck::kPayload
                                         ? prt::read_transfer(r.path)
                                         : prt::read_transfer_header(r.path);
      if (entry.mesh_hash != meshes::content_hash(mesh))
        throw std::runtime_error("baked from another mesh");
      // The name is a hash of the settings, but a file copied or left over under that name
      // must not stand in for them: its header has to say the same.
      if (const std::string differs = header_mismatch(entry, o); !differs.empty())
        throw std::runtime_error("its header says " + differs + ", not what this bake asks for");
      r.hit = true;
      return r;
    } catch (const std::exception& e) {
      discard(r.path, e, reporter);
    }
  }
  prepare(cache_dir);
  prt::write_transfer(r.path, run_bake(mesh, mesh_name, o, reporter));
  return r;
}

CompressCacheResult cached_compress(const fs::path& transfer_path, const meshes::Mesh& mesh,
                                    const std::string& mesh_path, const cpca::CompressOptions& o,
                                    const fs::path& cache_dir, const Reporter& reporter,
                                    bool rebuild) {
  sweep(cache_dir, reporter);
  const prt::TransferSet header = prt::read_transfer_header(transfer_path);
  std::ostringstream key;
  key.precision(9);
  key << "cpca v1 transfer " << hex(header.payload_checksum) << " mesh "
      << fs::absolute(mesh_path).lexically_normal().string() << " clusters " << o.clusters
      << " pcs " << o.components << " method " << int(o.method) << " solver " << int(o.solver)
      << " alpha " << o.alpha << " overdraw " << o.overdraw_reduction << ' ' << o.overdraw.tolerance
      << ' ' << o.overdraw.max_sweeps << " seed " << o.seed << " lbg " << o.lbg_threshold << ' '
      << o.lbg_max_iterations << " cpca " << o.cpca_threshold << ' ' << o.cpca_max_iterations << ' '
      << o.cpca_candidates;
  // Only the pass-designing methods read these; other keys stay as they were.
  if (o.method == cpca::ClusterMethod::kPatchFirst || o.method == cpca::ClusterMethod::kJoint ||
      o.method == cpca::ClusterMethod::kPatchJoint)
    key << " per-pass " << o.clusters_per_pass << " lambda " << o.lambda;
  if (o.method == cpca::ClusterMethod::kPatchEpsilon)
    key << " per-pass " << o.clusters_per_pass << " eps " << o.error_slack << " target "
        << o.error_target << " density " << reference_hash(o.reference_clusters)
        << " border-cuts bounded";  // the search with border cuts gives other clusters
  if (o.overdraw_cap > 0) key << " cap " << o.overdraw_cap;
  const std::string stem = "cpca-" + hex(hash_text(key.str()));
  CompressCacheResult r;
  r.path = cache_dir / (stem + ".prtc");
  // The compression's own measurements, which a cached set cannot reproduce.
  const fs::path summary = cache_dir / (stem + ".summary");
  if (!rebuild && fs::exists(r.path)) {
    try {
      // The whole file, for the same reason as the bake's.
      const cpca::CompressedSet set = cpca::read_compressed(r.path);
      if (set.transfer_hash != header.payload_checksum)
        throw std::runtime_error("compressed from another bake");
      r.summary = read_summary(summary);
      r.hit = true;
      return r;
    } catch (const std::exception& e) {
      discard(r.path, e, reporter);
    }
  }
  prepare(cache_dir);
  const prt::TransferSet transfer = prt::read_transfer(transfer_path);
  cpca::CompressReport report;
  cpca::write_compressed(r.path, run_compress(transfer, mesh, mesh_path, o, reporter, &report));
  r.summary = {report.clustering_seconds(), report.error.average_squared_error,
               report.error.relative_error};
  write_summary(summary, r.summary);
  return r;
}

CachedPair cached_bake_and_compress(const meshes::Mesh& mesh, const std::string& mesh_path,
                                    const prt::BakeOptions& bake,
                                    const cpca::CompressOptions& compress,
                                    const fs::path& cache_dir, const Reporter& reporter) {
  using Clock = std::chrono::steady_clock;
  const auto since = [](Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
  };
  CachedPair r;
  auto start = Clock::now();
  r.transfer = cached_bake(mesh, mesh_path, bake, cache_dir, reporter, BakeCheck::kHeader);
  r.bake_seconds = since(start);
  start = Clock::now();
  try {
    r.compressed = cached_compress(r.transfer.path, mesh, mesh_path, compress, cache_dir, reporter);
    r.compress_seconds = since(start);
    return r;
  } catch (const prt::TransferFileError& e) {
    if (!r.transfer.hit) throw;  // just baked: not a damaged cache entry
    discard(r.transfer.path, e, reporter);
  }
  start = Clock::now();
  r.transfer = cached_bake(mesh, mesh_path, bake, cache_dir, reporter);
  r.bake_seconds += since(start);
  start = Clock::now();
  r.compressed = cached_compress(r.transfer.path, mesh, mesh_path, compress, cache_dir, reporter);
  r.compress_seconds = since(start);
  return r;
}

}  // namespace pipeline
