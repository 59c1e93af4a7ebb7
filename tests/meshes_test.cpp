// Tests for meshes/: procedural meshes against their closed forms (area, radius, normals,
// orientation, watertightness), frame invariants and continuity, welding, the four loaders,
// the real Stanford bunny, and every error path of load_mesh.
#include "meshes/frames.h"
#include "meshes/load.h"
#include "meshes/mesh.h"
#include "meshes/procedural.h"
#include "meshes/spatial_order.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <sys/stat.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <numbers>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace {

using meshes::Mesh;
using meshes::MeshError;
using meshes::Triangle;
using meshes::Vec3;
namespace fs = std::filesystem;

constexpr double kPi = std::numbers::pi;
const fs::path kBunny = "/usr/share/glmark2/models/bunny.obj";

// Frames are computed in double and stored in float: columns are unit and orthogonal to a few
// float ulps. 1e-5 leaves room for that and catches any real error (which is O(1)).
constexpr float kFrameTol = 1e-5f;

// --- Helpers ---------------------------------------------------------------------------------

fs::path tmp_dir() {
  const fs::path dir = fs::path(PRTR_TEST_TMPDIR) / "meshes";
  fs::create_directories(dir);
  return dir;
}

fs::path write_file(const std::string& name, const std::string& content) {
  const fs::path path = tmp_dir() / name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << content;
  return path;
}

Vec3 face_normal(const Mesh& m, const Triangle& t) {
  return (m.positions[t[1]] - m.positions[t[0]]).cross(m.positions[t[2]] - m.positions[t[0]]);
}

Vec3 centroid(const Mesh& m, const Triangle& t) {
  return (m.positions[t[0]] + m.positions[t[1]] + m.positions[t[2]]) / 3.f;
}

double total_area(const Mesh& m) {
  double a = 0.0;
  for (const Triangle& t : m.triangles) a += 0.5 * meshes::double_area(m, t);
  return a;
}

// Every frame orthonormal and right-handed (t x b = n), checked independently of validate().
void expect_frames_orthonormal(const Mesh& m) {
  ASSERT_TRUE(m.has_frames());
  ASSERT_EQ(m.tangents.size(), m.positions.size());
  ASSERT_EQ(m.bitangents.size(), m.positions.size());
  int failures = 0;
  for (std::size_t v = 0; v < m.positions.size() && failures < 5; ++v) {
    const Vec3 &t = m.tangents[v], &b = m.bitangents[v], &n = m.normals[v];
    const bool ok = std::abs(t.norm() - 1.f) < kFrameTol && std::abs(b.norm() - 1.f) < kFrameTol &&
                    std::abs(n.norm() - 1.f) < kFrameTol && std::abs(t.dot(b)) < kFrameTol &&
                    std::abs(t.dot(n)) < kFrameTol && std::abs(b.dot(n)) < kFrameTol &&
                    (t.cross(b) - n).norm() < kFrameTol;
    if (!ok) {
      ++failures;
      ADD_FAILURE() << "vertex " << v << ": t " << t.transpose() << ", b " << b.transpose()
                    << ", n " << n.transpose();
    }
  }
  EXPECT_NO_THROW(meshes::validate(m, "test mesh"));
}

// Number of triangles on each undirected edge, and of each directed edge.
std::map<std::pair<std::uint32_t, std::uint32_t>, int> undirected_edges(const Mesh& m) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> count;
  for (const Triangle& t : m.triangles) {
    for (int i = 0; i < 3; ++i) {
      const std::uint32_t a = t[i], b = t[(i + 1) % 3];
      ++count[{std::min(a, b), std::max(a, b)}];
    }
  }
  return count;
}

std::set<std::pair<std::uint32_t, std::uint32_t>> directed_edges(const Mesh& m, int* duplicates) {
  std::set<std::pair<std::uint32_t, std::uint32_t>> edges;
  *duplicates = 0;
  for (const Triangle& t : m.triangles) {
    for (int i = 0; i < 3; ++i) {
      if (!edges.insert({t[i], t[(i + 1) % 3]}).second) ++*duplicates;
    }
  }
  return edges;
}

// The message of the MeshError `f` throws; a test failure if it throws nothing.
template <class F>
std::string error_of(F&& f) {
  return test_support::message_of<MeshError>(f);
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// A unit cube [0,1]^3 as 6 separate quads of 4 vertices each (24 vertices), outward CCW.
Mesh cube_of_separate_quads(float scale = 1.f) {
  const std::vector<std::array<Vec3, 4>> quads = {
      {Vec3(0, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 0), Vec3(1, 0, 0)},   // z = 0, -Z
      {Vec3(0, 0, 1), Vec3(1, 0, 1), Vec3(1, 1, 1), Vec3(0, 1, 1)},   // z = 1, +Z
      {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 0, 1), Vec3(0, 0, 1)},   // y = 0, -Y
      {Vec3(0, 1, 0), Vec3(0, 1, 1), Vec3(1, 1, 1), Vec3(1, 1, 0)},   // y = 1, +Y
      {Vec3(0, 0, 0), Vec3(0, 0, 1), Vec3(0, 1, 1), Vec3(0, 1, 0)},   // x = 0, -X
      {Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(1, 1, 1), Vec3(1, 0, 1)}};  // x = 1, +X
  Mesh m;
  for (const auto& q : quads) {
    const auto base = static_cast<std::uint32_t>(m.positions.size());
    for (const Vec3& p : q) m.positions.push_back(scale * p);
    m.triangles.push_back({base, base + 1, base + 2});
    m.triangles.push_back({base, base + 2, base + 3});
  }
  return m;
}

// The same cube with 8 shared corners, as index lists of quads (0-based).
const std::vector<Vec3> kCubeCorners = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0),
                                        Vec3(0, 0, 1), Vec3(1, 0, 1), Vec3(1, 1, 1), Vec3(0, 1, 1)};
const std::vector<std::array<int, 4>> kCubeQuads = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                                                    {3, 7, 6, 2}, {0, 4, 7, 3}, {1, 2, 6, 5}};

std::string cube_obj() {
  std::ostringstream s;
  s << "# unit cube\n";
  for (const Vec3& p : kCubeCorners) s << "v " << p.x() << " " << p.y() << " " << p.z() << "\n";
  for (const auto& q : kCubeQuads) {
    s << "f " << q[0] + 1 << " " << q[1] + 1 << " " << q[2] + 1 << " " << q[3] + 1 << "\n";
  }
  return s.str();
}

std::string cube_off() {
  std::ostringstream s;
  s << "OFF\n8 6 0\n";
  for (const Vec3& p : kCubeCorners) s << p.x() << " " << p.y() << " " << p.z() << "\n";
  for (const auto& q : kCubeQuads)
    s << "4 " << q[0] << " " << q[1] << " " << q[2] << " " << q[3] << "\n";
  return s.str();
}

