// meshes/load.cpp: OBJ and STL through OpenMesh's IO layer, OFF and PLY through our own
// readers, glTF 2.0 and 3DS through Assimp behind our guards, then clean-up (weld, drop
// degenerate and unreferenced, frames).
//
// OpenMesh's OFF and PLY readers size buffers from unchecked header counts and read values
// they never set after a parse error (see read_strict.h), which no guard in front of them can
// fix; they are replaced. Its OBJ reader is kept behind a strict pre-pass over face lines,
// and its STL reader behind our own binary/ASCII decision by file size. Assimp is kept
// behind the checks of asset_guard.h, which bound every size it would trust.
//
// OpenMesh is used only for parsing. Its readers feed a BaseImporter; OpenMesh's own
// ImporterT builds a halfedge mesh, which cannot hold non-manifold ("complex") faces: it
// either drops them or, in OpenMesh 9, duplicates their vertices, and both silently change
// the mesh. CollectingImporter below keeps the raw vertex and polygon lists instead, so every
// face the reader delivers reaches the clean-up and is counted in LoadReport. (On the Stanford
// bunny OpenMesh 9's PolyMesh happens to keep all 69,666 faces; non-manifold inputs such as
// the "fin" in meshes_test would not survive it unchanged.)
#include "meshes/load.h"

#include "meshes/weld.h"

#include "asset_guard.h"
#include "read_assimp.h"
#include "read_strict.h"

#include <OpenMesh/Core/IO/MeshIO.hh>

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cmath>
#include <fstream>
#include <iterator>
#include <map>
#include <mutex>
#include <new>
#include <sstream>
#include <string_view>
#include <system_error>
#include <unordered_map>
#include <vector>

namespace meshes {

namespace {

namespace fs = std::filesystem;
namespace omio = OpenMesh::IO;

// Relative to the squared bounding-box diagonal: a triangle whose doubled area is below this
// is a sliver of float rounding, with no usable normal.
constexpr double kDegenerateAreaRatio = 1e-12;

constexpr std::array<const char*, 7> kFormats = {"obj", "ply", "off", "stl", "3ds", "gltf", "glb"};

std::string supported_list() {
  std::string out;
  for (const char* f : kFormats) {
    if (!out.empty()) out += ", ";
    out += ".";
    out += f;
  }
  return out;
}

std::string describe_point(const Vec3& v) {
  std::ostringstream out;
  out << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return out.str();
}

// In double: for coordinates near the float limit (a triangle at +-3e38) the float
// difference max - min overflows to infinity, and an infinite diagonal makes every
// triangle's area look negligible.
double diagonal_of(const Bounds& box) {
  return (box.max.cast<double>() - box.min.cast<double>()).norm();
}

// Adding +0 turns -0 into +0, so equal floats have equal bits.
std::int32_t bits_of(float x) {
  return std::bit_cast<std::int32_t>(x + 0.f);
}

// --- Reading ---------------------------------------------------------------------------------

// Collects what a reader parses: positions and polygons as index lists, nothing else.
class CollectingImporter final : public omio::BaseImporter {
 public:
  std::vector<Vec3> positions;
  std::vector<std::uint32_t> corners;        // all faces' indices, concatenated
  std::vector<std::size_t> face_offsets{0};  // face f is corners[offsets[f], offsets[f+1])
  // One per position when the file gives every vertex a normal, else empty.
  std::vector<Vec3> normals;
  std::size_t split_by_normals = 0;  // OBJ: vertices added for a 'v' used with several 'vn'
  // The first face that names a vertex that does not exist, if any.
  bool has_bad_face = false;
  std::size_t bad_face = 0;
  long long bad_index = 0;

  std::size_t face_count() const { return face_offsets.size() - 1; }

  OpenMesh::VertexHandle add_vertex(const OpenMesh::Vec3f& p) override {
    positions.emplace_back(p[0], p[1], p[2]);
    return OpenMesh::VertexHandle(static_cast<int>(positions.size() - 1));
  }
  OpenMesh::VertexHandle add_vertex(const OpenMesh::Vec3d& p) override {
    return add_vertex(OpenMesh::Vec3f(p));
  }
  OpenMesh::VertexHandle add_vertex() override { return add_vertex(OpenMesh::Vec3f(0, 0, 0)); }
  void set_point(OpenMesh::VertexHandle vh, const OpenMesh::Vec3f& p) override {
    if (vh.is_valid() && static_cast<std::size_t>(vh.idx()) < positions.size()) {
      positions[static_cast<std::size_t>(vh.idx())] = Vec3(p[0], p[1], p[2]);
    }
  }

