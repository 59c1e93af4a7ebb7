// Normals and creases at load time: a file's own normals are kept (OBJ vn, PLY nx ny nz),
// and without them vertices are split where faces meet at more than the crease angle. Checked
// against face normals computed here from the positions, and against the file's values.
#include "meshes/creases.h"
#include "meshes/load.h"
#include "meshes/procedural.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <string>

namespace {

namespace fs = std::filesystem;
using meshes::Mesh;
using meshes::Vec3;

fs::path write_file(const std::string& name, const std::string& content) {
  return test_support::write_scratch("creases", name, content);
}

// Blender's auto-smooth angle: the cube's 90-degree edges are hard, a sphere's are not.
meshes::LoadOptions auto_smooth() {
  meshes::LoadOptions o;
  o.crease_angle_deg = 30;
  return o;
}

Vec3 face_normal(const Mesh& m, const meshes::Triangle& t) {
  return (m.positions[t[1]] - m.positions[t[0]])
      .cross(m.positions[t[2]] - m.positions[t[0]])
      .normalized();
}

// Largest angle (as 1 - cos) between a corner's vertex normal and its face's normal.
double worst_flatness(const Mesh& m) {
  double worst = 0;
  for (const meshes::Triangle& t : m.triangles) {
    const Vec3 n = face_normal(m, t);
    for (std::uint32_t v : t) worst = std::max(worst, 1.0 - double(m.normals[v].dot(n)));
  }
  return worst;
}

TEST(Creases, CubeWithoutNormalsLoadsWithFlatFaces) {
  meshes::LoadReport report;
  const Mesh m = meshes::load_mesh(write_file("cube.obj", test_support::cube_obj(false)),
                                   auto_smooth(), &report);
  EXPECT_EQ(report.file_vertices, 8u);
  EXPECT_FALSE(report.normals_from_file);
  // Each corner of the cube is shared by three faces at 90 degrees: one vertex per face.
  EXPECT_EQ(m.vertex_count(), 24u);
  EXPECT_EQ(report.vertices_split_at_creases, 16u);
  EXPECT_EQ(m.triangle_count(), 12u);
  EXPECT_LT(worst_flatness(m), 1e-6);
}

TEST(Creases, CreaseAngleBoundsGiveAllSmoothAndAllFlat) {
  const fs::path cube = write_file("cube.obj", test_support::cube_obj(false));
  meshes::LoadOptions smooth;
  smooth.crease_angle_deg = 180;
  const Mesh m = meshes::load_mesh(cube, smooth);
  ASSERT_EQ(m.vertex_count(), 8u);
  // Every corner's normal points along the diagonal (three equal angles of 90 degrees).
  for (std::size_t v = 0; v < 8; ++v) {
    const Vec3 expected = m.positions[v].normalized();
    EXPECT_GT(m.normals[v].dot(expected), 1 - 1e-6) << "vertex " << v;
  }

  // A sphere's neighbouring faces meet at a few degrees: flat only when the angle is 0.
  Mesh sphere = meshes::make_sphere(1.f, 24, 12);
  Mesh flat = sphere;
  meshes::LoadOptions zero;
  zero.crease_angle_deg = 0;
  meshes::clean_mesh(flat, zero);
  EXPECT_LT(worst_flatness(flat), 1e-6);
  meshes::clean_mesh(sphere, auto_smooth());
  EXPECT_GT(worst_flatness(sphere), 1e-3);
  // The default is all smooth (meshes/creases.h says why).
  EXPECT_EQ(meshes::load_mesh(cube).vertex_count(), 8u);
}

TEST(Creases, SmoothSurfaceIsLeftBitForBitAsBefore) {
  // No edge of a finely tessellated sphere reaches the default angle: the loader's result
  // must be exactly the all-smooth one, vertex order and normals included.
  Mesh with_creases = meshes::make_sphere(1.f, 32, 16);
  Mesh all_smooth = with_creases;
  meshes::LoadReport report;
  meshes::clean_mesh(with_creases, auto_smooth(), &report);
  meshes::LoadOptions smooth;
  smooth.crease_angle_deg = 180;
  meshes::clean_mesh(all_smooth, smooth);
  EXPECT_EQ(report.vertices_split_at_creases, 0u);
  ASSERT_EQ(with_creases.vertex_count(), all_smooth.vertex_count());
  EXPECT_EQ(with_creases.triangles, all_smooth.triangles);
  EXPECT_EQ(std::memcmp(with_creases.normals.data(), all_smooth.normals.data(),
                        all_smooth.normals.size() * sizeof(Vec3)),
            0);
}

TEST(Creases, SplitVerticesShareTheirPositionExactly) {
  // The bake shares ray origins between vertices at one position (meshes/weld.h): the copies
  // must be bit-identical, not merely close.
  Mesh m = meshes::load_mesh(write_file("cube.obj", test_support::cube_obj(false)), auto_smooth());
  for (const Vec3& p : m.positions) {
    int same = 0;
    for (const Vec3& q : m.positions) same += std::memcmp(p.data(), q.data(), sizeof(Vec3)) == 0;
    EXPECT_EQ(same, 3);
  }
}

TEST(Creases, ObjNormalsAreKeptAndWeldedOnlyWithEqualNormals) {
  meshes::LoadReport report;
  const Mesh m =
      meshes::load_mesh(write_file("cube_vn.obj", test_support::cube_obj(true)), {}, &report);
  EXPECT_TRUE(report.normals_from_file);
  EXPECT_EQ(report.file_vertices, 8u);
  EXPECT_EQ(report.vertices_split_by_file_normals, 16u);
  EXPECT_EQ(report.vertices_split_at_creases, 0u);
  EXPECT_EQ(m.vertex_count(), 24u);
  EXPECT_LT(worst_flatness(m), 1e-6);

  // Normals no computation would give (tilted off a flat quad) survive as written.
  const std::string quad =
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0.6 0.8\nvn 0.6 0 0.8\n"
      "f 1//1 2//2 3//1\nf 1//1 3//1 4//2\n";
  const Mesh q = meshes::load_mesh(write_file("tilted.obj", quad), {}, &report);
  EXPECT_TRUE(report.normals_from_file);
  ASSERT_EQ(q.vertex_count(), 4u);  // vertex 1 (0-based 0) and 3 use one normal each
  for (std::size_t v = 0; v < 4; ++v) {
    const Vec3 expected = (v == 1 || v == 3) ? Vec3(0.6f, 0, 0.8f) : Vec3(0, 0.6f, 0.8f);
    EXPECT_LT((q.normals[v] - expected).norm(), 1e-6) << "vertex " << v;
  }

  // A file where some corners lack a normal has none usable: computed, smooth quad.
  const std::string partial =
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0.6 0.8\n"
      "f 1//1 2//1 3//1\nf 1 3 4\n";
  const Mesh p = meshes::load_mesh(write_file("partial.obj", partial), {}, &report);
  EXPECT_FALSE(report.normals_from_file);
  for (const Vec3& n : p.normals) EXPECT_LT((n - Vec3(0, 0, 1)).norm(), 1e-6);
}

TEST(Creases, PlyNormalsAreKept) {
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nproperty float nx\nproperty float ny\nproperty float nz\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0 0 0 2\n1 0 0 0 0.6 0.8\n0 1 0 0.6 0 0.8\n3 0 1 2\n";
  meshes::LoadReport report;
  const Mesh m = meshes::load_mesh(write_file("normals.ply", ply), {}, &report);
  EXPECT_TRUE(report.normals_from_file);
  ASSERT_EQ(m.vertex_count(), 3u);
  EXPECT_LT((m.normals[0] - Vec3(0, 0, 1)).norm(), 1e-6);  // normalised
  EXPECT_LT((m.normals[1] - Vec3(0, 0.6f, 0.8f)).norm(), 1e-6);
  EXPECT_LT((m.normals[2] - Vec3(0.6f, 0, 0.8f)).norm(), 1e-6);
  // Frames stay orthonormal around the file's normals.
  for (std::size_t v = 0; v < 3; ++v) {
    EXPECT_NEAR(m.tangents[v].dot(m.normals[v]), 0, 1e-6);
    EXPECT_NEAR(m.tangents[v].norm(), 1, 1e-6);
  }
}

}  // namespace