std::string cube_ply_ascii() {
  std::ostringstream s;
  s << "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\n"
       "property float z\nelement face 6\nproperty list uchar int vertex_indices\nend_header\n";
  for (const Vec3& p : kCubeCorners) s << p.x() << " " << p.y() << " " << p.z() << "\n";
  for (const auto& q : kCubeQuads)
    s << "4 " << q[0] << " " << q[1] << " " << q[2] << " " << q[3] << "\n";
  return s.str();
}

// The cube's 12 triangles, each with its own three corners, as STL writes them.
std::vector<std::array<Vec3, 3>> cube_triangles() {
  std::vector<std::array<Vec3, 3>> out;
  for (const auto& q : kCubeQuads) {
    out.push_back({kCubeCorners[q[0]], kCubeCorners[q[1]], kCubeCorners[q[2]]});
    out.push_back({kCubeCorners[q[0]], kCubeCorners[q[2]], kCubeCorners[q[3]]});
  }
  return out;
}

std::string cube_stl_ascii() {
  std::ostringstream s;
  s << "solid cube\n";
  for (const auto& t : cube_triangles()) {
    const Vec3 n = (t[1] - t[0]).cross(t[2] - t[0]).normalized();
    s << "  facet normal " << n.x() << " " << n.y() << " " << n.z() << "\n    outer loop\n";
    for (const Vec3& p : t) s << "      vertex " << p.x() << " " << p.y() << " " << p.z() << "\n";
    s << "    endloop\n  endfacet\n";
  }
  s << "endsolid cube\n";
  return s.str();
}

void put_u32(std::string& out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
}
void put_f32(std::string& out, float f) {
  std::uint32_t bits;
  std::memcpy(&bits, &f, 4);
  put_u32(out, bits);
}

std::string cube_stl_binary(const std::string& header_text) {
  std::string s = header_text;
  s.resize(80, ' ');
  const auto tris = cube_triangles();
  put_u32(s, static_cast<std::uint32_t>(tris.size()));
  for (const auto& t : tris) {
    const Vec3 n = (t[1] - t[0]).cross(t[2] - t[0]).normalized();
    for (int k = 0; k < 3; ++k) put_f32(s, n[k]);
    for (const Vec3& p : t) {
      for (int k = 0; k < 3; ++k) put_f32(s, p[k]);
    }
    s.push_back('\0');
    s.push_back('\0');
  }
  return s;
}

// --- mesh.h ----------------------------------------------------------------------------------

TEST(Mesh, BoundsAndDoubleAreaClosedForm) {
  Mesh m;
  m.positions = {Vec3(1, 2, 3), Vec3(4, 2, 3), Vec3(1, 6, 3), Vec3(-1, 0, 5)};
  m.triangles = {{0, 1, 2}};
  const meshes::Bounds b = meshes::bounds(m);
  EXPECT_EQ(b.min, Vec3(-1, 0, 3));
  EXPECT_EQ(b.max, Vec3(4, 6, 5));
  EXPECT_FLOAT_EQ(b.diagonal(), std::sqrt(25.f + 36.f + 4.f));
  EXPECT_EQ(b.center(), Vec3(1.5f, 3.f, 4.f));
  // Legs 3 and 4: area 6, doubled 12.
  EXPECT_FLOAT_EQ(meshes::double_area(m, m.triangles[0]), 12.f);
  EXPECT_EQ(meshes::bounds(Mesh{}).diagonal(), 0.f);
}

TEST(Mesh, ValidateNamesTheMeshAndTheProblem) {
  Mesh m = meshes::make_sphere(1.f, 8, 4);
  EXPECT_NO_THROW(meshes::validate(m, "sphere"));

  Mesh bad_index = m;
  bad_index.triangles[3][1] = static_cast<std::uint32_t>(m.positions.size());
  std::string msg = error_of([&] { meshes::validate(bad_index, "my-mesh"); });
  EXPECT_TRUE(contains(msg, "my-mesh") && contains(msg, "triangle 3")) << msg;

  Mesh nan_pos = m;
  nan_pos.positions[5].y() = std::numeric_limits<float>::quiet_NaN();
  msg = error_of([&] { meshes::validate(nan_pos, "my-mesh"); });
  EXPECT_TRUE(contains(msg, "my-mesh") && contains(msg, "vertex 5")) << msg;

  Mesh skewed = m;
  skewed.tangents[2] = (skewed.tangents[2] + 0.01f * skewed.normals[2]).normalized();
  msg = error_of([&] { meshes::validate(skewed, "my-mesh"); });
  EXPECT_TRUE(contains(msg, "my-mesh") && contains(msg, "orthogonal")) << msg;

  Mesh left_handed = m;
  left_handed.bitangents[2] = -left_handed.bitangents[2];
  msg = error_of([&] { meshes::validate(left_handed, "my-mesh"); });
  EXPECT_TRUE(contains(msg, "right-handed")) << msg;

  Mesh partial = m;
  partial.tangents.pop_back();
  msg = error_of([&] { meshes::validate(partial, "my-mesh"); });
  EXPECT_TRUE(contains(msg, "partially")) << msg;
}

TEST(Mesh, ContentHashIsFnv1aAndSensitive) {
  // FNV-1a of zero bytes is the offset basis.
  EXPECT_EQ(meshes::content_hash(Mesh{}), 14695981039346656037ull);
  // A reference value computed independently (Python, struct.pack('<3f'/'<3I')): FNV-1a over
  // the little-endian bytes of the floats, then of the indices.
  Mesh known;
  known.positions = {Vec3(1.f, 2.f, 3.f), Vec3(-0.5f, 0.25f, 8.f)};
  known.triangles = {{0, 1, 1}};
  EXPECT_EQ(meshes::content_hash(known), 9356866946039099272ull);

  const Mesh a = meshes::make_sphere(1.f, 16, 8);
  Mesh b = a;
  EXPECT_EQ(meshes::content_hash(a), meshes::content_hash(b));
  b.positions[7].x() = std::nextafter(b.positions[7].x(), 10.f);
  EXPECT_NE(meshes::content_hash(a), meshes::content_hash(b));
  Mesh c = a;
  std::swap(c.triangles[0][1], c.triangles[0][2]);
  EXPECT_NE(meshes::content_hash(a), meshes::content_hash(c));
  // Frames are not part of the content.
  Mesh d = a;
  d.normals.clear();
  EXPECT_EQ(meshes::content_hash(a), meshes::content_hash(d));
}

// --- procedural.h ----------------------------------------------------------------------------