  OpenMesh::FaceHandle add_face(const VHandles& handles) override {
    for (const OpenMesh::VertexHandle& h : handles) {
      const long long idx = h.idx();
      if (idx < 0 || static_cast<std::size_t>(idx) >= positions.size()) {
        if (!has_bad_face) {
          has_bad_face = true;
          bad_face = face_count();
          bad_index = idx;
        }
        corners.push_back(0);
      } else {
        corners.push_back(static_cast<std::uint32_t>(idx));
      }
    }
    face_offsets.push_back(corners.size());
    return OpenMesh::FaceHandle(static_cast<int>(face_count() - 1));
  }

  void reserve(unsigned int vertices, unsigned int /*edges*/, unsigned int faces) override {
    positions.reserve(vertices);
    face_offsets.reserve(std::size_t{faces} + 1);
    corners.reserve(3 * std::size_t{faces});
  }
  size_t n_vertices() const override { return positions.size(); }
  size_t n_faces() const override { return face_count(); }
  size_t n_edges() const override { return 0; }

  // Everything below is data we do not use (or halfedge connectivity, which only the .om
  // format sends); ignoring it is the point of this importer.
  OpenMesh::HalfedgeHandle add_edge(OpenMesh::VertexHandle, OpenMesh::VertexHandle) override {
    return OpenMesh::HalfedgeHandle();
  }
  OpenMesh::FaceHandle add_face(OpenMesh::HalfedgeHandle) override {
    return OpenMesh::FaceHandle();
  }
  void add_face_texcoords(OpenMesh::FaceHandle, OpenMesh::VertexHandle,
                          const std::vector<OpenMesh::Vec2f>&) override {}
  void add_face_texcoords(OpenMesh::FaceHandle, OpenMesh::VertexHandle,
                          const std::vector<OpenMesh::Vec3f>&) override {}
  void set_face_texindex(OpenMesh::FaceHandle, int) override {}
  void set_halfedge(OpenMesh::VertexHandle, OpenMesh::HalfedgeHandle) override {}
  void set_normal(OpenMesh::VertexHandle, const OpenMesh::Vec3f&) override {}
  void set_normal(OpenMesh::VertexHandle, const OpenMesh::Vec3d&) override {}
  void set_normal(OpenMesh::FaceHandle, const OpenMesh::Vec3f&) override {}
  void set_normal(OpenMesh::FaceHandle, const OpenMesh::Vec3d&) override {}
  void set_color(OpenMesh::VertexHandle, const OpenMesh::Vec3uc&) override {}
  void set_color(OpenMesh::VertexHandle, const OpenMesh::Vec4uc&) override {}
  void set_color(OpenMesh::VertexHandle, const OpenMesh::Vec3f&) override {}
  void set_color(OpenMesh::VertexHandle, const OpenMesh::Vec4f&) override {}
  void set_color(OpenMesh::EdgeHandle, const OpenMesh::Vec3uc&) override {}
  void set_color(OpenMesh::EdgeHandle, const OpenMesh::Vec4uc&) override {}
  void set_color(OpenMesh::EdgeHandle, const OpenMesh::Vec3f&) override {}
  void set_color(OpenMesh::EdgeHandle, const OpenMesh::Vec4f&) override {}
  void set_color(OpenMesh::FaceHandle, const OpenMesh::Vec3uc&) override {}
  void set_color(OpenMesh::FaceHandle, const OpenMesh::Vec4uc&) override {}
  void set_color(OpenMesh::FaceHandle, const OpenMesh::Vec3f&) override {}
  void set_color(OpenMesh::FaceHandle, const OpenMesh::Vec4f&) override {}
  void set_texcoord(OpenMesh::VertexHandle, const OpenMesh::Vec2f&) override {}
  void set_texcoord(OpenMesh::VertexHandle, const OpenMesh::Vec3f&) override {}
  void set_texcoord(OpenMesh::HalfedgeHandle, const OpenMesh::Vec2f&) override {}
  void set_texcoord(OpenMesh::HalfedgeHandle, const OpenMesh::Vec3f&) override {}
  void set_status(OpenMesh::VertexHandle, const OpenMesh::Attributes::StatusInfo&) override {}
  void set_status(OpenMesh::HalfedgeHandle, const OpenMesh::Attributes::StatusInfo&) override {}
  void set_status(OpenMesh::EdgeHandle, const OpenMesh::Attributes::StatusInfo&) override {}
  void set_status(OpenMesh::FaceHandle, const OpenMesh::Attributes::StatusInfo&) override {}
  void set_next(OpenMesh::HalfedgeHandle, OpenMesh::HalfedgeHandle) override {}
  void set_face(OpenMesh::HalfedgeHandle, OpenMesh::FaceHandle) override {}
  void request_face_texcoords2D() override {}
  void add_texture_information(int, std::string) override {}
};

// OpenMesh's readers are singletons with per-read state (the OFF reader keeps the options it
// detected in a member), so reads are serialised.
std::mutex& reader_mutex() {
  static std::mutex m;
  return m;
}

// Binary STL is exactly 84 + 50 n bytes for the n in its header. OpenMesh decides by whether
// the file starts with "solid", which many binary exporters also write into their header, so
// we decide here by size and tell the reader.
// A file that does not start with "solid" can only be binary; when its size disagrees with
// its triangle count it is truncated (or padded), which `problem` then says.
bool is_binary_stl(const fs::path& path, std::uintmax_t size, std::string& problem) {
  if (size < 84) return false;
  std::ifstream in(path, std::ios::binary);
  char header[84];
  if (!in.read(header, sizeof(header))) return false;
  const auto* b = reinterpret_cast<const unsigned char*>(header + 80);
  const std::uintmax_t n = std::uintmax_t{b[0]} | (std::uintmax_t{b[1]} << 8) |
                           (std::uintmax_t{b[2]} << 16) | (std::uintmax_t{b[3]} << 24);
  if (size == 84 + 50 * n) return true;
  if (std::string_view(header, 5) != "solid") {
    problem = "binary STL whose header claims " + std::to_string(n) + " triangles (" +
              std::to_string(84 + 50 * n) + " bytes), but the file has " + std::to_string(size) +
              " bytes; it is truncated or damaged, re-export it";
  }
  return false;
}

// --- Clean-up ----------------------------------------------------------------------------------

struct CleanCounts {
  std::size_t welded = 0;
  std::size_t degenerate = 0;
  std::size_t unreferenced = 0;
  std::size_t split_at_creases = 0;
};

// Keeps welded vertices apart where their normals differ: v merges into the first vertex of
// its weld group whose normal is bit-identical to its own.
void separate_by_normal(std::vector<std::uint32_t>& remap, const std::vector<Vec3>& normals) {
  std::map<std::array<std::int64_t, 4>, std::uint32_t> first;
  for (std::size_t v = 0; v < remap.size(); ++v) {
    const Vec3& n = normals[v];
    const std::array<std::int64_t, 4> key = {remap[v], bits_of(n.x()), bits_of(n.y()),
                                             bits_of(n.z())};
    remap[v] = first.try_emplace(key, std::uint32_t(v)).first->second;
  }
}

// The triangles through the weld `remap`, less those it collapses and those with twice their
// area under `min_double_area` (counted in `degenerate`).
std::vector<Triangle> welded_triangles(const Mesh& mesh, const std::vector<std::uint32_t>& remap,
                                       double min_double_area, std::size_t& degenerate) {
  std::vector<Triangle> kept;
  kept.reserve(mesh.triangles.size());
  for (const Triangle& t : mesh.triangles) {
    const Triangle w = {remap[t[0]], remap[t[1]], remap[t[2]]};
    const bool collapsed = w[0] == w[1] || w[1] == w[2] || w[0] == w[2];
    const double area2 = collapsed ? 0.0 : double_area(mesh, w);
    if (collapsed || !(area2 > 0.0) || area2 < min_double_area) {
      ++degenerate;
      continue;
    }
    kept.push_back(w);
  }
  return kept;
}

// Welds, drops degenerate triangles and unused vertices, computes frames: from
// `file_normals` (one per position) when given, else smooth within creases. `name` starts
// every error message.
CleanCounts clean(Mesh& mesh, const LoadOptions& options, const std::string& name,
                  const std::vector<Vec3>* file_normals = nullptr) {
  // Structural problems are the caller's (in-memory meshes) or were reported by the loader.
  {
    Mesh bare;
    bare.positions = mesh.positions;  // validate without frames: they are recomputed below
    bare.triangles = mesh.triangles;
    validate(bare, name);
  }
  CleanCounts counts;
  const std::size_t triangles_in = mesh.triangles.size();
  const Bounds box = bounds(mesh);
  const double diagonal = diagonal_of(box);

  std::vector<Vec3> unit_normals;
  if (file_normals != nullptr) {
    unit_normals.reserve(file_normals->size());
    for (const Vec3& n : *file_normals) unit_normals.push_back(n.normalized());
  }
  std::vector<std::uint32_t> remap = weld_map(mesh.positions, options.weld_tolerance, box);
  if (file_normals != nullptr) separate_by_normal(remap, unit_normals);
  for (std::size_t v = 0; v < remap.size(); ++v) {
    if (remap[v] != v) ++counts.welded;
  }

  std::vector<Triangle> kept =
      welded_triangles(mesh, remap, kDegenerateAreaRatio * diagonal * diagonal, counts.degenerate);

  // Compact: survivors keep their relative order.
  constexpr std::uint32_t kUnused = 0xFFFFFFFFu;
  std::vector<std::uint32_t> new_index(mesh.positions.size(), kUnused);
  for (const Triangle& t : kept) {
    for (std::uint32_t v : t) new_index[v] = 0;
  }
  std::vector<Vec3> positions, normals;
  positions.reserve(mesh.positions.size());
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    if (new_index[v] == kUnused) {
      if (remap[v] == v) ++counts.unreferenced;  // welded vertices are counted as welded
      continue;
    }
    new_index[v] = static_cast<std::uint32_t>(positions.size());
    positions.push_back(mesh.positions[v]);
    if (file_normals != nullptr) normals.push_back(unit_normals[v]);
  }
  for (Triangle& t : kept) {
    for (std::uint32_t& v : t) v = new_index[v];
  }

