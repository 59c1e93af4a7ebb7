// tests/meshes_gltf_test.cpp: glTF 2.0 (.gltf, .glb) loading through meshes::load_mesh, and
// the guards in front of Assimp. Every file is written here; world positions are checked
// against the node transforms composed by the glTF rule (T * R * S, parent * child) with
// Eigen, independently of Assimp.
#include "common/base64.h"
#include "meshes/load.h"
#include "meshes/weld.h"
#include "test_support.h"

#include <gtest/gtest.h>
#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include <cstring>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using meshes::Mesh;
using meshes::Vec3;
using nlohmann::json;

fs::path write_file(const std::string& name, const std::string& content) {
  return test_support::write_scratch("meshes_gltf", name, content);
}

template <class T>
void put(std::string& out, T v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof v);
}

// Mesh 0: a triangle (non-indexed). Mesh 1: a unit quad as two indexed triangles.
const std::vector<Vec3> kTriangle = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
const std::vector<Vec3> kQuad = {{0, 0, 0}, {1, 0, 0}, {1, 0, -1}, {0, 0, -1}};

struct Scene {
  json gltf;
  std::string bin;
};

// Node 0 (TRS) has child node 1 (TRS) with the quad; node 2 (a matrix) has the triangle.
Scene two_mesh_scene() {
  Scene s;
  for (const Vec3& p : kTriangle) s.bin.append(reinterpret_cast<const char*>(p.data()), 12);
  for (const Vec3& p : kQuad) s.bin.append(reinterpret_cast<const char*>(p.data()), 12);
  for (std::uint16_t i : {0, 1, 2, 0, 2, 3}) put(s.bin, i);
  s.gltf = {{"asset", {{"version", "2.0"}}},
            {"scene", 0},
            {"scenes", {{{"nodes", {0, 2}}}}},
            {"nodes",
             {{{"translation", {1.0, 2.0, 3.0}},
               {"rotation", {0.0, 0.3826834, 0.0, 0.9238795}},  // 45 degrees about +Y
               {"scale", {2.0, 0.5, 1.0}},
               {"children", {1}}},
              {{"mesh", 1},
               {"translation", {0.0, 0.0, -4.0}},
               {"rotation", {0.5, 0.5, 0.5, 0.5}},  // 120 degrees about (1, 1, 1)
               {"scale", {3.0, 3.0, 3.0}}},
              {{"mesh", 0},
               {"matrix", {0, 1, 0, 0, -1, 0, 0, 0, 0, 0, 1, 0, 5, 0, 0, 1}}}}},  // column-major
            {"meshes",
             {{{"primitives", {{{"attributes", {{"POSITION", 0}}}}}}},
              {{"primitives", {{{"attributes", {{"POSITION", 1}}}, {"indices", 2}}}}}}},
            {"accessors",
             {{{"bufferView", 0},
               {"componentType", 5126},
               {"count", 3},
               {"type", "VEC3"},
               {"min", {0, 0, 0}},
               {"max", {1, 1, 0}}},
              {{"bufferView", 1},
               {"componentType", 5126},
               {"count", 4},
               {"type", "VEC3"},
               {"min", {0, 0, -1}},
               {"max", {1, 0, 0}}},
              {{"bufferView", 2}, {"componentType", 5123}, {"count", 6}, {"type", "SCALAR"}}}},
            {"bufferViews",
             {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 36}},
              {{"buffer", 0}, {"byteOffset", 36}, {"byteLength", 48}},
              {{"buffer", 0}, {"byteOffset", 84}, {"byteLength", 12}}}},
            {"buffers", {{{"byteLength", s.bin.size()}}}}};
  return s;
}

std::string as_gltf(Scene s) {
  s.gltf["buffers"][0]["uri"] =
      "data:application/octet-stream;base64," + common::base64_encode(s.bin);
  return s.gltf.dump();
}