TEST(Procedural, SphereIsRoundClosedAndFacesOut) {
  const float r = 2.f;
  const Vec3 c(1.f, -2.f, 0.5f);
  const Mesh m = meshes::make_sphere(r, 64, 32, c);
  EXPECT_EQ(m.vertex_count(), 2u + 64u * 31u);  // poles shared, 31 inner rings
  EXPECT_EQ(m.triangle_count(), 2u * 64u * 31u);

  for (std::size_t v = 0; v < m.vertex_count(); ++v) {
    // Float positions: relative error a few ulps.
    ASSERT_NEAR((m.positions[v] - c).norm(), r, 1e-5f * r) << "vertex " << v;
  }
  // Angle-weighted normals of the tessellation differ from the radial direction by O(h^2)
  // (worst next to the poles, where the triangles are thinnest): measured 6.0e-3, 1.5e-3,
  // 3.8e-4 for 32, 64, 128 segments. At 128 x 64 that is well inside 1e-3.
  const Mesh fine = meshes::make_sphere(r, 128, 64, c);
  for (std::size_t v = 0; v < fine.vertex_count(); ++v) {
    const Vec3 radial = (fine.positions[v] - c).normalized();
    ASSERT_LT((fine.normals[v] - radial).norm(), 1e-3f) << "vertex " << v;
  }

  // The polyhedron is inscribed, so its area is below 4 pi r^2. The deficit is quadratic in
  // the angle step (measured 0.80% at 32 x 16, 0.20% at 64 x 32); 1% bounds it at 64 x 32.
  const double sphere = 4.0 * kPi * r * r;
  const double area = total_area(m);
  EXPECT_LT(area, sphere);
  EXPECT_GT(area, 0.99 * sphere);

  // Watertight and consistently oriented: each edge on exactly two triangles, each directed
  // edge once (so the two triangles run it in opposite directions).
  for (const auto& [edge, count] : undirected_edges(m)) {
    ASSERT_EQ(count, 2) << "edge " << edge.first << "-" << edge.second;
  }
  int duplicates = 0;
  directed_edges(m, &duplicates);
  EXPECT_EQ(duplicates, 0);

  for (std::size_t f = 0; f < m.triangle_count(); ++f) {
    const Triangle& t = m.triangles[f];
    ASSERT_GT(face_normal(m, t).dot(centroid(m, t) - c), 0.f) << "triangle " << f;
  }
  expect_frames_orthonormal(m);
}

TEST(Procedural, TorusAreaAndOrientation) {
  const float R = 1.5f, r = 0.4f;
  // At 192 x 96 the angle-weighted normals are within 3.4e-4 of the exact ones (the error is
  // O(h^2): 5.4e-3 at 48 x 24, 1.4e-3 at 96 x 48), inside the 1e-3 checked below.
  const Mesh m = meshes::make_torus(R, r, 192, 96);
  EXPECT_EQ(m.vertex_count(), 192u * 96u);
  // The polyhedron is inscribed in both directions; the area deficit is quadratic in the
  // angle steps (measured 0.46% at 48 x 24, 0.029% at 192 x 96); 0.5% bounds it here.
  const double torus = 4.0 * kPi * kPi * R * r;
  const double area = total_area(m);
  EXPECT_LT(area, torus);
  EXPECT_GT(area, 0.995 * torus);

  for (const auto& [edge, count] : undirected_edges(m)) ASSERT_EQ(count, 2);
  for (std::size_t v = 0; v < m.vertex_count(); ++v) {
    const Vec3& p = m.positions[v];
    const Vec3 tube_centre = R * Vec3(p.x(), 0.f, p.z()).normalized();
    const Vec3 outward = p - tube_centre;
    ASSERT_NEAR(outward.norm(), r, 1e-5f);
    ASSERT_LT((m.normals[v] - outward.normalized()).norm(), 1e-3f) << "vertex " << v;
  }
  for (const Triangle& t : m.triangles) {
    const Vec3 p = centroid(m, t);
    const Vec3 tube_centre = R * Vec3(p.x(), 0.f, p.z()).normalized();
    ASSERT_GT(face_normal(m, t).dot(p - tube_centre), 0.f);
  }
  expect_frames_orthonormal(m);
}

TEST(Procedural, PlaneFacesUp) {
  const Mesh m = meshes::make_plane(3.f, 5, 0.25f);
  EXPECT_EQ(m.vertex_count(), 36u);
  EXPECT_EQ(m.triangle_count(), 50u);
  EXPECT_NEAR(total_area(m), 9.0, 1e-5);
  for (const Vec3& p : m.positions) EXPECT_EQ(p.y(), 0.25f);
  for (const Vec3& n : m.normals) EXPECT_EQ(n, Vec3(0, 1, 0));
  for (const Triangle& t : m.triangles) {
    EXPECT_GT(face_normal(m, t).normalized().y(), 1.f - 1e-6f);
  }
  // All normals are +Y, so the reference axis is X (the first with zero score) and the frame
  // is exact: t = +X, b = n x t = -Z.
  for (std::size_t v = 0; v < m.vertex_count(); ++v) {
    EXPECT_EQ(m.tangents[v], Vec3(1, 0, 0));
    EXPECT_EQ(m.bitangents[v], Vec3(0, 0, -1));
  }
  expect_frames_orthonormal(m);
}

TEST(Procedural, PlaneAndSphereGeometry) {
  const float radius = 0.5f, height = 1.5f;
  const Mesh m = meshes::make_plane_and_sphere(6.f, 24, radius, height, 32, 16);
  const Mesh plane = meshes::make_plane(6.f, 24);
  const Mesh sphere = meshes::make_sphere(radius, 32, 16);
  EXPECT_EQ(m.vertex_count(), plane.vertex_count() + sphere.vertex_count());
  EXPECT_EQ(m.triangle_count(), plane.triangle_count() + sphere.triangle_count());
  const Vec3 c(0.f, height, 0.f);
  for (std::size_t v = 0; v < m.vertex_count(); ++v) {
    const Vec3& p = m.positions[v];
    if (v < plane.vertex_count()) {
      EXPECT_EQ(p.y(), 0.f);
      EXPECT_EQ(m.normals[v], Vec3(0, 1, 0));
    } else {
      EXPECT_NEAR((p - c).norm(), radius, 1e-5f);
    }
  }
  expect_frames_orthonormal(m);
}