  if (kept.empty()) {
    std::ostringstream msg;
    msg << name << ": no faces left after clean-up: all " << triangles_in
        << " triangle(s) are degenerate (a repeated vertex, or zero area, after welding "
           "points closer than "
        << options.weld_tolerance
        << " x the bounding-box diagonal); check that the file holds a surface and, if its "
           "details are tiny next to its extent, lower LoadOptions::weld_tolerance";
    throw MeshError(msg.str());
  }

  mesh.positions = std::move(positions);
  mesh.triangles = std::move(kept);
  mesh.normals = std::move(normals);
  mesh.tangents.clear();
  mesh.bitangents.clear();
  if (file_normals != nullptr) {
    compute_tangents(mesh);
  } else {
    counts.split_at_creases = split_creases(mesh, options.crease_angle_deg);
    compute_frames(mesh, options.normal_weighting);
  }
  return counts;
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::string upper(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  return s;
}

std::string read_all(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Moves what one of our readers produced into the importer, which range-checks the indices.
void deliver(detail::RawPolygons& raw, CollectingImporter& importer) {
  importer.positions = std::move(raw.positions);
  importer.face_offsets = std::move(raw.face_offsets);
  importer.normals = std::move(raw.normals);
  importer.corners.reserve(raw.corners.size());
  for (const std::int64_t index : raw.corners) {
    if (index < 0 || std::uint64_t(index) >= importer.positions.size()) {
      if (!importer.has_bad_face) {
        importer.has_bad_face = true;
        const auto at = std::size_t(&index - raw.corners.data());
        importer.bad_face = std::size_t(
            std::upper_bound(importer.face_offsets.begin(), importer.face_offsets.end(), at) -
            importer.face_offsets.begin() - 1);
        importer.bad_index = index;
      }
      importer.corners.push_back(0);
    } else {
      importer.corners.push_back(std::uint32_t(index));
    }
  }
}

// True when every normal is finite and not zero, so that it has a direction.
bool usable_normals(const std::vector<Vec3>& normals) {
  return std::all_of(normals.begin(), normals.end(),
                     [](const Vec3& n) { return n.allFinite() && n.squaredNorm() > 0.f; });
}

// OpenMesh's OBJ reader gives positions and faces only, so the normals come from our own
// pass over the text, matched to the faces OpenMesh delivered (it skips some, see
// LoadReport) by their vertex indices. When every corner has a normal, each (v, vn) pair
// becomes a vertex: the first pair of a 'v' keeps its index, the others are appended.
// Anything that does not match leaves the importer without normals, as for a file without.
void attach_obj_normals(std::string_view text, CollectingImporter& importer) {
  detail::ObjNormals obj;
  detail::read_obj_normals(text, obj);
  if (obj.normals.empty() || !usable_normals(obj.normals)) return;
  const auto normal_count = std::int64_t(obj.normals.size());
  std::vector<std::uint32_t> normal_of_corner(importer.corners.size());
  const std::size_t obj_faces = obj.face_offsets.size() - 1;
  std::size_t j = 0;
  for (std::size_t f = 0; f < importer.face_count(); ++f) {
    const std::size_t begin = importer.face_offsets[f];
    const std::size_t k = importer.face_offsets[f + 1] - begin;
    bool found = false;
    for (; j < obj_faces && !found; ++j) {
      const std::size_t ob = obj.face_offsets[j];
      if (obj.face_offsets[j + 1] - ob != k) continue;
      bool same = true;
      for (std::size_t c = 0; c < k && same; ++c)
        same = obj.vertices[ob + c] == std::int64_t(importer.corners[begin + c]);
      if (!same) continue;
      for (std::size_t c = 0; c < k; ++c) {
        const std::int64_t n = obj.normal_of_corner[ob + c];
        if (n < 0 || n >= normal_count) return;  // a corner without a (valid) normal
        normal_of_corner[begin + c] = std::uint32_t(n);
      }
      found = true;
    }
    if (!found) return;
  }
  constexpr std::uint32_t kNone = 0xFFFFFFFFu;
  const std::size_t vertex_count = importer.positions.size();
  std::vector<std::uint32_t> first_normal(vertex_count, kNone);
  std::unordered_map<std::uint64_t, std::uint32_t> extra;  // (v << 32 | vn) -> vertex
  std::vector<Vec3> normals(vertex_count, Vec3::UnitY());  // unused vertices are dropped later
  for (std::size_t c = 0; c < importer.corners.size(); ++c) {
    std::uint32_t& v = importer.corners[c];
    const std::uint32_t n = normal_of_corner[c];
    if (first_normal[v] == kNone) {
      first_normal[v] = n;
      normals[v] = obj.normals[n];
    } else if (first_normal[v] != n) {
      const std::uint64_t key = (std::uint64_t(v) << 32) | n;
      const auto [it, fresh] = extra.try_emplace(key, std::uint32_t(importer.positions.size()));
      if (fresh) {
        const Vec3 p = importer.positions[v];
        importer.positions.push_back(p);
        normals.push_back(obj.normals[n]);
      }
      v = it->second;
    }
  }
  importer.split_by_normals = importer.positions.size() - vertex_count;
  importer.normals = std::move(normals);
}

// Fills `importer` from the file; returns false when OpenMesh's reader gave up, throws what
// `fail` makes for problems our own readers name.
template <class Fail>
bool parse(const fs::path& path, const std::string& format, std::uintmax_t size, bool want_normals,
           CollectingImporter& importer, const Fail& fail) {
  const std::lock_guard<std::mutex> lock(reader_mutex());
  omio::Options opt;
  if (format == "3ds" || format == "gltf" || format == "glb") {
    detail::ReferencedFiles referenced;
    const std::string refused = format == "3ds"   ? detail::check_3ds(path, size)
                                : format == "glb" ? detail::check_glb(path, size, referenced)
                                                  : detail::check_gltf(path, size, referenced);
    if (!refused.empty()) throw fail(refused);
    detail::RawPolygons raw;
    if (const std::string problem = detail::read_assimp(path, referenced, raw, format != "3ds");
        !problem.empty()) {
      throw fail(problem);
    }
    deliver(raw, importer);
    return true;
  }
  if (format == "off" || format == "ply") {
    const std::string bytes = read_all(path);
    detail::RawPolygons raw;
    const std::string problem =
        format == "off" ? detail::read_off(bytes, raw) : detail::read_ply(bytes, raw);
    if (!problem.empty()) {
      throw fail("could not parse this file as " + upper(format) + ": " + problem +
                 "; fix or re-export the file");
    }
    deliver(raw, importer);
    return true;
  }
  if (format == "stl") {
    // Through the stream interface, so the binary/ASCII decision is ours.
    std::string problem;
    const bool binary = is_binary_stl(path, size, problem);
    if (!problem.empty()) throw fail(problem);
    const std::string bytes = read_all(path);
    detail::RawPolygons raw;
    problem = binary ? detail::read_stl_binary(bytes, raw) : detail::read_stl_ascii(bytes, raw);
    if (!problem.empty()) {
      throw fail(std::string("could not parse this file as ") + (binary ? "binary" : "ASCII") +
                 " STL: " + problem);
    }
    deliver(raw, importer);
    return true;
  }
  // OBJ: OpenMesh asserts on face corners without a vertex number, so they never reach it.
  std::string text = read_all(path);
  if (const std::string problem = detail::normalise_obj_text(text); !problem.empty()) {
    throw fail("could not parse this file as OBJ: " + problem);
  }
  if (const std::string problem = detail::check_obj_faces(text); !problem.empty()) {
    throw fail("could not parse this file as OBJ: " + problem + "; fix the line");
  }
  // Materials are not used, and OpenMesh opens an 'mtllib' by whatever name it gives: a
  // FIFO blocked forever, ../../dev/zero read until memory ran out. So the reader gets the
  // file's text from memory with every mtllib line blanked, and opens nothing itself.
  detail::blank_obj_material_libraries(text);
  std::istringstream in(text);
  if (!omio::IOManager().read(in, ".obj", importer, opt)) return false;
  if (want_normals) attach_obj_normals(text, importer);
  return true;
}

// File-system problems first, each with its own fix; returns the lower-case format.
template <class Fail>
std::string check_source(const fs::path& path, const Fail& fail) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec && ec != std::errc::no_such_file_or_directory) {
    throw fail("cannot be inspected (" + ec.message() + "); check the path and permissions");
  }
  if (!fs::exists(status)) {
    throw fail("no such file; check the path (relative paths start at " +
               fs::current_path(ec).string() + ")");
  }
  if (fs::is_directory(status)) {
    throw fail("is a directory, not a mesh file; name a " + supported_list() + " file inside it");
  }
  const std::string extension = path.extension().string();
  const std::string format = lower(extension.empty() ? extension : extension.substr(1));
  if (std::find(kFormats.begin(), kFormats.end(), format) == kFormats.end()) {
    throw fail("unknown mesh format (" +
               (extension.empty() ? std::string("no extension") : "'" + extension + "'") +
               "); supported extensions are " + supported_list() +
               " (rename the file if it is one of these, or convert it, e.g. with meshlab)");
  }
  return format;
}

// Parses into `importer`. Memory use is bounded by the file's size (every reader checks counts
// against the bytes that are left), so running out of memory here means the file itself is
// too large.
template <class Fail>
void parse_checked(const fs::path& path, const std::string& format, bool want_normals,
                   CollectingImporter& importer, const Fail& fail) {
  std::error_code ec;
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec) throw fail("cannot read its size (" + ec.message() + "); check permissions");
  if (size == 0) throw fail("the file is empty (0 bytes); re-export the mesh");
  if (!std::ifstream(path, std::ios::binary)) {
    throw fail("cannot be opened for reading; check its permissions");
  }
  bool parsed = false;
  try {
    parsed = parse(path, format, size, want_normals, importer, fail);
  } catch (const std::bad_alloc&) {
    throw fail("too large to load into memory (" + std::to_string(size) +
               " bytes); free memory or simplify the mesh");
  } catch (const std::length_error&) {
    throw fail("too large to load into memory (" + std::to_string(size) +
               " bytes); free memory or simplify the mesh");
  }
  if (!parsed) {
    throw fail("could not parse this file as " + upper(format) + "; check that it is a valid ." +
               format + " file (re-export it if unsure)");
  }
}

