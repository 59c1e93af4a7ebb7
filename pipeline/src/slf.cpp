// The surface light field's pipeline (pipeline/slf.h).
#include "pipeline/slf.h"

#include "common/atomic_file.h"
#include "common/format_bytes.h"
#include "common/hash.h"
#include "meshes/atlas.h"
#include "pipeline/pipeline.h"
#include "prt/slf_filter.h"

#include <tbb/parallel_for.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace pipeline {
namespace {

namespace fs = std::filesystem;

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

template <class T>
void hash_value(std::uint64_t& h, const T& value) {
  h = common::fnv1a(&value, sizeof value, h);
}

std::uint64_t bake_key(const meshes::Mesh& mesh, const probes::Probe& probe, const SlfSettings& s) {
  std::uint64_t h = common::kFnvOffset;
  // The key's layout and the estimator's version (4: shared light samples' views from a
  // (0, 2)-sequence), so a bake by an older estimator is not reused.
  hash_value(h, std::uint32_t(4));
  hash_value(h, meshes::content_hash(mesh));
  hash_value(h, prt::probe_hash(probe));
  const prt::SlfBakeOptions& o = s.bake;
  for (std::int64_t v :
       {std::int64_t(s.atlas_width), std::int64_t(s.atlas_height), std::int64_t(o.grid.azimuth),
        std::int64_t(o.grid.elevation), std::int64_t(o.spp), std::int64_t(o.bounces),
        std::int64_t(o.seed), std::int64_t(o.first_row), std::int64_t(o.end_row),
        std::int64_t(o.material.kind), std::int64_t(o.material.masking), std::int64_t(s.charts),
        std::int64_t(o.light_samples), std::int64_t(o.grid.space)})
    hash_value(h, v);
  for (float v : {o.material.albedo.x(), o.material.albedo.y(), o.material.albedo.z(),
                  o.material.specular, o.material.exponent, o.material.roughness, o.material.f0})
    hash_value(h, v);
  hash_value(h, o.ray_offset);
  return h;
}

std::string hex16(std::uint64_t h) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

}  // namespace

SlfRun make_slf(const meshes::Mesh& mesh, const std::string& mesh_path, const probes::Probe& probe,
                const std::string& probe_name, SlfSettings settings, const fs::path& cache_dir,
                const Reporter& reporter) {
  settings.bake.validate();
  settings.filter.validate();
  const meshes::Atlas atlas =
      meshes::make_atlas(mesh, settings.atlas_width, settings.atlas_height, {settings.charts});
  const std::uint64_t rows = atlas.used_texels();
  const std::uint64_t end = settings.bake.end_row == 0 ? rows : settings.bake.end_row;
  const std::uint64_t count = end > settings.bake.first_row ? end - settings.bake.first_row : 0;
  if (count < std::uint64_t(std::max(1, settings.compress.clusters))) {
    throw std::invalid_argument("--clusters " + std::to_string(settings.compress.clusters) +
                                " is more than the " + std::to_string(count) +
                                " rows (atlas texels) baked; use fewer clusters or a larger "
                                "--samples atlas");
  }
  const std::size_t columns = 3 * std::size_t(settings.bake.grid.directions());
  {
    char line[320];
    std::snprintf(
        line, sizeof line,
        "slf: %dx%d atlas (%d %s charts), %llu of %llu texels used (%zu triangles); %llu rows x "
        "%d %s directions x %d spp, %d bounce(s); %s of radiance",
        atlas.width, atlas.height, atlas.chart_count, meshes::kAtlasChartsNames.name(atlas.charts),
        static_cast<unsigned long long>(rows),
        static_cast<unsigned long long>(std::uint64_t(atlas.width) * atlas.height),
        mesh.triangles.size(), static_cast<unsigned long long>(count),
        settings.bake.grid.directions(),
        std::string(prt::kSlfDirectionSpaceNames.name(settings.bake.grid.space)).c_str(),
        settings.bake.spp, settings.bake.bounces,
        common::format_bytes(count * columns * 4).c_str());
    reporter.tell(line);
  }
  settings.bake.progress = [&reporter](std::uint64_t done, std::uint64_t total) {
    reporter.report("slf bake", done, total);
  };

  SlfRun run;
  const auto bake_start = std::chrono::steady_clock::now();
  prt::SlfMatrix matrix;
  if (cache_dir.empty()) {
    matrix = prt::bake_slf(mesh, atlas, probe, settings.bake);
    reporter.end_step();
  } else {
    fs::create_directories(cache_dir);
    common::sweep_stale_temporaries(cache_dir);
    run.bake_path = cache_dir / ("slf-" + hex16(bake_key(mesh, probe, settings)) + ".slf");
    if (fs::exists(run.bake_path)) {
      try {
        matrix = prt::read_slf(run.bake_path);
        if (matrix.shape.mesh_hash != meshes::content_hash(mesh) ||
            matrix.shape.probe_hash != prt::probe_hash(probe) || matrix.shape.rows != rows ||
            matrix.shape.charts != settings.charts ||
            matrix.shape.first_row != settings.bake.first_row || matrix.shape.row_count != count)
          throw prt::SlfFileError(run.bake_path.string() + ": not the bake its name says");
        run.bake_cached = true;
      } catch (const std::exception& e) {
        reporter.warn(std::string("cached bake unusable, baking again: ") + e.what());
        fs::remove(run.bake_path);
      }
    }
    if (!run.bake_cached) {
      prt::bake_slf_to_file(mesh, atlas, probe, settings.bake, run.bake_path);
      reporter.end_step();
      matrix = prt::read_slf(run.bake_path);
    }
  }
  const double bake_seconds = seconds_since(bake_start);
  SlfRun compressed = compress_slf(mesh, atlas, mesh_path, probe_name, std::move(matrix),
                                   settings.compress, settings.filter, reporter);
  compressed.bake_seconds = bake_seconds;
  compressed.bake_cached = run.bake_cached;
  compressed.bake_path = run.bake_path;
  return compressed;
}