TEST(Procedural, OpenBoxHasFiveInwardFacesAndAnOpenTop) {
  const float s = 2.f, h = 0.5f * s;
  const Mesh m = meshes::make_open_box(s, 4);
  EXPECT_NEAR(total_area(m), 5.0 * s * s, 1e-4);

  // Group triangles by their (axis-aligned) unit normal: exactly five groups, one per face,
  // each of area s^2, with normals +Y (floor) and +-X, +-Z (walls) pointing inward.
  std::map<std::array<int, 3>, double> area_by_normal;
  for (const Triangle& t : m.triangles) {
    const Vec3 n = face_normal(m, t).normalized();
    const std::array<int, 3> key = {static_cast<int>(std::lround(n.x())),
                                    static_cast<int>(std::lround(n.y())),
                                    static_cast<int>(std::lround(n.z()))};
    ASSERT_NEAR(std::abs(n.x()) + std::abs(n.y()) + std::abs(n.z()), 1.f, 1e-6f);
    area_by_normal[key] += 0.5 * meshes::double_area(m, t);
    // Inward: the normal points from the face toward the box centre.
    ASSERT_GT(n.dot(Vec3::Zero() - centroid(m, t)), 0.f);
  }
  ASSERT_EQ(area_by_normal.size(), 5u);
  EXPECT_EQ(area_by_normal.count({0, -1, 0}), 0u) << "the top must be missing";
  for (const auto& [normal, area] : area_by_normal) EXPECT_NEAR(area, s * s, 1e-4);
  EXPECT_EQ(area_by_normal.count({0, 1, 0}), 1u);

  // Top open: no triangle lies in the plane y = +s/2.
  for (const Triangle& t : m.triangles) {
    const bool all_top =
        m.positions[t[0]].y() == h && m.positions[t[1]].y() == h && m.positions[t[2]].y() == h;
    ASSERT_FALSE(all_top);
  }
  // Sharp edges: every vertex normal is its own face's normal (faces do not share vertices).
  for (const Triangle& t : m.triangles) {
    const Vec3 n = face_normal(m, t).normalized();
    for (std::uint32_t v : t) ASSERT_LT((m.normals[v] - n).norm(), 1e-6f);
  }
  expect_frames_orthonormal(m);
}

TEST(Procedural, MergeOffsetsIndices) {
  const Mesh a = meshes::make_plane(1.f, 1);
  const Mesh b = meshes::make_sphere(1.f, 4, 2, Vec3(0, 3, 0));
  const Mesh m = meshes::merge({a, b});
  ASSERT_EQ(m.vertex_count(), a.vertex_count() + b.vertex_count());
  ASSERT_EQ(m.triangle_count(), a.triangle_count() + b.triangle_count());
  const auto off = static_cast<std::uint32_t>(a.vertex_count());
  for (std::size_t f = 0; f < b.triangle_count(); ++f) {
    const Triangle& t = m.triangles[a.triangle_count() + f];
    for (int k = 0; k < 3; ++k) EXPECT_EQ(t[k], b.triangles[f][k] + off);
  }
  expect_frames_orthonormal(m);
}

TEST(Procedural, RejectsBadParameters) {
  EXPECT_THROW(meshes::make_sphere(1.f, 2, 8), std::invalid_argument);
  EXPECT_THROW(meshes::make_sphere(-1.f), std::invalid_argument);
  EXPECT_THROW(meshes::make_torus(0.5f, 1.f), std::invalid_argument);
  EXPECT_THROW(meshes::make_plane(1.f, 0), std::invalid_argument);
  EXPECT_THROW(meshes::make_plane_and_sphere(6.f, 4, 1.f, 0.5f), std::invalid_argument);
}

// --- frames.h --------------------------------------------------------------------------------

TEST(Frames, TangentFromReference) {
  const Vec3 ref(1, 0, 0);
  // Generic normal: the tangent is the normalised projection of the reference.
  const Vec3 n = Vec3(1, 2, 3).normalized();
  const Vec3 t = meshes::tangent_from_reference(n, ref);
  const Vec3 expected = (ref - ref.dot(n) * n).normalized();
  EXPECT_LT((t - expected).norm(), 1e-6f);
  // Parallel and anti-parallel normals fall back to another axis and stay orthonormal.
  for (const Vec3& p : {Vec3(1, 0, 0), Vec3(-1, 0, 0), Vec3(1, 1e-5f, 0).normalized()}) {
    const Vec3 tp = meshes::tangent_from_reference(p, ref);
    EXPECT_NEAR(tp.norm(), 1.f, 1e-6f);
    EXPECT_NEAR(tp.dot(p), 0.f, 1e-6f);
  }
}

TEST(Frames, ReferenceAxisAvoidsTheNormals) {
  // A square in the YZ plane (normal +X): X scores highest, Y is the first of the two zero
  // scores, so the tangent is +Y everywhere and b = X x Y = +Z.
  Mesh m;
  m.positions = {Vec3(0, 0, 0), Vec3(0, 1, 0), Vec3(0, 1, 1), Vec3(0, 0, 1)};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  meshes::compute_frames(m);
  for (std::size_t v = 0; v < 4; ++v) {
    EXPECT_EQ(m.normals[v], Vec3(1, 0, 0));
    EXPECT_EQ(m.tangents[v], Vec3(0, 1, 0));
    EXPECT_EQ(m.bitangents[v], Vec3(0, 0, 1));
  }
}

TEST(Frames, AngleAndAreaWeighting) {
  // Vertex 0 is shared by a large triangle in the z = 0 plane (normal +Z, area 8) and a small
  // one in the x = 0 plane (normal +X, area 1/2); both have a right angle at vertex 0.
  // Angle weighting weighs them equally: n = (X + Z)/sqrt2. Area weighting favours the large
  // face by the area ratio 16.
  Mesh m;
  m.positions = {Vec3(0, 0, 0), Vec3(4, 0, 0), Vec3(0, 4, 0), Vec3(0, 0, -1), Vec3(0, 1, 0)};
  m.triangles = {{0, 1, 2}, {0, 3, 4}};
  const Vec3 nz = face_normal(m, m.triangles[0]).normalized();
  const Vec3 nx = face_normal(m, m.triangles[1]).normalized();
  ASSERT_LT((nz - Vec3(0, 0, 1)).norm(), 1e-6f);
  ASSERT_LT((nx - Vec3(1, 0, 0)).norm(), 1e-6f);

  meshes::compute_frames(m, meshes::NormalWeighting::kAngle);
  EXPECT_LT((m.normals[0] - (nx + nz).normalized()).norm(), 1e-6f);
  meshes::compute_frames(m, meshes::NormalWeighting::kArea);
  EXPECT_LT((m.normals[0] - (nx + 16.f * nz).normalized()).norm(), 1e-6f);
}

TEST(Frames, UnusedVertexGetsAValidFrame) {
  Mesh m = meshes::make_plane(1.f, 1);
  m.positions.push_back(Vec3(5, 5, 5));  // no face touches it
  meshes::compute_frames(m);
  EXPECT_EQ(m.normals.back(), Vec3(0, 1, 0));
  expect_frames_orthonormal(m);
}

