// The surface light field's bake and its .slf file (prt/slf_bake.h). Rows are independent:
// row r's random numbers are keyed by r itself (and the direction and sample), so a range
// baked alone, by another process, or with any number of threads gives the same bytes as
// the same rows of the whole bake.
#include "prt/slf_bake.h"

#include "prt/path_tracer.h"
#include "prt/sampling.h"

#include "common/atomic_file.h"
#include "common/binary_file.h"
#include "common/hash.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <mutex>

#include <fcntl.h>
#include <unistd.h>

namespace prt {
namespace {

namespace fs = std::filesystem;

constexpr common::VersionedFormat kSlfFormat{"surface light field file",
                                             ".slf file written by prtr slf",
                                             "create it with prtr slf",
                                             "bake it again with prtr slf",
                                             {'P', 'R', 'T', 'R', 'S', 'L', 'F', 'M'},
                                             kSlfFileVersion,
                                             1};

constexpr std::size_t kSlfOffWidth = 16, kSlfOffCharts = 18, kSlfOffHeight = 20,
                      kSlfOffAzimuth = 24, kSlfOffElevation = 28, kSlfOffSpp = 32,
                      kSlfOffBounces = 36, kSlfOffLightSamples = 38, kSlfOffKind = 40,
                      kSlfOffMasking = 44, kSlfOffSpace = 46, kSlfOffSeed = 48,
                      kSlfOffMeshHash = 56, kSlfOffAlbedo = 64, kSlfOffSpecular = 76,
                      kSlfOffExponent = 80, kSlfOffRoughness = 84, kSlfOffF0 = 88, kSlfOffRows = 92,
                      kSlfOffFirstRow = 96, kSlfOffRowCount = 100, kSlfOffPayloadChecksum = 104,
                      kSlfOffProbeHash = 112;
constexpr int kMaxSpp = 65536;
constexpr float kSlfMaxRadiance = 1e20f;

}  // namespace

void put_slf_settings(common::VersionedHeader& h, const SlfShape& s) {
  common::put_field(h, kSlfOffWidth, std::uint16_t(s.atlas_width));
  common::put_field(h, kSlfOffCharts, std::uint16_t(s.charts));
  common::put_field(h, kSlfOffHeight, std::uint32_t(s.atlas_height));
  common::put_field(h, kSlfOffAzimuth, std::uint32_t(s.grid.azimuth));
  common::put_field(h, kSlfOffElevation, std::uint32_t(s.grid.elevation));
  common::put_field(h, kSlfOffSpp, std::uint32_t(s.spp));
  common::put_field(h, kSlfOffBounces, std::uint16_t(s.bounces));
  common::put_field(h, kSlfOffLightSamples, std::uint16_t(s.light_samples));
  common::put_field(h, kSlfOffKind, std::uint32_t(s.material.kind));
  common::put_field(h, kSlfOffMasking, std::uint16_t(s.material.masking));
  common::put_field(h, kSlfOffSpace, std::uint16_t(s.grid.space));
  common::put_field(h, kSlfOffMeshHash, s.mesh_hash);
  for (int c = 0; c < 3; ++c) common::put_field(h, kSlfOffAlbedo + 4 * c, s.material.albedo[c]);
  common::put_field(h, kSlfOffSpecular, s.material.specular);
  common::put_field(h, kSlfOffExponent, s.material.exponent);
  common::put_field(h, kSlfOffRoughness, s.material.roughness);
  common::put_field(h, kSlfOffF0, s.material.f0);
  common::put_field(h, kSlfOffProbeHash, s.probe_hash);
}

void get_slf_settings(const common::VersionedHeader& h, SlfShape& s) {
  const auto count = [&h](std::size_t offset) {
    return int(std::min<std::uint32_t>(common::get_field<std::uint32_t>(h, offset), 1u << 30));
  };
  if (common::header_version(h) >= 2) {
    s.atlas_width = common::get_field<std::uint16_t>(h, kSlfOffWidth);
    s.charts = meshes::AtlasCharts(common::get_field<std::uint16_t>(h, kSlfOffCharts));
  } else {
    s.atlas_width = count(kSlfOffWidth);
    s.charts = meshes::AtlasCharts::kPerTriangle;
  }
  s.atlas_height = count(kSlfOffHeight);
  s.grid.azimuth = count(kSlfOffAzimuth);
  s.grid.elevation = count(kSlfOffElevation);
  s.spp = count(kSlfOffSpp);
  if (common::header_version(h) >= 3) {
    s.bounces = common::get_field<std::uint16_t>(h, kSlfOffBounces);
    s.light_samples = common::get_field<std::uint16_t>(h, kSlfOffLightSamples);
  } else {
    s.bounces = count(kSlfOffBounces);
    s.light_samples = 0;
  }
  s.material.kind = MaterialKind(common::get_field<std::uint32_t>(h, kSlfOffKind));
  if (common::header_version(h) >= 4) {
    s.material.masking = Masking(common::get_field<std::uint16_t>(h, kSlfOffMasking));
    s.grid.space = SlfDirectionSpace(common::get_field<std::uint16_t>(h, kSlfOffSpace));
  } else {
    s.material.masking = Masking(common::get_field<std::uint32_t>(h, kSlfOffMasking));
    s.grid.space = SlfDirectionSpace::kView;
  }
  s.mesh_hash = common::get_field<std::uint64_t>(h, kSlfOffMeshHash);
  for (int c = 0; c < 3; ++c)
    s.material.albedo[c] = common::get_field<float>(h, kSlfOffAlbedo + 4 * c);
  s.material.specular = common::get_field<float>(h, kSlfOffSpecular);
  s.material.exponent = common::get_field<float>(h, kSlfOffExponent);
  s.material.roughness = common::get_field<float>(h, kSlfOffRoughness);
  s.material.f0 = common::get_field<float>(h, kSlfOffF0);
  s.probe_hash = common::get_field<std::uint64_t>(h, kSlfOffProbeHash);
}

std::string slf_layout_problem(const SlfShape& s) {
  bool space_known = false;
  for (const auto& entry : kSlfDirectionSpaceNames.entries)
    space_known |= entry.value == s.grid.space;
  if (!space_known)
    return "direction space " + std::to_string(std::uint32_t(s.grid.space)) + " is unknown";
  for (const auto& entry : meshes::kAtlasChartsNames.entries)
    if (entry.value == s.charts) return {};
  return "atlas chart method " + std::to_string(std::uint32_t(s.charts)) + " is unknown";
}

namespace {

common::VersionedHeader encode_slf_header(const SlfShape& s, std::uint64_t payload_checksum) {
  common::VersionedHeader h = common::begin_header(kSlfFormat);
  put_slf_settings(h, s);
  common::put_field(h, kSlfOffSeed, s.seed);
  common::put_field(h, kSlfOffRows, std::uint32_t(s.rows));
  common::put_field(h, kSlfOffFirstRow, std::uint32_t(s.first_row));
  common::put_field(h, kSlfOffRowCount, std::uint32_t(s.row_count));
  common::put_field(h, kSlfOffPayloadChecksum, payload_checksum);
  common::seal_header(h);
  return h;
}

// Empty when the shape's fields are what a reader accepts.
std::string shape_problem(const SlfShape& s) {
  const auto in = [](std::uint64_t v, std::uint64_t lo, std::uint64_t hi) {
    return v >= lo && v <= hi;
  };
  if (!in(std::uint64_t(s.atlas_width), 4, 8192) || !in(std::uint64_t(s.atlas_height), 4, 8192))
    return "atlas size " + std::to_string(s.atlas_width) + " x " + std::to_string(s.atlas_height) +
           " is outside [4, 8192]";
  if (std::string problem = slf_layout_problem(s); !problem.empty()) return problem;
  if (!in(std::uint64_t(s.grid.azimuth), 1, 4096) || !in(std::uint64_t(s.grid.elevation), 1, 4096))
    return "direction grid " + std::to_string(s.grid.azimuth) + " x " +
           std::to_string(s.grid.elevation) + " is outside [1, 4096]";
  if (!in(std::uint64_t(s.spp), 1, kMaxSpp))
    return "spp " + std::to_string(s.spp) + " out of range";
  if (!in(std::uint64_t(s.bounces), 0, 16))
    return "bounces " + std::to_string(s.bounces) + " out of range";
  if (!in(std::uint64_t(s.light_samples), 0, kMaxLightSamples))
    return "light samples " + std::to_string(s.light_samples) + " out of range";
  try {
    s.material.validate();
  } catch (const std::invalid_argument& e) {
    return std::string("material: ") + e.what();
  }
  if (s.rows > std::uint64_t(s.atlas_width) * std::uint64_t(s.atlas_height))
    return std::to_string(s.rows) + " rows for an atlas of " +
           std::to_string(std::uint64_t(s.atlas_width) * std::uint64_t(s.atlas_height)) + " texels";
  if (s.first_row > s.rows || s.row_count > s.rows - s.first_row)
    return "rows [" + std::to_string(s.first_row) + ", " +
           std::to_string(s.first_row + s.row_count) + ") are outside the matrix's " +
           std::to_string(s.rows);
  return {};
}

SlfShape decode_slf_header(const common::VersionedHeader& h) {
  SlfShape s;
  get_slf_settings(h, s);
  s.seed = common::get_field<std::uint64_t>(h, kSlfOffSeed);
  s.rows = common::get_field<std::uint32_t>(h, kSlfOffRows);
  s.first_row = common::get_field<std::uint32_t>(h, kSlfOffFirstRow);
  s.row_count = common::get_field<std::uint32_t>(h, kSlfOffRowCount);
  return s;
}

SlfShape read_slf_file(const fs::path& path, std::vector<float>* payload) {
  const auto fail = [&](const std::string& problem) {
    return SlfFileError(path.string() + ": " + problem);
  };
  common::OpenedVersionedFile f = common::open_versioned(path, kSlfFormat);
  if (!f.problem.empty()) throw fail(f.problem);
  const SlfShape shape = decode_slf_header(f.header);
  if (const std::string problem = shape_problem(shape); !problem.empty())
    throw fail("header field " + problem + "; the file is damaged: " + kSlfFormat.remedy);
  if (const std::string problem = common::header_checksum_problem(f.header, kSlfFormat);
      !problem.empty())
    throw fail(problem);
  const std::uint64_t floats = shape.row_count * shape.columns();
  const std::uint64_t expected = common::kVersionedHeaderBytes + floats * sizeof(float);
  if (const std::string problem = common::file_size_problem(expected, f.size, kSlfFormat);
      !problem.empty())
    throw fail(problem);
  if (!payload) return shape;
  payload->resize(floats);
  f.stream.read(reinterpret_cast<char*>(payload->data()), std::streamsize(floats * sizeof(float)));
  if (std::uint64_t(f.stream.gcount()) != floats * sizeof(float))
    throw fail("could not read the payload (the file changed while it was read)");
  if (const std::string problem = common::checksum_problem(
          "payload", common::fnv1a(payload->data(), floats * sizeof(float)),
          common::get_field<std::uint64_t>(f.header, kSlfOffPayloadChecksum), kSlfFormat);
      !problem.empty())
    throw fail(problem);
  for (std::size_t i = 0; i < payload->size(); ++i) {
    if (!(std::abs((*payload)[i]) <= kSlfMaxRadiance)) {
      throw fail("value " + std::to_string((*payload)[i]) + " at row " +
                 std::to_string(shape.first_row + i / shape.columns()) +
                 " is not a radiance; the file is damaged: " + kSlfFormat.remedy);
    }
  }
  return shape;
}

// Writes the header over the zeros at the start of the atomic file's temporary.
void write_header(const common::AtomicFile& file, const common::VersionedHeader& h) {
  const int fd = ::open(file.temporary().c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0 || ::pwrite(fd, h.data(), h.size(), 0) != static_cast<ssize_t>(h.size())) {
    const std::string why = std::strerror(errno);
    if (fd >= 0) ::close(fd);
    throw common::IoError(file.target().string() + ": cannot write the header (" + why + ")");
  }
  ::close(fd);
}

// Point i of `count` in the unit square: the first n^2 (n = floor(sqrt(count))) one in each
// cell of an n x n grid, the rest uniform, so every point is uniform over the square on
// average and the mean over them is unbiased (stratified sampling; the grid takes the
// variation across the square out of the estimate).
Eigen::Vector2d stratified_point(int i, int count, RandomStream& rng) {
  const int n = int(std::sqrt(double(count)));
  const double a = rng.next(), b = rng.next();
  if (i >= n * n) return {a, b};
  return {(i % n + a) / n, (i / n + b) / n};
}

// Cell (i, j) of the grid: azimuth cell i, and the cosines of its polar edges.
struct GridCell {
  int i;
  double top, bottom;
  GridCell(const SlfGrid& grid, int column)
      : i(column % grid.azimuth),
        top(std::cos(slf_polar_span(grid) * (column / grid.azimuth) / grid.elevation)),
        bottom(std::cos(slf_polar_span(grid) * (column / grid.azimuth + 1) / grid.elevation)) {}
};

// The direction in the grid's axes at (a, b) in [0, 1)^2 over the cell: azimuth linear in a,
// cosine of the polar angle linear in b, so uniform in solid angle inside the cell.
Eigen::Vector3d cell_direction(const SlfGrid& grid, const GridCell& cell, double a, double b) {
  const double cos_polar = std::clamp(cell.top + b * (cell.bottom - cell.top), -1.0, 1.0);
  return slf_direction_at_cosine(2 * (cell.i + a) / grid.azimuth, cos_polar);
}

// The texel's samples: the mean radiance over each cell of the grid, from spp paths a cell
// toward views stratified over the cell. With light_samples, the first vertex's light
// technique is light_samples x spp probe samples shared by all of the texel's cells (one
// shadow ray each, prt::SharedLights), each cell pairing every one of them with its own view,
// again stratified over the cell: per cell as many light-view pairs as the paths' own light
// samples would give light_samples times over, for the price of BRDF evaluations. In the
// reflected and local spaces a cell's samples are mirrored about the shading normal or
// turned out of its frame into views (prt/slf_directions.h), uniform over the cell's image
// since both keep solid angle.
void bake_row(const PathTracer& tracer, const meshes::Atlas& atlas, std::uint32_t texel,
              std::uint64_t row, const SlfBakeOptions& o, float* out) {
  const int directions = o.grid.directions();
  const SurfacePoint point =
      tracer.surface_point(atlas.texel_triangle[texel], atlas.texel_barycentric[texel].x(),
                           atlas.texel_barycentric[texel].y());
  thread_local std::vector<ExitQuery> queries;
  thread_local std::vector<Eigen::Vector3d> sums, light_sums;
  thread_local std::vector<std::uint32_t> shift_x, shift_y;
  thread_local Eigen::Matrix3Xd views;
  thread_local std::vector<GridCell> cells;
  queries.clear();
  cells.clear();
  sums.assign(std::size_t(directions), Eigen::Vector3d::Zero());
  const std::uint64_t row_key = mix_key(o.seed ^ 0x51F0000000000000ULL, row);
  const int shared = o.light_samples * o.spp;
  const SharedLights lights =
      o.light_samples > 0 ? tracer.sample_lights(point, shared, mix_key(row_key, 0x11647ULL))
                          : SharedLights{};
  const double ratio = lights.size() > 0 ? double(o.light_samples) : 0.0;
  const SlfPointSpace space(o.grid, point.frame.col(2));
  const auto view_at = [&](const GridCell& cell, const Eigen::Vector2d& ab) {
    return space.to_view(cell_direction(o.grid, cell, ab.x(), ab.y()));
  };
  shift_x.resize(std::size_t(directions));
  shift_y.resize(std::size_t(directions));
  for (int column = 0; column < directions; ++column) {
    const GridCell& cell = cells.emplace_back(o.grid, column);
    const std::uint64_t column_key = mix_key(row_key, std::uint64_t(column));
    for (int k = 0; k < o.spp; ++k) {
      const std::uint64_t key = mix_key(column_key, std::uint64_t(k));
      RandomStream jitter{key, 0};
      const Eigen::Vector2d ab = stratified_point(k, o.spp, jitter);
      ExitQuery q{point, view_at(cell, ab), key, std::uint32_t(column)};
      q.shared_light_ratio = ratio;
      queries.push_back(q);
    }
    RandomStream jitter{mix_key(column_key, 0x11647ULL), 0};
    shift_x[std::size_t(column)] = std::uint32_t(jitter.next() * 0x1.0p32);
    shift_y[std::size_t(column)] = std::uint32_t(jitter.next() * 0x1.0p32);
  }
  if (ratio > 0) {
    // Light sample l is paired, in every cell, with view l of a digitally shifted
    // (0, 2)-sequence over the cell (each cell its own random shift). The probe's samples are
    // stratified along its CDF, so a bright source (a sun) takes a run of consecutive l, and
    // the sequence spreads any such run over the whole cell; pairing sample l with stratum l
    // plus a random rotation gave the run a strip of the cell, a quarter of its polar range
    // for 64 samples. Each view is uniform over the cell and drawn apart from its light
    // sample, so the sum stays unbiased. Unlit samples need no view. One light at a time
    // against its view in every cell, so that the BRDF runs on arrays.
    light_sums.assign(std::size_t(directions), Eigen::Vector3d::Zero());
    views.resize(3, directions);
    for (std::uint32_t l = 0; l < std::uint32_t(shared); ++l) {
      if (!lights.lit(l)) continue;
      for (int column = 0; column < directions; ++column)
        views.col(column) =
            view_at(cells[std::size_t(column)],
                    sobol02(l, shift_x[std::size_t(column)], shift_y[std::size_t(column)]));
      tracer.add_shared_light(point, lights, l, views, ratio, light_sums.data());
    }
    for (int column = 0; column < directions; ++column)
      sums[std::size_t(column)] += light_sums[std::size_t(column)] / o.light_samples;
  }
  tracer.add_exit_radiance(queries, sums.data());
  for (int column = 0; column < directions; ++column) {
    for (int c = 0; c < 3; ++c) out[3 * column + c] = float(sums[std::size_t(column)][c] / o.spp);
  }
}

struct SlfRange {
  std::vector<std::uint32_t> texels;  // of the whole matrix
  std::uint64_t first = 0, end = 0;
};

SlfRange resolve_slf_range(const meshes::Mesh& mesh, const meshes::Atlas& atlas,
                           const SlfBakeOptions& o) {
  o.validate();
  if (atlas.uv.size() != 3 * mesh.triangles.size() ||
      atlas.texel_triangle.size() != std::size_t(atlas.width) * std::size_t(atlas.height)) {
    throw std::invalid_argument("the atlas was not made for this mesh (" +
                                std::to_string(atlas.uv.size() / 3) + " charts for " +
                                std::to_string(mesh.triangles.size()) + " triangles)");
  }
  SlfRange r;
  r.texels = slf_rows(atlas);
  r.first = o.first_row;
  r.end = o.end_row == 0 ? r.texels.size() : o.end_row;
  if (r.end > r.texels.size() || r.first > r.end) {
    throw std::invalid_argument("--rows [" + std::to_string(r.first) + ", " +
                                std::to_string(r.end) + ") is outside the " +
                                std::to_string(r.texels.size()) + " rows of the atlas");
  }
  return r;
}

SlfShape shape_of(const meshes::Mesh& mesh, const meshes::Atlas& atlas, const probes::Probe& probe,
                  const SlfBakeOptions& o, const SlfRange& r) {
  SlfShape s;
  s.atlas_width = atlas.width;
  s.atlas_height = atlas.height;
  s.charts = atlas.charts;
  s.grid = o.grid;
  s.spp = o.spp;
  s.light_samples = o.light_samples;
  s.bounces = o.bounces;
  s.seed = o.seed;
  s.material = o.material;
  s.mesh_hash = meshes::content_hash(mesh);
  s.probe_hash = probe_hash(probe);
  s.rows = r.texels.size();
  s.first_row = r.first;
  s.row_count = r.end - r.first;
  return s;
}

// Bakes the range block by block, handing each block to `sink` in row order.
void bake_blocks(const meshes::Mesh& mesh, const meshes::Atlas& atlas, const probes::Probe& probe,
                 const SlfBakeOptions& o, const SlfRange& r,
                 const std::function<void(const float*, std::uint64_t rows)>& sink) {
  PathTracerOptions tracer_options;
  tracer_options.bounces = o.bounces;
  tracer_options.seed = o.seed;
  tracer_options.ray_offset = o.ray_offset;
  const PathTracer tracer(mesh, probe, o.material, tracer_options);
  const std::size_t columns = std::size_t(3) * std::size_t(o.grid.directions());
  const std::uint64_t block =
      o.block_rows > 0 ? o.block_rows
                       : std::max<std::uint64_t>(1, (std::uint64_t(16) << 20) / (4 * columns));
  const std::uint64_t total = r.end - r.first;
  std::vector<float> buffer;
  std::atomic<std::uint64_t> done{0};
  std::mutex report;
  auto last = std::chrono::steady_clock::now();
  for (std::uint64_t begin = r.first; begin < r.end; begin += block) {
    const std::uint64_t rows = std::min(block, r.end - begin);
    buffer.assign(rows * columns, 0.f);
    tbb::parallel_for(std::uint64_t(0), rows, [&](std::uint64_t k) {
      bake_row(tracer, atlas, r.texels[begin + k], begin + k, o, buffer.data() + k * columns);
      const std::uint64_t now = done.fetch_add(1) + 1;
      if (o.progress && report.try_lock()) {
        const auto t = std::chrono::steady_clock::now();
        if (t - last >= std::chrono::milliseconds(50)) {
          last = t;
          o.progress(now, total);
        }
        report.unlock();
      }
    });
    sink(buffer.data(), rows);
  }
  if (o.progress) o.progress(total, total);
}

}  // namespace

void SlfBakeOptions::validate() const {
  grid.validate();
  if (spp < 1 || spp > kMaxSpp)
    throw std::invalid_argument("--spp must be in [1, 65536], got " + std::to_string(spp));
  if (light_samples < 0 || light_samples > kMaxLightSamples)
    throw std::invalid_argument("--light-samples must be in [0, " +
                                std::to_string(kMaxLightSamples) + "], got " +
                                std::to_string(light_samples));
  PathTracerOptions tracer;
  tracer.bounces = bounces;
  tracer.ray_offset = ray_offset;
  tracer.validate();
  material.validate();
  if (end_row != 0 && first_row > end_row) {
    throw std::invalid_argument("--rows: the first row " + std::to_string(first_row) +
                                " is past the end " + std::to_string(end_row));
  }
}

std::vector<std::uint32_t> slf_rows(const meshes::Atlas& atlas) {
  std::vector<std::uint32_t> rows;
  rows.reserve(atlas.texel_triangle.size());
  for (std::size_t i = 0; i < atlas.texel_triangle.size(); ++i) {
    if (atlas.texel_triangle[i] >= 0) rows.push_back(std::uint32_t(i));
  }
  return rows;
}

std::uint64_t probe_hash(const probes::Probe& probe) {
  const std::int32_t size[2] = {probe.width(), probe.height()};
  std::uint64_t h = common::fnv1a(size, sizeof(size));
  return common::fnv1a(probe.texels().data(), probe.texels().size() * sizeof(probes::Rgb), h);
}

SlfMatrix bake_slf(const meshes::Mesh& mesh, const meshes::Atlas& atlas, const probes::Probe& probe,
                   const SlfBakeOptions& options) {
  const SlfRange r = resolve_slf_range(mesh, atlas, options);
  SlfMatrix m;
  m.shape = shape_of(mesh, atlas, probe, options, r);
  m.data.reserve(m.shape.row_count * m.shape.columns());
  bake_blocks(mesh, atlas, probe, options, r, [&](const float* data, std::uint64_t rows) {
    m.data.insert(m.data.end(), data, data + rows * m.shape.columns());
  });
  return m;
}

SlfShape bake_slf_to_file(const meshes::Mesh& mesh, const meshes::Atlas& atlas,
                          const probes::Probe& probe, const SlfBakeOptions& options,
                          const fs::path& path) {
  const SlfRange r = resolve_slf_range(mesh, atlas, options);
  const SlfShape shape = shape_of(mesh, atlas, probe, options, r);
  common::AtomicFile file(path);
  const common::VersionedHeader zeros{};
  file.write(zeros.data(), zeros.size());
  std::uint64_t hash = common::kFnvOffset;
  bake_blocks(mesh, atlas, probe, options, r, [&](const float* data, std::uint64_t rows) {
    const std::size_t bytes = rows * shape.columns() * sizeof(float);
    for (std::size_t i = 0; i < rows * shape.columns(); ++i) {
      if (!(std::abs(data[i]) <= kSlfMaxRadiance)) {
        throw std::runtime_error(path.string() +
                                 ": the bake produced a non-finite radiance; "
                                 "check the probe and the mesh");
      }
    }
    hash = common::fnv1a(data, bytes, hash);
    file.write(data, bytes);
  });
  write_header(file, encode_slf_header(shape, hash));
  file.commit();
  return shape;
}

void write_slf(const fs::path& path, const SlfMatrix& m) {
  const auto refuse = [&](const std::string& problem) {
    return std::invalid_argument(path.string() +
                                 ": cannot write the surface light field: " + problem);
  };
  if (const std::string problem = shape_problem(m.shape); !problem.empty()) throw refuse(problem);
  if (m.data.size() != m.shape.row_count * m.shape.columns())
    throw refuse("data holds " + std::to_string(m.data.size()) + " floats, not " +
                 std::to_string(m.shape.row_count * m.shape.columns()));
  for (float v : m.data)
    if (!(std::abs(v) <= kSlfMaxRadiance)) throw refuse("a value is not a finite radiance");
  const std::size_t bytes = m.data.size() * sizeof(float);
  const common::VersionedHeader h = encode_slf_header(m.shape, common::fnv1a(m.data.data(), bytes));
  common::AtomicFile file(path);
  file.write(h.data(), h.size());
  file.write(m.data.data(), bytes);
  file.commit();
}

SlfMatrix read_slf(const fs::path& path) {
  SlfMatrix m;
  m.shape = read_slf_file(path, &m.data);
  return m;
}

SlfShape read_slf_header(const fs::path& path) {
  return read_slf_file(path, nullptr);
}

SlfMatrix join_slf_parts(const std::vector<fs::path>& parts) {
  if (parts.empty()) throw SlfFileError("join_slf_parts: no parts given");
  std::vector<SlfMatrix> read_parts;
  for (const fs::path& p : parts) read_parts.push_back(read_slf(p));
  std::vector<std::size_t> order(read_parts.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return read_parts[a].shape.first_row < read_parts[b].shape.first_row;
  });
  SlfMatrix whole;
  whole.shape = read_parts[order[0]].shape;
  std::uint64_t next = 0;
  for (std::size_t i : order) {
    const SlfShape& s = read_parts[i].shape;
    const SlfShape& w = whole.shape;
    if (s.atlas_width != w.atlas_width || s.atlas_height != w.atlas_height ||
        s.charts != w.charts || s.grid.azimuth != w.grid.azimuth ||
        s.grid.elevation != w.grid.elevation || s.grid.space != w.grid.space || s.spp != w.spp ||
        s.bounces != w.bounces || s.light_samples != w.light_samples || s.seed != w.seed ||
        s.mesh_hash != w.mesh_hash || s.probe_hash != w.probe_hash || s.rows != w.rows ||
        s.material.kind != w.material.kind || s.material.albedo != w.material.albedo ||
        s.material.specular != w.material.specular || s.material.exponent != w.material.exponent ||
        s.material.roughness != w.material.roughness || s.material.f0 != w.material.f0 ||
        s.material.masking != w.material.masking) {
      throw SlfFileError(parts[i].string() + ": baked with other settings than " +
                         parts[order[0]].string() + "; bake every part with the same flags");
    }
    if (s.first_row != next) {
      throw SlfFileError(parts[i].string() + ": starts at row " + std::to_string(s.first_row) +
                         " where row " + std::to_string(next) +
                         " was expected; the parts must cover every row once");
    }
    next += s.row_count;
    whole.data.insert(whole.data.end(), read_parts[i].data.begin(), read_parts[i].data.end());
  }
  if (next != whole.shape.rows) {
    throw SlfFileError("the parts cover rows [0, " + std::to_string(next) + ") of " +
                       std::to_string(whole.shape.rows) + "; bake the missing rows");
  }
  whole.shape.first_row = 0;
  whole.shape.row_count = whole.shape.rows;
  return whole;
}

}  // namespace prt