SlfRun compress_slf(const meshes::Mesh& mesh, const meshes::Atlas& atlas,
                    const std::string& mesh_path, const std::string& probe_name,
                    prt::SlfMatrix matrix, cpca::CompressOptions compress,
                    const prt::SlfFilterOptions& filter, const Reporter& reporter) {
  SlfRun run;
  const std::uint64_t count = matrix.shape.row_count;
  const std::size_t columns = matrix.shape.columns();
  if (matrix.data.size() != count * columns)
    throw std::invalid_argument("compress_slf: the matrix holds " +
                                std::to_string(matrix.data.size()) + " floats, not " +
                                std::to_string(count) + " rows x " + std::to_string(columns));
  filter.validate();
  if (filter.radius > 0 && matrix.shape.first_row == 0 &&
      matrix.shape.row_count == matrix.shape.rows)
    prt::filter_slf_texels(matrix, mesh, atlas, filter);
  compress.layout = {1, 3, matrix.shape.grid.directions()};
  const Eigen::Map<const cpca::DataMatrix> data(matrix.data.data(), Eigen::Index(count),
                                                Eigen::Index(columns));
  const auto compress_start = std::chrono::steady_clock::now();
  cpca::CompressedSet set = cpca::compress(
      data, compress, nullptr, &run.report, [&reporter](const std::string& stage, double fraction) {
        reporter.report(stage, std::uint64_t(std::lround(1000 * fraction)), 1000);
      });
  reporter.end_step();
  run.compress_seconds = seconds_since(compress_start);
  set.mesh_hash = meshes::content_hash(mesh);
  set.mesh_path = fs::absolute(mesh_path).lexically_normal().string();

  // The error, by reconstructing every row (independent of cpca's own bookkeeping), in
  // fixed blocks reduced in order so that it does not depend on the thread count.
  constexpr std::uint64_t kBlock = 256;
  const std::uint64_t blocks = (count + kBlock - 1) / kBlock;
  std::vector<double> error(blocks, 0.0), norm(blocks, 0.0);
  tbb::parallel_for(std::uint64_t(0), blocks, [&](std::uint64_t b) {
    std::vector<float> row(columns);
    for (std::uint64_t r = b * kBlock; r < std::min(count, (b + 1) * kBlock); ++r) {
      cpca::reconstruct_vertex(set, r, row.data());
      const float* raw = matrix.row(r);
      for (std::size_t c = 0; c < columns; ++c) {
        const double d = double(row[c]) - double(raw[c]);
        error[b] += d * d;
        norm[b] += double(raw[c]) * double(raw[c]);
      }
    }
  });
  double total_error = 0, total_norm = 0;
  for (std::uint64_t b = 0; b < blocks; ++b) {
    total_error += error[b];
    total_norm += norm[b];
  }
  const double entries = double(count) * double(columns);
  run.rms_error = std::sqrt(total_error / entries);
  run.relative_rms_error = total_norm > 0 ? std::sqrt(total_error / total_norm) : 0.0;
  run.raw_floats = count * columns;
  run.compressed_floats =
      count * std::uint64_t(set.component_count) +
      std::uint64_t(set.cluster_count) * std::uint64_t(set.component_count + 1) * columns;
  run.ratio = double(run.raw_floats) / double(run.compressed_floats);

  run.slf.bake = matrix.shape;
  run.slf.mesh_path = set.mesh_path;
  run.slf.probe_name = probe_name;
  run.slf.set = std::move(set);
  return run;
}

}  // namespace pipeline