TEST(Frames, TangentsVaryContinuouslyOnAFineSphere) {
  const Mesh m = meshes::make_sphere(1.f, 128, 64);
  expect_frames_orthonormal(m);

  // Find the reference axis: the one every bitangent is orthogonal to (b = n x t with t in
  // the plane of n and the axis).
  int axis = -1;
  for (int k = 0; k < 3; ++k) {
    bool all = true;
    for (const Vec3& b : m.bitangents) all = all && std::abs(b[k]) < 1e-4f;
    if (all) axis = k;
  }
  // The sphere's vertices crowd at the Y poles, so the axis must not be Y.
  ASSERT_TRUE(axis == 0 || axis == 2) << axis;

  // The field t = normalize(a - (a.n) n) turns by at most max(1, cot theta) radians per
  // radian moved on the sphere, theta being the angle to the nearer singular point +-a. So
  // away from those points (theta >= 20 deg) neighbours' tangents differ by at most
  // cot(20 deg) x the longest edge's angle (0.069 rad, a quad diagonal), about 11 deg; 10% on
  // top covers the edge's path passing closer to the singular point than its ends.
  const double min_theta = 20.0 * kPi / 180.0;
  double longest = 0.0;
  for (const auto& [edge, count] : undirected_edges(m)) {
    const Vec3 a = m.positions[edge.first], b = m.positions[edge.second];
    longest = std::max(longest, std::acos(std::clamp(double(a.dot(b)), -1.0, 1.0)));
  }
  const double bound = 1.1 * (1.0 / std::tan(min_theta)) * longest;
  EXPECT_LT(bound, 0.25);  // ~14 degrees: small, so the test is meaningful

  double worst = 0.0;
  std::size_t checked = 0;
  for (const auto& [edge, count] : undirected_edges(m)) {
    const Vec3 p = m.positions[edge.first], q = m.positions[edge.second];
    const double tp = std::acos(std::min(1.0, double(std::abs(p[axis])))),
                 tq = std::acos(std::min(1.0, double(std::abs(q[axis]))));
    if (std::min(tp, tq) < min_theta) continue;
    const Vec3 a = m.tangents[edge.first], b = m.tangents[edge.second];
    worst = std::max(worst, std::acos(std::clamp(double(a.dot(b)), -1.0, 1.0)));
    ++checked;
  }
  EXPECT_GT(checked, undirected_edges(m).size() / 2);
  EXPECT_LT(worst, bound) << "largest tangent turn between neighbours (rad)";
}

// --- load.h: clean-up ------------------------------------------------------------------------

// The clean-up with every edge smooth: for tests of welding on cubes, whose 90-degree edges
// would otherwise be split again at the default crease angle (creases_test.cpp).
meshes::LoadOptions all_smooth() {
  meshes::LoadOptions o;
  o.crease_angle_deg = 180;
  return o;
}

TEST(Clean, WeldsDuplicatedCornersOfACube) {
  for (float scale : {1.f, 1000.f, 1e-3f}) {
    Mesh m = cube_of_separate_quads(scale);
    ASSERT_EQ(m.vertex_count(), 24u);
    meshes::LoadReport report;
    meshes::clean_mesh(m, all_smooth(), &report);
    EXPECT_EQ(m.vertex_count(), 8u) << "scale " << scale;
    EXPECT_EQ(m.triangle_count(), 12u) << "scale " << scale;
    EXPECT_EQ(report.vertices_welded, 16u);
    EXPECT_EQ(report.degenerate_faces_dropped, 0u);
    EXPECT_EQ(report.unreferenced_vertices_dropped, 0u);
    EXPECT_EQ(report.file_vertices, 24u);
    EXPECT_EQ(report.file_faces, 12u);
    EXPECT_NEAR(total_area(m), 6.0 * scale * scale, 1e-5 * scale * scale);
    // Welded into a closed, consistently oriented surface.
    for (const auto& [edge, count] : undirected_edges(m)) EXPECT_EQ(count, 2);
    // Corners keep their first occurrence's index order: the first quad's four corners.
    EXPECT_EQ(m.positions[0], scale * Vec3(0, 0, 0));
    EXPECT_EQ(m.positions[1], scale * Vec3(0, 1, 0));
    expect_frames_orthonormal(m);
  }
}

TEST(Clean, WeldToleranceIsRelativeToTheBoundingBox) {
  // The cube's diagonal is sqrt(3); move one duplicate corner by 1e-7 of it (welds at the
  // default 1e-6) or by 1e-5 of it (does not).
  for (float scale : {1.f, 1000.f}) {
    const float diag = std::sqrt(3.f) * scale;
    Mesh near = cube_of_separate_quads(scale);
    near.positions[4].x() += 1e-7f * diag;
    meshes::clean_mesh(near, all_smooth());
    EXPECT_EQ(near.vertex_count(), 8u);

    Mesh far = cube_of_separate_quads(scale);
    far.positions[4].x() += 1e-5f * diag;
    meshes::clean_mesh(far, all_smooth());
    EXPECT_EQ(far.vertex_count(), 9u);
  }
  // Negative tolerance: no welding at all.
  Mesh m = cube_of_separate_quads();
  meshes::LoadOptions no_weld = all_smooth();
  no_weld.weld_tolerance = -1.0;
  meshes::clean_mesh(m, no_weld);
  EXPECT_EQ(m.vertex_count(), 24u);
  // Zero tolerance welds bit-identical positions only.
  Mesh exact = cube_of_separate_quads();
  exact.positions[4].x() = std::nextafter(exact.positions[4].x(), 1.f);
  meshes::LoadOptions zero = all_smooth();
  zero.weld_tolerance = 0.0;
  meshes::clean_mesh(exact, zero);
  EXPECT_EQ(exact.vertex_count(), 9u);
}

TEST(Clean, WeldMergesIntoTheLowestIndexWithinReach) {
  // A and B are 1.5 eps apart (both survive); C lies between them, within eps of both, and
  // must merge into A, the lower index, whatever order the hash grid visits them in.
  const double tol = 0.01;
  const float eps = static_cast<float>(tol * std::sqrt(2.0));  // bbox diagonal is sqrt(2)
  const Vec3 a(0.5f, 0.2f, 0.f);
  for (bool b_first : {false, true}) {  // A's index below B's, and the other way round
    Mesh m;
    m.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
    const Vec3 b = a + Vec3(1.5f * eps, 0.f, 0.f), c = a + Vec3(0.75f * eps, 0.f, 0.f);
    m.positions.push_back(b_first ? b : a);  // 3
    m.positions.push_back(b_first ? a : b);  // 4
    m.positions.push_back(c);                // 5
    m.triangles = {{3, 1, 2}, {4, 0, 1}, {5, 0, 2}};
    meshes::LoadOptions options;
    options.weld_tolerance = tol;
    meshes::LoadReport report;
    meshes::clean_mesh(m, options, &report);
    EXPECT_EQ(report.vertices_welded, 1u);
    ASSERT_EQ(m.triangle_count(), 3u);
    // C went to the lower of indices 3 and 4.
    EXPECT_EQ(m.positions[m.triangles[2][0]], b_first ? b : a) << "b_first " << b_first;
  }
}