// What the reader delivered must name existing, finite vertices and hold faces.
template <class Fail>
void check_parsed(const CollectingImporter& importer, const std::string& format, const Fail& fail) {
  if (importer.has_bad_face) {
    std::ostringstream msg;
    msg << "face " << importer.bad_face << " (0-based, in file order) refers to vertex "
        << importer.bad_index << ", which does not exist (the reader found "
        << importer.positions.size()
        << " vertices); a vertex line may be malformed (OpenMesh's text readers skip "
           "coordinates they cannot parse, such as 'nan' or 'inf'); fix the file";
    throw fail(msg.str());
  }
  if (importer.positions.empty() && importer.face_count() == 0) {
    throw fail("no vertices and no faces found; check that this is really a ." + format +
               " mesh file (the " + upper(format) + " reader skips " +
               (format == "obj" || format == "stl" ? "lines" : "records") + " it does not know)");
  }
  if (importer.face_count() == 0) {
    throw fail("the file has no faces, only " + std::to_string(importer.positions.size()) +
               " vertices; a point cloud cannot be baked, export the surface with its faces");
  }
  for (std::size_t v = 0; v < importer.positions.size(); ++v) {
    if (!importer.positions[v].allFinite()) {
      throw fail("vertex " + std::to_string(v) +
                 " (0-based, in file order) has a non-finite coordinate " +
                 describe_point(importer.positions[v]) + "; fix or remove it");
    }
  }
}