std::string as_glb(const Scene& s) {
  std::string text = s.gltf.dump();
  while (text.size() % 4 != 0) text += ' ';
  std::string bin = s.bin;
  while (bin.size() % 4 != 0) bin += '\0';
  std::string out;
  put(out, std::uint32_t(0x46546C67));
  put(out, std::uint32_t(2));
  put(out, std::uint32_t(12 + 8 + text.size() + 8 + bin.size()));
  put(out, std::uint32_t(text.size()));
  put(out, std::uint32_t(0x4E4F534A));
  out += text;
  put(out, std::uint32_t(bin.size()));
  put(out, std::uint32_t(0x004E4942));
  return out + bin;
}

Eigen::Matrix4d trs(const Eigen::Vector3d& t, const Eigen::Quaterniond& r,
                    const Eigen::Vector3d& s) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = r.normalized().toRotationMatrix() * s.asDiagonal();
  m.topRightCorner<3, 1>() = t;
  return m;
}

// The world positions of two_mesh_scene(), composed by the glTF rule.
std::vector<Eigen::Vector3d> expected_world() {
  // Eigen's quaternion constructor takes (w, x, y, z); glTF stores (x, y, z, w).
  const Eigen::Matrix4d node0 =
      trs({1, 2, 3}, Eigen::Quaterniond(0.9238795, 0, 0.3826834, 0), {2, 0.5, 1});
  const Eigen::Matrix4d node1 = trs({0, 0, -4}, Eigen::Quaterniond(0.5, 0.5, 0.5, 0.5), {3, 3, 3});
  Eigen::Matrix4d node2;
  node2 << 0, -1, 0, 5, 1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1;
  std::vector<Eigen::Vector3d> out;
  for (const Vec3& p : kQuad) {
    out.push_back((node0 * node1 * p.cast<double>().homogeneous()).head<3>());
  }
  for (const Vec3& p : kTriangle) out.push_back((node2 * p.cast<double>().homogeneous()).head<3>());
  return out;
}

void expect_world_positions(const Mesh& m) {
  const std::vector<Eigen::Vector3d> expected = expected_world();
  ASSERT_EQ(m.vertex_count(), expected.size());
  ASSERT_EQ(m.triangle_count(), 3u);
  for (const Eigen::Vector3d& e : expected) {
    double nearest = 1e30;
    for (const Vec3& p : m.positions) nearest = std::min(nearest, (p.cast<double>() - e).norm());
    EXPECT_LT(nearest, 1e-5) << "no loaded vertex at " << e.transpose();
  }
}

void expect_load_error(const fs::path& path, const std::string& needle) {
  try {
    meshes::load_mesh(path);
    ADD_FAILURE() << path << " loaded, expected an error containing '" << needle << "'";
  } catch (const meshes::MeshError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path.string()), std::string::npos) << what;
    EXPECT_NE(what.find(needle), std::string::npos) << what;
  }
}

}  // namespace

TEST(Gltf, TwoMeshSceneIsFlattenedIntoWorldSpace) {
  meshes::LoadReport report;
  const Mesh m =
      meshes::load_mesh(write_file("scene.gltf", as_gltf(two_mesh_scene())), {}, &report);
  expect_world_positions(m);
  EXPECT_EQ(report.format, "gltf");
  EXPECT_EQ(report.file_vertices, 7u);
  EXPECT_EQ(report.file_faces, 3u);
}

TEST(Gltf, GlbAndExternalBufferGiveTheSameScene) {
  expect_world_positions(meshes::load_mesh(write_file("scene.glb", as_glb(two_mesh_scene()))));
  Scene s = two_mesh_scene();
  write_file("scene.bin", s.bin);
  s.gltf["buffers"][0]["uri"] = "scene.bin";
  expect_world_positions(meshes::load_mesh(write_file("external.gltf", s.gltf.dump())));
}

TEST(GltfErrors, SkinsAndMorphTargetsAreRefused) {
  Scene skinned = two_mesh_scene();
  skinned.gltf["skins"] = {{{"joints", {0}}}};
  skinned.gltf["nodes"][1]["skin"] = 0;
  expect_load_error(write_file("skinned.gltf", as_gltf(skinned)), "skins (bones)");
  Scene morph = two_mesh_scene();
  morph.gltf["meshes"][0]["primitives"][0]["targets"] = {{{"POSITION", 0}}};
  expect_load_error(write_file("morph.gltf", as_gltf(morph)), "morph targets");
}