TEST(Clean, DropsAndCountsDegenerateFacesAndUnusedVertices) {
  Mesh m;
  m.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0),
                 Vec3(2, 0, 0), Vec3(7, 7, 7),  // unreferenced
                 Vec3(0, 0, 0)};                // duplicate of 0, welded
  m.triangles = {{0, 1, 2},                     // good
                 {0, 0, 2},                     // repeated index
                 {0, 1, 3},                     // collinear: zero area
                 {5, 0, 1}};                    // repeated after welding 5 -> 0
  meshes::LoadReport report;
  meshes::clean_mesh(m, {}, &report);
  EXPECT_EQ(m.triangle_count(), 1u);
  EXPECT_EQ(m.vertex_count(), 3u);
  EXPECT_EQ(report.degenerate_faces_dropped, 3u);
  EXPECT_EQ(report.vertices_welded, 1u);
  EXPECT_EQ(report.unreferenced_vertices_dropped, 2u);  // (2,0,0) and (7,7,7)
  EXPECT_EQ(report.triangles_after_triangulation,
            m.triangle_count() + report.degenerate_faces_dropped);
  expect_frames_orthonormal(m);
}

TEST(Clean, RejectsNonFiniteAndAllDegenerate) {
  Mesh nan_mesh = cube_of_separate_quads();
  nan_mesh.positions[3].z() = std::numeric_limits<float>::infinity();
  std::string msg = error_of([&] { meshes::clean_mesh(nan_mesh); });
  EXPECT_TRUE(contains(msg, "vertex 3")) << msg;

  Mesh flat;
  flat.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)};
  flat.triangles = {{0, 1, 2}, {2, 1, 0}};
  meshes::LoadReport report;
  report.path = "flat-thing";
  msg = error_of([&] { meshes::clean_mesh(flat, {}, &report); });
  EXPECT_TRUE(contains(msg, "flat-thing") && contains(msg, "no faces left")) << msg;
}

// --- load.h: formats -------------------------------------------------------------------------

TEST(Load, SameCubeFromEveryFormat) {
  struct Case {
    std::string file, content, format;
    std::size_t file_faces, polygons;
  };
  const std::vector<Case> cases = {
      {"cube.obj", cube_obj(), "obj", 6, 6},
      {"cube.off", cube_off(), "off", 6, 6},
      {"cube.ply", cube_ply_ascii(), "ply", 6, 6},
      {"cube_ascii.stl", cube_stl_ascii(), "stl", 12, 0},
      {"cube_binary.stl", cube_stl_binary("binary cube"), "stl", 12, 0},
      // A binary STL whose header starts with "solid", which OpenMesh's own detection
      // would take for ASCII.
      {"cube_solid_header.stl", cube_stl_binary("solid cube, binary"), "stl", 12, 0},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.file);
    const fs::path path = write_file(c.file, c.content);
    meshes::LoadReport report;
    const Mesh m = meshes::load_mesh(path, all_smooth(), &report);
    EXPECT_EQ(m.vertex_count(), 8u);
    EXPECT_EQ(m.triangle_count(), 12u);
    EXPECT_EQ(report.format, c.format);
    EXPECT_EQ(report.path, path.string());
    EXPECT_EQ(report.file_faces, c.file_faces);
    EXPECT_EQ(report.polygons_triangulated, c.polygons);
    EXPECT_EQ(report.triangles_after_triangulation, 12u);
    EXPECT_EQ(report.degenerate_faces_dropped, 0u);
    EXPECT_NEAR(total_area(m), 6.0, 1e-5);
    for (const auto& [edge, count] : undirected_edges(m)) EXPECT_EQ(count, 2);
    const Vec3 centre(0.5f, 0.5f, 0.5f);
    for (const Triangle& t : m.triangles) {
      EXPECT_GT(face_normal(m, t).dot(centroid(m, t) - centre), 0.f);
    }
    expect_frames_orthonormal(m);
  }
}

TEST(Load, QuadIsFanTriangulatedAndUppercaseExtensionWorks) {
  const std::string quad = "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nv 0.5 0 1.5\nf 1 4 5 3 2\n";
  for (const std::string name : {"pentagon.obj", "PENTAGON.OBJ"}) {
    SCOPED_TRACE(name);
    meshes::LoadReport report;
    const Mesh m = meshes::load_mesh(write_file(name, quad), {}, &report);
    EXPECT_EQ(report.file_faces, 1u);
    EXPECT_EQ(report.polygons_triangulated, 1u);
    EXPECT_EQ(report.triangles_after_triangulation, 3u);
    EXPECT_EQ(m.triangle_count(), 3u);
    EXPECT_EQ(report.format, "obj");
    EXPECT_NEAR(total_area(m), 1.25, 1e-6);
    for (const Vec3& n : m.normals) EXPECT_LT((n - Vec3(0, 1, 0)).norm(), 1e-6f);
  }
}