// Fan-triangulates: corners c0 ... c(k-1) give (c0, ci, ci+1). A face with fewer than three
// corners has no area and counts as one degenerate triangle (returned).
std::size_t triangulate(CollectingImporter& importer, Mesh& mesh, LoadReport& report) {
  report.file_vertices = importer.positions.size() - importer.split_by_normals;
  report.file_faces = importer.face_count();
  mesh.positions = std::move(importer.positions);
  std::size_t short_faces = 0;
  for (std::size_t f = 0; f < importer.face_count(); ++f) {
    const std::size_t begin = importer.face_offsets[f];
    const std::size_t k = importer.face_offsets[f + 1] - begin;
    if (k < 3) {
      ++short_faces;
      continue;
    }
    if (k > 3) ++report.polygons_triangulated;
    const std::uint32_t* c = importer.corners.data() + begin;
    for (std::size_t i = 1; i + 1 < k; ++i) mesh.triangles.push_back({c[0], c[i], c[i + 1]});
  }
  report.triangles_after_triangulation = mesh.triangles.size() + short_faces;
  return short_faces;
}

}  // namespace

void clean_mesh(Mesh& mesh, const LoadOptions& options, LoadReport* report) {
  const std::size_t vertices_in = mesh.positions.size();
  const std::size_t triangles_in = mesh.triangles.size();
  const std::string name =
      report != nullptr && !report->path.empty() ? report->path : std::string("in-memory mesh");
  const CleanCounts counts = clean(mesh, options, name);
  if (report != nullptr) {
    report->file_vertices = vertices_in;
    report->file_faces = triangles_in;
    report->triangles_after_triangulation = triangles_in;
    report->polygons_triangulated = 0;
    report->degenerate_faces_dropped = counts.degenerate;
    report->vertices_welded = counts.welded;
    report->unreferenced_vertices_dropped = counts.unreferenced;
    report->normals_from_file = false;
    report->vertices_split_by_file_normals = 0;
    report->vertices_split_at_creases = counts.split_at_creases;
  }
}