TEST(GltfErrors, PointsOnlyIsRefused) {
  Scene s = two_mesh_scene();
  for (json& mesh : s.gltf["meshes"]) mesh["primitives"][0]["mode"] = 0;
  expect_load_error(write_file("points.gltf", as_gltf(s)), "only points or lines");
}

TEST(GltfErrors, TruncatedOrLyingGlbIsRefused) {
  std::string glb = as_glb(two_mesh_scene());
  expect_load_error(write_file("truncated.glb", glb.substr(0, glb.size() - 20)), "truncated");
  // Header length patched to match, so the chunk's own claim is what gives it away.
  std::string cut = glb.substr(0, glb.size() - 20);
  const std::uint32_t n = std::uint32_t(cut.size());
  std::memcpy(cut.data() + 8, &n, 4);
  expect_load_error(write_file("short_chunk.glb", cut), "past the end of the file");
  expect_load_error(write_file("not.glb", "solid nothing\n"), "not a .glb file");
}

TEST(GltfErrors, ClaimsPastTheDataAreRefused) {
  Scene s = two_mesh_scene();
  s.gltf["accessors"][1]["count"] = 4000000000u;
  expect_load_error(write_file("big_count.gltf", as_gltf(s)), "accessor 1 claims 4000000000");
  Scene b = two_mesh_scene();
  b.gltf["buffers"][0]["byteLength"] = 1u << 30;
  expect_load_error(write_file("big_buffer.glb", as_glb(b)), "buffer 0 claims");
  Scene v = two_mesh_scene();
  v.gltf["bufferViews"][2]["byteOffset"] = 90;
  expect_load_error(write_file("big_view.gltf", as_gltf(v)), "bufferView 2 spans");
}

TEST(GltfErrors, DataUrisMustBeBase64) {
  // Assimp's decoder leaked its buffer on a bad character (found by fuzz_mesh_gltf).
  std::string text = as_gltf(two_mesh_scene());
  text[text.find("base64,") + 10] = '*';
  expect_load_error(write_file("bad_char.gltf", text), "not base64 at offset");
  Scene s = two_mesh_scene();
  s.gltf["buffers"][0]["uri"] = "data:application/octet-stream,%00%01";
  expect_load_error(write_file("not_base64.gltf", s.gltf.dump()), "not base64");
  // Built by appending: GCC 12 misreads literal + std::string&& as an out-of-bounds memcpy
  // (-Warray-bounds false positive) once <string> comes from the precompiled header.
  std::string ragged = "data:application/octet-stream;base64,QUJD";
  ragged.append(3, 'A');
  s.gltf["buffers"][0]["uri"] = ragged;
  expect_load_error(write_file("ragged.gltf", s.gltf.dump()), "whole number of base64 quads");
  // Assimp keeps the payload's offset in a char: a header of 147 characters made it read
  // before the string (found by fuzz_mesh_gltf).
  Scene h = two_mesh_scene();
  std::string long_header = "data:application";
  long_header.append(110, 'x');
  long_header += "/octet-stream;base64,";
  long_header += common::base64_encode(h.bin);
  h.gltf["buffers"][0]["uri"] = long_header;
  expect_load_error(write_file("long_header.gltf", h.gltf.dump()), "header of 146 characters");
}

TEST(GltfErrors, UrisOutsideTheFolderAreRefused) {
  Scene s = two_mesh_scene();
  write_file("scene.bin", s.bin);
  for (const char* uri :
       {"../meshes_gltf/scene.bin", "/etc/passwd", "%2e%2e/x.bin", "file:///etc/passwd"}) {
    s.gltf["buffers"][0]["uri"] = uri;
    expect_load_error(write_file("escape.gltf", s.gltf.dump()), "outside the file's folder");
  }
  // Images are not needed for geometry: a missing texture beside the file is fine, one
  // outside the folder is still refused.
  Scene textured = two_mesh_scene();
  textured.gltf["images"] = {{{"uri", "missing_texture.png"}}};
  EXPECT_EQ(meshes::load_mesh(write_file("textured.gltf", as_gltf(textured))).triangle_count(), 3u);
  textured.gltf["images"][0]["uri"] = "../texture.png";
  expect_load_error(write_file("textured_escape.gltf", as_gltf(textured)), "image 0 refers to");
}