TEST(Load, ObjMaterialLibrariesAreNeverOpened) {
  // Materials are not used; an mtllib naming a FIFO used to block forever and one naming
  // ../../dev/zero to read until memory ran out.
  const fs::path obj = write_file("mtllib.obj",
                                  "mtllib mtllib.fifo\n  mtllib ../../../../../../../../dev/zero\n"
                                  "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const fs::path fifo = obj.parent_path() / "mtllib.fifo";
  fs::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const Mesh m = meshes::load_mesh(obj);
  EXPECT_EQ(m.vertex_count(), 3u);
  EXPECT_EQ(m.triangle_count(), 1u);
}

TEST(Load, KeepsNonManifoldFaces) {
  // Three triangles on one edge (a "fin"), which a halfedge mesh cannot hold: OpenMesh's
  // ImporterT would drop or split them. All three must arrive, on the original 5 vertices.
  const std::string fin =
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 0 -1 0\n"
      "f 1 2 3\nf 1 2 4\nf 1 2 5\n";
  meshes::LoadReport report;
  const Mesh m = meshes::load_mesh(write_file("fin.obj", fin), all_smooth(), &report);
  EXPECT_EQ(report.file_faces, 3u);
  EXPECT_EQ(m.triangle_count(), 3u);
  EXPECT_EQ(m.vertex_count(), 5u);
}

TEST(Load, CountsDegenerateFacesInAFile) {
  // OFF passes every face through: two good triangles, one with a repeated corner, one
  // collinear, one collapsing after the duplicate vertex 5 welds into vertex 0.
  const std::string off =
      "OFF\n6 5 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n2 0 0\n0 0 0\n"
      "3 0 1 2\n3 1 3 2\n3 0 0 2\n3 0 1 4\n3 5 0 2\n";
  meshes::LoadReport report;
  const Mesh m = meshes::load_mesh(write_file("degenerate.off", off), {}, &report);
  EXPECT_EQ(report.file_faces, 5u);
  EXPECT_EQ(m.triangle_count(), 2u);
  EXPECT_EQ(report.degenerate_faces_dropped, 3u);
  EXPECT_EQ(report.triangles_after_triangulation,
            m.triangle_count() + report.degenerate_faces_dropped);
  EXPECT_EQ(report.vertices_welded, 1u);
  EXPECT_EQ(report.unreferenced_vertices_dropped, 1u);  // (2, 0, 0)
  EXPECT_EQ(m.vertex_count(), 4u);
}

TEST(Load, ObjReaderSkipsFacesThatRepeatAVertex) {
  // A quirk of OpenMesh's OBJ reader, documented in LoadReport: "f 1 1 3" never reaches us,
  // so it is in neither file_faces nor degenerate_faces_dropped. If OpenMesh changes this,
  // the report doc must change with it.
  const std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 1 1 3\nf 2 4 3\n";
  meshes::LoadReport report;
  const Mesh m = meshes::load_mesh(write_file("repeated.obj", obj), {}, &report);
  EXPECT_EQ(m.triangle_count(), 2u);
  EXPECT_EQ(report.file_faces, 2u);
  EXPECT_EQ(report.degenerate_faces_dropped, 0u);
}

TEST(Load, StanfordBunny) {
  if (!fs::exists(kBunny)) GTEST_SKIP() << kBunny << " not installed (package glmark2-data)";
  meshes::LoadReport report;
  const Mesh m = meshes::load_mesh(kBunny, {}, &report);
  std::cout << "bunny: " << m.vertex_count() << " vertices, " << m.triangle_count()
            << " triangles; file " << report.file_vertices << " vertices, " << report.file_faces
            << " faces; dropped " << report.degenerate_faces_dropped << " degenerate faces, "
            << report.vertices_welded << " welded and " << report.unreferenced_vertices_dropped
            << " unreferenced vertices\n";
  EXPECT_EQ(report.file_vertices, 34835u);
  EXPECT_EQ(report.file_faces, 69666u);  // every 'f' line arrives
  EXPECT_EQ(report.polygons_triangulated, 0u);
  EXPECT_EQ(report.triangles_after_triangulation, report.file_faces);
  EXPECT_EQ(report.file_faces, m.triangle_count() + report.degenerate_faces_dropped);
  EXPECT_EQ(report.file_vertices,
            m.vertex_count() + report.vertices_welded + report.unreferenced_vertices_dropped);
  EXPECT_LT(report.degenerate_faces_dropped, 100u);
  // Exact, from the file itself: every 'v' line is a distinct position, so welding must keep
  // them all (and the report says none is unreferenced).
  std::ifstream obj(kBunny);
  std::set<std::string> positions;
  std::size_t v_lines = 0;
  for (std::string line; std::getline(obj, line);)
    if (line.rfind("v ", 0) == 0) ++v_lines, positions.insert(line);
  EXPECT_EQ(positions.size(), v_lines);
  EXPECT_EQ(m.vertex_count(), positions.size());
  expect_frames_orthonormal(m);

  const Mesh again = meshes::load_mesh(kBunny);
  EXPECT_EQ(meshes::content_hash(m), meshes::content_hash(again));
  EXPECT_EQ(m.normals, again.normals);
}

// --- load.h: errors --------------------------------------------------------------------------

// load_mesh(path) must throw a MeshError whose message names the file and contains `phrase`.
void expect_load_error(const fs::path& path, const std::string& phrase) {
  SCOPED_TRACE(path.string());
  const std::string msg = error_of([&] { meshes::load_mesh(path); });
  EXPECT_TRUE(contains(msg, path.filename().string())) << msg;
  EXPECT_TRUE(contains(msg, phrase)) << msg;
}

TEST(LoadErrors, FileSystemProblems) {
  expect_load_error(tmp_dir() / "does_not_exist.obj", "no such file");
  const fs::path dir = tmp_dir() / "a_directory.obj";
  fs::create_directories(dir);
  expect_load_error(dir, "directory");
  expect_load_error(write_file("points.xyz", "0 0 0\n1 0 0\n"), ".obj, .ply, .off, .stl");
  expect_load_error(write_file("no_extension", cube_obj()), "no extension");
  expect_load_error(write_file("empty.obj", ""), "empty");
}

TEST(LoadErrors, BadContent) {
  // Garbage the PLY and OFF parsers reject outright.
  expect_load_error(write_file("garbage.ply", "this is not a mesh\n\x01\x02\x03"), "parse");
  expect_load_error(write_file("garbage.off", "hello world\n"), "parse");
  // Garbage the OBJ parser skips line by line, leaving nothing; the STL reader stops at once.
  expect_load_error(write_file("garbage.obj", "hello world\nthis is garbage\n"), "no faces");
  expect_load_error(write_file("garbage.stl", "hello world\nthis is garbage\n"),
                    "does not start with 'solid'");
  expect_load_error(write_file("random.obj", std::string("\x7f\x00\xff\x13 binary junk", 17)),
                    "no faces");
  // Vertices only.
  expect_load_error(write_file("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n"), "no faces");
  // Every face degenerate.
  expect_load_error(
      write_file("all_degenerate.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\nf 1 1 2\n"),
      "no faces left");
  // Out-of-range index.
  expect_load_error(write_file("bad_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"),
                    "does not exist");
}

TEST(LoadErrors, NonFiniteCoordinates) {
  // Binary PLY carries the NaN bits through to us.
  std::string ply =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  const float coords[9] = {0, 0, 0, 1, std::numeric_limits<float>::quiet_NaN(), 0, 0, 1, 0};
  for (float f : coords) put_f32(ply, f);
  ply.push_back(3);
  for (std::uint32_t i : {0u, 1u, 2u}) put_u32(ply, i);
  expect_load_error(write_file("nan.ply", ply), "vertex 1");
  expect_load_error(tmp_dir() / "nan.ply", "non-finite");

  // OpenMesh's OBJ reader cannot parse "nan" and skips the vertex; the face then points past
  // the vertices it has, which is reported with a hint.
  expect_load_error(write_file("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n"), "nan");
}

}  // namespace

// --- 3DS ---------------------------------------------------------------------------------------