Mesh load_mesh(const fs::path& path, const LoadOptions& options, LoadReport* report) {
  const std::string name = path.string();
  const auto fail = [&](const std::string& problem) -> MeshError {
    return MeshError(name + ": " + problem);
  };
  const std::string format = check_source(path, fail);
  CollectingImporter importer;
  parse_checked(path, format, options.file_normals, importer, fail);
  check_parsed(importer, format, fail);

  LoadReport local;
  local.path = name;
  local.format = format;
  Mesh mesh;
  std::vector<Vec3> normals = std::move(importer.normals);
  const bool normals_from_file = options.file_normals && !normals.empty() &&
                                 normals.size() == importer.positions.size() &&
                                 usable_normals(normals);
  // Unusable normals after the OBJ pass split vertices by them: the copies sit at
  // bit-identical positions, so welding merges them again.
  local.vertices_split_by_file_normals = normals_from_file ? importer.split_by_normals : 0;
  const std::size_t short_faces = triangulate(importer, mesh, local);
  if (mesh.triangles.empty()) {
    throw fail("none of its " + std::to_string(short_faces) +
               " faces has three corners (they are points or edges); export the surface");
  }
  const CleanCounts counts = clean(mesh, options, name, normals_from_file ? &normals : nullptr);
  local.normals_from_file = normals_from_file;
  local.vertices_split_at_creases = counts.split_at_creases;
  local.degenerate_faces_dropped = counts.degenerate + short_faces;
  local.vertices_welded = counts.welded;
  local.unreferenced_vertices_dropped = counts.unreferenced;
  validate(mesh, name);
  if (report != nullptr) *report = local;
  return mesh;
}

}  // namespace meshes