TEST(GltfErrors, AccessorsMustHaveTheTypeOfTheirRole) {
  // The exact 609-byte file that crashed Assimp (SIGSEGV): a LINE_LOOP whose indices name the
  // float VEC3 position accessor.
  const std::string crash =
      R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)"
      R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":0,"mode":2}]}],)"
      R"("buffers":[{"byteLength":72,"uri":"data:application/octet-stream;base64,)"
      R"(AAAAAAAiYnl0ZUxlbmd0aCI6IDcyfV0sICJidWZmZXJWaWV3cwAED6AAAAAAAIA/AAACAAEAAAABAAMAAAADAAIAAQECAAMA"}],)"
      R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":48},{"buffer":0,"byteOffset":48,)"
      R"("byteLength":24}],"accessors":[{"bufferView":0,"componentType":5126,"count":4,)"
      R"("type":"VEC3","min":[0,0,0],"max":[1,1,1]},{"bufferView":1,"componentType":5123,)"
      R"("count":12,"type":"SCALAR"}]})";
  expect_load_error(write_file("line_loop_float_indices.gltf", crash),
                    "indices accessor 0 is not SCALAR of unsigned");
  Scene positions = two_mesh_scene();
  positions.gltf["meshes"][1]["primitives"][0]["attributes"]["POSITION"] = 2;  // the indices
  expect_load_error(write_file("scalar_positions.gltf", as_gltf(positions)), "POSITION accessor");
  Scene mode = two_mesh_scene();
  mode.gltf["meshes"][0]["primitives"][0]["mode"] = 9;
  expect_load_error(write_file("mode9.gltf", as_gltf(mode)), "mode 9");
}

TEST(GltfErrors, HostileStructureIsRefusedBeforeAssimp) {
  std::string deep = R"({"asset":{"version":"2.0"},"x":)";
  deep += std::string(100000, '[') + std::string(100000, ']') + "}";
  expect_load_error(write_file("deep.gltf", deep), "nests deeper than 64");
  Scene cycle = two_mesh_scene();
  cycle.gltf["nodes"][1]["children"] = {0};
  expect_load_error(write_file("cycle.gltf", as_gltf(cycle)), "cycle");
  Scene shared = two_mesh_scene();
  shared.gltf["nodes"][2]["children"] = {1};
  expect_load_error(write_file("shared.gltf", as_gltf(shared)), "two parents");
  expect_load_error(write_file("v1.gltf", R"({"asset":{"version":"1.0"}})"), "not glTF 2.0");
  expect_load_error(write_file("broken.gltf", R"({"asset":)"), "does not parse");
}