namespace {

// A chunk: id, total length (header included), body.
std::string chunk(std::uint16_t id, const std::string& body) {
  std::string s(6, '\0');
  const std::uint32_t length = std::uint32_t(6 + body.size());
  std::memcpy(s.data(), &id, 2);
  std::memcpy(s.data() + 2, &length, 4);
  return s + body;
}

template <class T>
std::string bytes_of(const T& value) {
  return std::string(reinterpret_cast<const char*>(&value), sizeof value);
}

// One object with a quad as two triangles, 3DS Z-up coordinates.
std::string quad_3ds() {
  std::string vertices = bytes_of(std::uint16_t(4));
  const float p[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  for (const auto& v : p) vertices += std::string(reinterpret_cast<const char*>(v), 12);
  std::string faces = bytes_of(std::uint16_t(2));
  const std::uint16_t f[2][4] = {{0, 1, 2, 7}, {0, 2, 3, 7}};
  for (const auto& t : f) faces += std::string(reinterpret_cast<const char*>(t), 8);
  const std::string mesh = chunk(0x4100, chunk(0x4110, vertices) + chunk(0x4120, faces));
  return chunk(0x4D4D, chunk(0x3D3D, chunk(0x4000, std::string("quad") + '\0' + mesh)));
}

}  // namespace

TEST(Load, ThreeDsGeometryIsConvertedToYUp) {
  const Mesh m = meshes::load_mesh(write_file("quad.3ds", quad_3ds()));
  ASSERT_EQ(m.vertex_count(), 4u);
  ASSERT_EQ(m.triangle_count(), 2u);
  // 3DS (x, y, z) -> (x, z, -y): the quad in the 3DS ground plane lies in our XZ plane, and
  // its counter-clockwise winding about 3DS +Z now faces our +Y.
  for (const Vec3& p : m.positions) EXPECT_FLOAT_EQ(p.y(), 0.f);
  for (const Triangle& t : m.triangles) EXPECT_GT(face_normal(m, t).normalized().y(), 0.999f);
}

TEST(LoadErrors, DamagedThreeDsChunks) {
  std::string truncated = quad_3ds();
  truncated.resize(truncated.size() - 10);  // the face list claims more than is there
  expect_load_error(write_file("truncated.3ds", truncated), "damaged");
  expect_load_error(write_file("notthreeds.3ds", "hello, not a 3ds file"), "not a 3DS file");
  // A vertex list claiming more records than its chunk holds, chunk lengths all consistent.
  std::string short_list = quad_3ds();
  const std::size_t count_at = short_list.find(std::string("\x10\x41", 2)) + 6;
  short_list[count_at] = 9;
  expect_load_error(write_file("short_list.3ds", short_list),
                    "vertex list chunk at byte 29 claims 9 records of 12 bytes in 56 bytes");
}

TEST(Load, GlmarkHorse) {
  const fs::path horse = "/usr/share/glmark2/models/horse.3ds";
  if (!fs::exists(horse)) GTEST_SKIP() << horse << " not installed (package glmark2-data)";
  const Mesh m = meshes::load_mesh(horse);
  EXPECT_EQ(m.vertex_count(), 3582u);
  EXPECT_EQ(m.triangle_count(), 7172u);
}

TEST(Frames, FoldedBackSliversDoNotTurnTheNormalInward) {
  // A fan at the origin: two faces of 30 degrees each facing +Y carry almost all the area;
  // two slivers of 160 degrees each fold back under them, facing -Y, with 1e-4 of the area.
  // By corner angle the slivers win 320 to 60 and the normal would point to -Y, away from
  // almost all of the fan, as at a fold-back corner of a scanned mesh.
  const double kDeg = std::numbers::pi / 180.0;
  auto at = [&](double degrees, double radius) {
    return Vec3(static_cast<float>(radius * std::cos(degrees * kDeg)), 0.f,
                static_cast<float>(-radius * std::sin(degrees * kDeg)));
  };
  Mesh m;
  m.positions = {Vec3::Zero(), at(0, 1),       at(30, 1),     at(60, 1),
                 at(0, 0.01),  at(-160, 0.01), at(-320, 0.01)};
  m.triangles = {{0, 1, 2}, {0, 2, 3}, {0, 4, 5}, {0, 5, 6}};
  for (std::size_t f = 0; f < 2; ++f) ASSERT_GT(face_normal(m, m.triangles[f]).y(), 0.f);
  for (std::size_t f = 2; f < 4; ++f) ASSERT_LT(face_normal(m, m.triangles[f]).y(), 0.f);

  meshes::compute_frames(m, meshes::NormalWeighting::kAngle);
  EXPECT_GT(m.normals[0].y(), 0.9999f) << m.normals[0].transpose();
  meshes::compute_frames(m, meshes::NormalWeighting::kArea);
  EXPECT_GT(m.normals[0].y(), 0.9999f) << m.normals[0].transpose();
}

// Morton order against an independent, bit-by-bit interleave: on a lattice whose vertices
// are numbered in a shuffled order, spatial_order must list them by the interleaved code.
TEST(SpatialOrder, MortonCodeInterleavesBits) {
  std::mt19937 rng(3);
  for (int i = 0; i < 2000; ++i) {
    const std::uint32_t c[3] = {std::uint32_t(rng() & 0x1fffff), std::uint32_t(rng() & 0x1fffff),
                                std::uint32_t(rng() & 0x1fffff)};
    std::uint64_t expected = 0;
    for (int bit = 0; bit < 21; ++bit) {
      for (int a = 0; a < 3; ++a) expected |= std::uint64_t((c[a] >> bit) & 1) << (3 * bit + a);
    }
    ASSERT_EQ(meshes::morton_code(c[0], c[1], c[2]), expected)
        << c[0] << " " << c[1] << " " << c[2];
  }
}

TEST(SpatialOrder, ALatticeComesOutInZOrderAndNeighboursStayNear) {
  // An 8 x 8 x 8 lattice on [0, 7]: cell k of an axis is Morton cell k * (2^21 - 1) / 7.
  const int n = 8;
  std::vector<std::array<int, 3>> cells;
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) cells.push_back({x, y, z});
  std::shuffle(cells.begin(), cells.end(), std::mt19937(5));
  meshes::Mesh mesh;
  for (const auto& c : cells) mesh.positions.emplace_back(float(c[0]), float(c[1]), float(c[2]));
  const std::vector<std::uint32_t> order = meshes::spatial_order(mesh);
  ASSERT_EQ(order.size(), cells.size());
  auto code = [&](std::uint32_t i) {
    auto q = [](int k) { return std::uint32_t(float(k) / 7.f * float((1 << 21) - 1)); };
    return meshes::morton_code(q(cells[i][0]), q(cells[i][1]), q(cells[i][2]));
  };
  for (std::size_t i = 1; i < order.size(); ++i) EXPECT_LT(code(order[i - 1]), code(order[i]));
  const std::vector<std::uint32_t> inverse = meshes::inverse_permutation(order);
  for (std::size_t i = 0; i < order.size(); ++i) EXPECT_EQ(inverse[order[i]], i);
  // Z-order visits each 2 x 2 x 2 block in turn: consecutive vertices 1 apart on average
  // at most 2, where the shuffled index order averages ~4.
  auto mean_step = [&](auto at) {
    double sum = 0;
    for (std::size_t i = 1; i < cells.size(); ++i)
      sum += (mesh.positions[at(i)] - mesh.positions[at(i - 1)]).norm();
    return sum / double(cells.size() - 1);
  };
  EXPECT_LT(mean_step([&](std::size_t i) { return order[i]; }), 2.0);
  EXPECT_GT(mean_step([](std::size_t i) { return i; }), 3.0);
}