// A box as exporters write it: 24 vertices, four per face with the face's normal (NORMAL),
// and 36 indices; with `normals` false the same without the NORMAL attribute.
Scene split_normal_box(bool normals) {
  const int faces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                           {3, 7, 6, 2}, {0, 4, 7, 3}, {1, 2, 6, 5}};
  const Vec3 face_normals[6] = {{0, 0, -1}, {0, 0, 1},  {0, -1, 0},
                                {0, 1, 0},  {-1, 0, 0}, {1, 0, 0}};
  const auto corner = [](int i) {
    return Vec3(i == 1 || i == 2 || i == 5 || i == 6 ? 1.f : -1.f,
                i == 2 || i == 3 || i >= 6 ? 1.f : -1.f, i >= 4 ? 1.f : -1.f);
  };
  Scene s;
  for (const auto& f : faces)
    for (int i : f) s.bin.append(reinterpret_cast<const char*>(corner(i).data()), 12);
  for (const Vec3& n : face_normals)
    for (int k = 0; k < 4; ++k) s.bin.append(reinterpret_cast<const char*>(n.data()), 12);
  for (std::uint16_t f = 0; f < 6; ++f)
    for (std::uint16_t i : {0, 1, 2, 0, 2, 3}) put(s.bin, std::uint16_t(4 * f + i));
  json attributes = {{"POSITION", 0}};
  if (normals) attributes["NORMAL"] = 1;
  s.gltf = {{"asset", {{"version", "2.0"}}},
            {"scene", 0},
            {"scenes", {{{"nodes", {0}}}}},
            {"nodes", {{{"mesh", 0}}}},
            {"meshes", {{{"primitives", {{{"attributes", attributes}, {"indices", 2}}}}}}},
            {"accessors",
             {{{"bufferView", 0},
               {"componentType", 5126},
               {"count", 24},
               {"type", "VEC3"},
               {"min", {-1, -1, -1}},
               {"max", {1, 1, 1}}},
              {{"bufferView", 1}, {"componentType", 5126}, {"count", 24}, {"type", "VEC3"}},
              {{"bufferView", 2}, {"componentType", 5123}, {"count", 36}, {"type", "SCALAR"}}}},
            {"bufferViews",
             {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 288}},
              {{"buffer", 0}, {"byteOffset", 288}, {"byteLength", 288}},
              {{"buffer", 0}, {"byteOffset", 576}, {"byteLength", 72}}}},
            {"buffers", {{{"byteLength", s.bin.size()}}}}};
  return s;
}

TEST(GltfNormals, SplitNormalBoxKeepsItsTwentyFourVertices) {
  meshes::LoadReport report;
  const Mesh m =
      meshes::load_mesh(write_file("box.gltf", as_gltf(split_normal_box(true))), {}, &report);
  EXPECT_TRUE(report.normals_from_file);
  EXPECT_EQ(report.vertices_welded, 0u);
  ASSERT_EQ(m.vertex_count(), 24u);
  ASSERT_EQ(m.triangle_count(), 12u);
  // Every corner's normal is its face's, as the file says: the box renders with hard edges.
  for (const meshes::Triangle& t : m.triangles) {
    const Vec3 face = (m.positions[t[1]] - m.positions[t[0]])
                          .cross(m.positions[t[2]] - m.positions[t[0]])
                          .normalized();
    for (std::uint32_t v : t) EXPECT_GT(m.normals[v].dot(face), 1 - 1e-6);
  }
  // Without NORMAL the positions weld to 8, and a 30-degree crease angle splits them again.
  meshes::LoadOptions auto_smooth;
  auto_smooth.crease_angle_deg = 30;
  const Mesh bare = meshes::load_mesh(write_file("bare_box.gltf", as_gltf(split_normal_box(false))),
                                      auto_smooth, &report);
  EXPECT_FALSE(report.normals_from_file);
  EXPECT_EQ(report.vertices_welded, 16u);
  EXPECT_EQ(report.vertices_split_at_creases, 16u);
  EXPECT_EQ(bare.vertex_count(), 24u);
}

TEST(Weld, GroupsEqualPositionsDenselyInFirstOccurrenceOrder) {
  const std::vector<Vec3> p = {{1, 2, 3},       {0, 0, 0}, {1, 2, 3},
                               {-0.f, 0, -0.f}, {4, 5, 6}, {0, 0, 1e-30f}};
  const meshes::PositionGroups g = meshes::group_equal_positions(p);
  EXPECT_EQ(g.group, (std::vector<std::uint32_t>{0, 1, 0, 1, 2, 3}));
  EXPECT_EQ(g.first, (std::vector<std::uint32_t>{0, 1, 4, 5}));
  // Brute force: same group exactly when the coordinates compare equal.
  for (std::size_t a = 0; a < p.size(); ++a) {
    for (std::size_t b = 0; b < p.size(); ++b) {
      EXPECT_EQ(g.group[a] == g.group[b], p[a] == p[b]) << a << " " << b;
    }
  }
}
