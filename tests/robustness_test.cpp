// Hostile inputs: small files that once crashed a loader, made it allocate gigabytes, or
// read memory it never set. Every file is written here, byte by byte; the expectation is a
// prompt error that names the file and says what to do.
#include "common/atomic_file.h"
#include "meshes/load.h"
#include "probes/load.h"
#include "test_support.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

fs::path write_file(const std::string& name, const std::string& bytes) {
  const fs::path p = test_support::scratch("robustness", name);
  std::ofstream(p, std::ios::binary) << bytes;
  return p;
}

template <class Load>
std::string error_of(Load load) {
  try {
    load();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no error)";
}

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

// The loader must fail with a message naming the file and containing `phrase`, within a
// second (the inputs here once took minutes).
template <class Load>
void expect_quick_error(const fs::path& p, const std::string& phrase, double max_seconds,
                        Load load) {
  SCOPED_TRACE(p.filename().string());
  const auto start = std::chrono::steady_clock::now();
  const std::string msg = error_of([&] { load(p); });
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_TRUE(contains(msg, p.filename().string())) << msg;
  EXPECT_TRUE(contains(msg, phrase)) << msg;
  EXPECT_LT(seconds, max_seconds) << msg;
}

void expect_mesh_error(const fs::path& p, const std::string& phrase, double max_seconds = 1.0) {
  expect_quick_error(p, phrase, max_seconds, [](const fs::path& f) { meshes::load_mesh(f); });
}

void expect_probe_error(const fs::path& p, const std::string& phrase) {
  expect_quick_error(p, phrase, 1.0, [](const fs::path& f) { probes::load_probe(f); });
}

template <class T>
std::string bytes_of(const T& value) {
  return std::string(reinterpret_cast<const char*>(&value), sizeof value);
}

// --- OBJ ----------------------------------------------------------------------------------

TEST(HostileObj, CornerWithoutVertexNumberIsAnErrorNotAnAbort) {
  // OpenMesh's reader asserts on these (SIGABRT with Debian's build).
  expect_mesh_error(write_file("slash_zero.obj", "f /0"), "face corner '/0'");
  expect_mesh_error(write_file("after_geometry.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf /0\n"),
                    "line 5");
  expect_mesh_error(write_file("double_slash.obj", "v 0 0 0\nf //1 1 1\n"), "face corner");
  expect_mesh_error(write_file("zero_index.obj", "v 0 0 0\nf 0 1 1\n"), "non-zero");
  expect_mesh_error(write_file("no_corners.obj", "v 0 0 0\nf\n"), "no corners");
  expect_mesh_error(write_file("huge_index.obj", "v 0 0 0\nf 1 99999999999 1\n"), "face corner");
  // Still accepted: every spelling of a corner OBJ allows.
  const fs::path ok = write_file("corners.obj",
                                 "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n"
                                 "f 1/1 2/1/1 3//1\nf -3 -2 -1\n");
  meshes::LoadReport report;
  // The second face is the first one again, through negative (relative) numbers.
  EXPECT_EQ(meshes::load_mesh(ok, {}, &report).triangle_count(), 2u);
  EXPECT_EQ(report.file_faces, 2u);
}

// --- 3DS ----------------------------------------------------------------------------------

std::string chunk(std::uint16_t id, const std::string& body) {
  return bytes_of(id) + bytes_of(std::uint32_t(6 + body.size())) + body;
}

// An object chunk (0x4000) named "quad": a triangle mesh of one unit quad as two triangles.
std::string quad_object() {
  std::string vertices = bytes_of(std::uint16_t(4));
  const float p[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  for (const auto& v : p) vertices += std::string(reinterpret_cast<const char*>(v), 12);
  // Face records carry a flags word after the three indices.
  std::string face_records = bytes_of(std::uint16_t(2));
  for (int t = 0; t < 2; ++t) {
    const std::uint16_t idx[4] = {0, std::uint16_t(1 + t), std::uint16_t(2 + t), 0};
    face_records += std::string(reinterpret_cast<const char*>(idx), 8);
  }
  return chunk(0x4000, std::string("quad\0", 5) +
                           chunk(0x4100, chunk(0x4110, vertices) + chunk(0x4120, face_records)));
}

TEST(Hostile3ds, DeepNestingIsRefusedWithoutRecursion) {
  // A quad inside 20,000 nested editor chunks overflowed the stack of a recursive walk. The
  // guard in front of Assimp walks chunks with its own stack and refuses past 32 levels.
  const std::string nested = quad_object();
  // Headers outermost first: level d encloses 20000 - d editor headers and the object.
  constexpr std::uint32_t kLevels = 20000;
  std::string file =
      bytes_of(std::uint16_t(0x4D4D)) + bytes_of(std::uint32_t(6 * (kLevels + 1) + nested.size()));
  for (std::uint32_t d = 0; d < kLevels; ++d) {
    file += bytes_of(std::uint16_t(0x3D3D)) +
            bytes_of(std::uint32_t(6 * (kLevels - d) + nested.size()));
  }
  const fs::path deep = write_file("deep.3ds", file + nested);
  EXPECT_GT(fs::file_size(deep), 120000u);
  expect_mesh_error(deep, "nest deeper than 32 levels");

  // The same depth of main chunks with nothing inside.
  std::string empty;
  for (std::uint32_t d = 0; d <= kLevels; ++d) {
    empty += bytes_of(std::uint16_t(0x4D4D)) + bytes_of(std::uint32_t(6 * (kLevels + 1 - d)));
  }
  expect_mesh_error(write_file("deep_empty.3ds", empty), "nest deeper than 32 levels");

  // At a depth real files have (main, editor, object, mesh) the quad loads.
  const std::string shallow = chunk(0x4D4D, chunk(0x3D3D, nested));
  EXPECT_EQ(meshes::load_mesh(write_file("shallow.3ds", shallow)).triangle_count(), 2u);
}

TEST(Hostile3ds, KeyframeTrackCountMustFitItsChunk) {
  // Assimp reserves 24 bytes per key a position track claims before reading any: 2^31 keys
  // in a 150-byte file asked for 51 GB.
  const std::string object = quad_object();
  const auto with_track = [&](std::uint32_t keys, const std::string& key_bytes) {
    const std::string name = chunk(0xB010, std::string("quad\0", 5) + std::string(6, '\0'));
    const std::string track = chunk(0xB020, std::string(10, '\0') + bytes_of(keys) + key_bytes);
    return chunk(0x4D4D, chunk(0x3D3D, object) + chunk(0xB000, chunk(0xB002, name + track)));
  };
  expect_mesh_error(write_file("track_2g.3ds", with_track(0x7FFFFFFF, "")),
                    "claims 2147483647 keys");
  // One real key (frame, flags, x y z) fits and loads.
  const std::string key =
      bytes_of(std::uint32_t(0)) + bytes_of(std::uint16_t(0)) + std::string(12, '\0');
  EXPECT_EQ(meshes::load_mesh(write_file("track_1.3ds", with_track(1, key))).triangle_count(), 2u);
}

// --- OFF ----------------------------------------------------------------------------------

TEST(HostileOff, HeaderCountsAreCheckedAgainstTheFileSize) {
  // One vertex line after a header claiming N vertices and N faces: once 2 GB at N = 20,000.
  for (const char* n : {"20000", "1000000", "4000000000", "99999999999999999999"}) {
    SCOPED_TRACE(n);
    const std::string off = std::string("OFF\n") + n + " " + n + " 0\n0 0 0\n";
    expect_mesh_error(write_file("claims.off", off), "parse");
  }
  expect_mesh_error(write_file("claims2.off", "OFF\n20000 20000 0\n0 0 0\n"), "claims 20000");
  expect_mesh_error(write_file("few.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1\n"),
                    "claims 3 corners");
  expect_mesh_error(write_file("short.off", "OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n1 1 1\n# no faces\n"),
                    "the file ends after 0 of the 1 faces");
  expect_mesh_error(write_file("binary.off", "OFF BINARY\n"), "binary OFF");
  expect_mesh_error(write_file("word.off", "OFF\n3 1 0\n0 0 0\n1 x 0\n0 1 0\n3 0 1 2\n"),
                    "'x' is not a number");
  // Comments, counts on the header line and colours after a face still load.
  const fs::path ok = write_file("colour.off",
                                 "COFF 3 1 0 # counts here\n0 0 0 1 1 1 1\n1 0 0 1 1 1 1\n"
                                 "0 1 0 1 1 1 1\n3 0 1 2 255 0 0\n");
  EXPECT_EQ(meshes::load_mesh(ok).triangle_count(), 1u);
}

// --- PLY ----------------------------------------------------------------------------------

const std::string kPlyHeader =
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
    "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";

TEST(HostilePly, NanInTextIsTheSameErrorEveryTime) {
  // OpenMesh read a value it never set after failing on "nan": usually exit 1, sometimes
  // gigabytes and bad_alloc.
  const fs::path p = write_file("nan.ply", kPlyHeader + "0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n");
  const std::string first = error_of([&] { meshes::load_mesh(p); });
  EXPECT_TRUE(contains(first, "vertex 1") && contains(first, "non-finite")) << first;
  for (int run = 0; run < 5; ++run) EXPECT_EQ(error_of([&] { meshes::load_mesh(p); }), first);
}

TEST(HostilePly, HugeCountsAreRefusedBeforeAllocation) {
  for (const char* n : {"4000000000", "40000000"}) {
    SCOPED_TRACE(n);
    const std::string ply = std::string("ply\nformat binary_little_endian 1.0\nelement vertex ") +
                            n +
                            "\nproperty float x\nproperty float y\nproperty float z\n"
                            "end_header\n" +
                            std::string(12, '\0');
    expect_mesh_error(write_file("claims.ply", ply), "claims");
  }
  // A face list claiming 255 corners with three behind it.
  std::string binary =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  binary += std::string(36, '\0');
  binary += char(255);
  binary += std::string(12, '\0');
  expect_mesh_error(write_file("list.ply", binary), "items");
  expect_mesh_error(
      write_file("no_props.ply", "ply\nformat ascii 1.0\nelement vertex 4000000000\nend_header\n"),
      "no properties");
  expect_mesh_error(write_file("no_end.ply", "ply\nformat ascii 1.0\nelement vertex 3\n"),
                    "end_header");
}

TEST(HostilePly, BigEndianAndExtraPropertiesLoad) {
  std::string ply =
      "ply\nformat binary_big_endian 1.0\ncomment made here\nelement vertex 3\n"
      "property double x\nproperty double y\nproperty double z\nproperty uchar red\n"
      "element face 1\nproperty list uchar uint vertex_indices\nproperty float quality\n"
      "element edge 1\nproperty int a\nproperty int b\nend_header\n";
  const auto put_be = [&ply](const void* v, std::size_t n) {
    const auto* b = static_cast<const char*>(v);
    for (std::size_t i = n; i-- > 0;) ply += b[i];
  };
  const double p[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  for (const auto& v : p) {
    for (double x : v) put_be(&x, 8);
    ply += char(200);
  }
  ply += char(3);
  for (std::uint32_t i : {0u, 1u, 2u}) put_be(&i, 4);
  const float quality = 1;
  put_be(&quality, 4);
  for (std::int32_t i : {0, 1}) put_be(&i, 4);
  meshes::LoadReport report;
  const meshes::Mesh m = meshes::load_mesh(write_file("be.ply", ply), {}, &report);
  EXPECT_EQ(m.triangle_count(), 1u);
  EXPECT_NEAR(meshes::double_area(m, m.triangles[0]), 1.0, 1e-6);
}

// --- STL ------------------------------------------------------------------------------------

TEST(HostileStl, TruncatedBinaryIsNamedAsSuch) {
  std::string stl(80, '\0');
  stl += bytes_of(std::uint32_t(5));
  stl += std::string(100, '\0');
  expect_mesh_error(write_file("short.stl", stl), "claims 5 triangles");
}

// Found by a second hostile-input round: each was read, with a wrong result or none.

std::string ascii_stl_with_third_vertex(const std::string& third) {
  return "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex " + third +
         "\nendloop\nendfacet\nendsolid t\n";
}

TEST(HostileStl, AsciiCoordinatesMustAllBeFiniteNumbers) {
  // OpenMesh's reader left an unparsable coordinate unset: another mesh hash on every run.
  expect_mesh_error(write_file("two.stl", ascii_stl_with_third_vertex("1 2")),
                    "line 6: 'vertex' needs three coordinates, found 2");
  expect_mesh_error(write_file("word.stl", ascii_stl_with_third_vertex("abc 0 0")),
                    "line 6: 'abc' is not a number");
  // ... and read 'inf' and 'nan' as 0.
  expect_mesh_error(write_file("inf.stl", ascii_stl_with_third_vertex("0 0 inf")), "'inf'");
  expect_mesh_error(write_file("nan.stl", ascii_stl_with_third_vertex("0 0 nan")), "'nan'");
  expect_mesh_error(write_file("big.stl", ascii_stl_with_third_vertex("0 0 1e39")), "'1e39'");
  const meshes::Mesh m =
      meshes::load_mesh(write_file("good.stl", ascii_stl_with_third_vertex("0 1 0")));
  EXPECT_EQ(m.vertex_count(), 3u);
  EXPECT_EQ(m.triangle_count(), 1u);
}

TEST(HostileStl, BinaryNanIsNamedByItsTriangle) {
  // It was reported as "no faces, only 1 vertices".
  std::string stl(80, '\0');
  stl += bytes_of(std::uint32_t(2));
  const float good[12] = {0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0};
  float bad[12] = {0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0};
  bad[10] = std::numeric_limits<float>::quiet_NaN();
  for (const float* t : {good, static_cast<const float*>(bad)})
    stl += std::string(reinterpret_cast<const char*>(t), 48) + std::string(2, '\0');
  expect_mesh_error(write_file("nan_binary.stl", stl), "triangle 1 has a non-finite coordinate");
}

TEST(HostileObj, ClassicMacLineEndsLoad) {
  // CR-only line ends made the file one line: "no faces, only 1 vertices".
  const meshes::Mesh m =
      meshes::load_mesh(write_file("cr.obj", "v 0 0 0\rv 1 0 0\rv 0 1 0\rf 1 2 3\r"));
  EXPECT_EQ(m.triangle_count(), 1u);
}

TEST(HostileObj, OverlongLineIsRefused) {
  // A 300 MB 'v' line peaked at 4.6 GB inside OpenMesh's reader; a line is bounded first.
  std::string line = "v ";
  line.append(2'000'000, '1');
  line.append(" 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  expect_mesh_error(write_file("long.obj", line), "line 1 has 2000006 bytes");
}

TEST(HostilePly, FacesWithoutThreeCornersAndRepeatedPropertiesAreNamed) {
  const std::string head =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  // Reported as "all 0 triangle(s) are degenerate".
  expect_mesh_error(write_file("zero_corners.ply", head + "0 0 0\n1 0 0\n0 1 0\n0\n"),
                    "none of its 1 faces has three corners");
  const std::string twice =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n";
  expect_mesh_error(write_file("twice.ply", twice), "property 'x' appears twice");
}

TEST(Hostile3ds, FaceIndexPastTheVertexListIsRefused) {
  // Assimp replaced the index by the last vertex and kept the face.
  std::string vertices = bytes_of(std::uint16_t(3));
  for (float x : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) vertices += bytes_of(x);
  std::string faces = bytes_of(std::uint16_t(1));
  for (std::uint16_t i : {0, 1, 60000, 7}) faces += bytes_of(i);
  const std::string mesh = chunk(0x4100, chunk(0x4110, vertices) + chunk(0x4120, faces));
  const std::string file = chunk(0x4D4D, chunk(0x3D3D, chunk(0x4000, std::string("q", 2) + mesh)));
  expect_mesh_error(write_file("index.3ds", file), "names vertex 60000, but its mesh has 3");
}

// A glTF file of `body` (what follows the asset, without the closing brace).
std::string gltf(const std::string& body) {
  return R"({"asset":{"version":"2.0"},)" + body + "}";
}

// One triangle's positions (and six 16-bit indices) as a base64 buffer of 48 bytes.
const std::string kTriangleBuffer =
    "data:application/octet-stream;base64,"
    "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIAAQD//wAA";

TEST(HostileGltf, IndexPastTheVerticesIsRefused) {
  // Indices 0 1 2 1 65535 0 into 3 vertices: Assimp dropped the second face without a word.
  const std::string file = gltf(
      R"("scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],"meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],"buffers":[{"byteLength":48,"uri":")" +
      kTriangleBuffer +
      R"("}],"bufferViews":[{"buffer":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":12}],"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"},{"bufferView":1,"componentType":5123,"count":6,"type":"SCALAR"}])");
  expect_mesh_error(write_file("index.gltf", file), "index 4 is 65535, but the primitive has 3");
}

std::string external_triangle_gltf(const std::string& uri, const std::string& scene_nodes = "0") {
  return gltf(
      R"("scenes":[{"nodes":[)" + scene_nodes +
      R"(]}],"nodes":[{"mesh":0}],"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"buffers":[{"byteLength":36,"uri":")" +
      uri +
      R"("}],"bufferViews":[{"buffer":0,"byteLength":36}],"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}])");
}

TEST(HostileGltf, PercentEscapedUriReadsTheFileThatWasChecked) {
  // The guard checked tet.bin, Assimp opened "t%65t.bin" as written: a FIFO there blocked.
  const fs::path dir = test_support::scratch("robustness", "escaped");
  fs::create_directories(dir);
  const float triangle[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::ofstream(dir / "tet.bin", std::ios::binary)
      .write(reinterpret_cast<const char*>(triangle), sizeof triangle);
  fs::remove(dir / "t%65t.bin");
  ASSERT_EQ(::mkfifo((dir / "t%65t.bin").c_str(), 0600), 0);
  std::ofstream(dir / "escaped.gltf") << external_triangle_gltf("t%65t.bin");
  const auto start = std::chrono::steady_clock::now();
  const meshes::Mesh m = meshes::load_mesh(dir / "escaped.gltf");
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5.0);
  EXPECT_EQ(m.triangle_count(), 1u);
  // The decoded name itself a FIFO: refused, not opened.
  fs::remove(dir / "fifo.bin");
  ASSERT_EQ(::mkfifo((dir / "fifo.bin").c_str(), 0600), 0);
  std::ofstream(dir / "fifo.gltf") << external_triangle_gltf("fif%6F.bin");
  expect_mesh_error(dir / "fifo.gltf", "not a file beside the .gltf");
}

TEST(HostileGltf, InstancingIsBoundedFromTheCounts) {
  // A scene naming one root 2,000 times and a mesh repeating one primitive 70,000 times
  // took gigabytes before any count was checked.
  const fs::path dir = test_support::scratch("robustness", "instancing");
  fs::create_directories(dir);
  std::ofstream(dir / "grid.bin", std::ios::binary) << std::string(120024, '\0');
  std::string roots = "0";
  for (int i = 1; i < 2000; ++i) roots += ",0";
  std::ofstream(dir / "roots.gltf") << gltf(
      R"("scenes":[{"nodes":[)" + roots +
      R"(]}],"nodes":[{"mesh":0}],"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"buffers":[{"byteLength":120024,"uri":"grid.bin"}],"bufferViews":[{"buffer":0,"byteLength":120024}],"accessors":[{"bufferView":0,"componentType":5126,"count":10002,"type":"VEC3"}])");
  expect_mesh_error(dir / "roots.gltf", "scene 0 places 20004000 vertices in 2000 nodes");
  std::string primitives = R"({"attributes":{"POSITION":0}})";
  for (int i = 1; i < 70000; ++i) primitives += R"(,{"attributes":{"POSITION":0}})";
  std::ofstream(dir / "primitives.gltf") << gltf(
      R"("scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],"meshes":[{"primitives":[)" + primitives +
      R"(]}],"buffers":[{"byteLength":120024,"uri":"grid.bin"}],"bufferViews":[{"buffer":0,"byteLength":120024}],"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}])");
  // 2 MB of JSON: parsing it takes 2 s under the sanitizers, so the bound is looser here.
  expect_mesh_error(dir / "primitives.gltf", "70000 mesh primitives", 10.0);
}

// --- Extreme but finite coordinates -----------------------------------------------------------

TEST(HostileGeometry, TriangleNearTheFloatLimitIsNotDegenerate) {
  // max - min overflows float (6e38 > 3.4e38); the diagonal is taken in double.
  const std::string obj = "v -3e38 -3e38 0\nv 3e38 -3e38 0\nv -3e38 3e38 0\nf 1 2 3\n";
  const meshes::Mesh m = meshes::load_mesh(write_file("huge.obj", obj));
  EXPECT_EQ(m.triangle_count(), 1u);
  for (const meshes::Vec3& n : m.normals) EXPECT_NEAR(n.z(), 1.f, 1e-6f);
}

// --- Probes -------------------------------------------------------------------------------

TEST(HostileProbe, HdrHeaderClaimingBillionsOfTexels) {
  // 53 bytes claiming 40000 x 20000: once 9.5 GB and 29 s before failing.
  const std::string hdr = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 20000 +X 40000\n";
  expect_probe_error(write_file("huge.hdr", hdr), "cannot hold that many");
  // 2e9 x 1e9 once failed as "vector::_M_default_append", naming nothing.
  expect_probe_error(write_file("huger.hdr",
                                "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n"
                                "-Y 1000000000 +X 2000000000\n"),
                     "re-export");
}

std::string exr_attribute(const std::string& name, const std::string& type, std::int32_t size,
                          const std::string& value) {
  return name + '\0' + type + '\0' + bytes_of(size) + value;
}

TEST(HostileProbe, ExrAttributeClaimingGigabytes) {
  // A kilobyte-sized EXR whose string attribute claims 1.9 GB: OpenEXR allocated it before
  // noticing the file ends.
  std::string exr = std::string("\x76\x2f\x31\x01", 4) + bytes_of(std::uint32_t(2));
  exr += exr_attribute("comments", "string", 1900000000, std::string(1000, 'x'));
  expect_probe_error(write_file("attr.exr", exr), "attribute 'comments'");
  // Negative sizes too.
  std::string negative = std::string("\x76\x2f\x31\x01", 4) + bytes_of(std::uint32_t(2));
  negative += exr_attribute("owner", "string", -5, "abc");
  expect_probe_error(write_file("negative.exr", negative), "attribute 'owner'");
  // A channel list whose declared size is short of its records: OpenEXR reads the records,
  // not the size, so it reads the next attribute (here claiming 1.9 GB) from elsewhere than
  // a walk by sizes would. Found by fuzz_probe_exr.
  std::string channel = std::string("R\0", 2) + std::string(16, '\0');
  std::string desync = std::string("\x76\x2f\x31\x01", 4) + bytes_of(std::uint32_t(2));
  desync += exr_attribute("channels", "chlist", 1, channel + '\0');
  desync += exr_attribute("x", "string", 1900000000, std::string(100, 'x'));
  expect_probe_error(write_file("desync.exr", desync), "attribute 'channels' (chlist)");
  // A preview image larger than the file.
  std::string preview = std::string("\x76\x2f\x31\x01", 4) + bytes_of(std::uint32_t(2));
  preview += exr_attribute(
      "preview", "preview", 16,
      bytes_of(std::uint32_t(30000)) + bytes_of(std::uint32_t(30000)) + std::string(8, '\0'));
  expect_probe_error(write_file("preview.exr", preview), "attribute 'preview'");
}

// A minimal single-part scan-line header: three half channels, the given data window and
// compression, and nothing after it but `tail` bytes.
std::string exr_scanlines(std::int32_t width, std::int32_t height, char compression,
                          std::size_t tail) {
  std::string channels;
  for (const char* c : {"B", "G", "R"}) {
    channels += std::string(c) + '\0' + bytes_of(std::int32_t(1)) + std::string(4, '\0') +
                bytes_of(std::int32_t(1)) + bytes_of(std::int32_t(1));
  }
  channels += '\0';
  const std::string window = bytes_of(std::int32_t(0)) + bytes_of(std::int32_t(0)) +
                             bytes_of(width - 1) + bytes_of(height - 1);
  std::string exr = std::string("\x76\x2f\x31\x01", 4) + bytes_of(std::uint32_t(2));
  exr += exr_attribute("channels", "chlist", std::int32_t(channels.size()), channels);
  exr += exr_attribute("compression", "compression", 1, std::string(1, compression));
  exr += exr_attribute("dataWindow", "box2i", 16, window);
  exr += exr_attribute("displayWindow", "box2i", 16, window);
  exr += exr_attribute("lineOrder", "lineOrder", 1, std::string(1, '\0'));
  return exr + '\0' + std::string(tail, '\0');
}

TEST(HostileProbe, ExrDataWindowSizingOpenExrBuffers) {
  // Found by fuzz_probe_exr: a 2 KB file whose data window is 16.5 million texels wide made
  // OpenEXR's ZIP decompressor allocate 16 scan lines of it, 1.5 GB, while opening the file.
  expect_probe_error(write_file("wide.exr", exr_scanlines(16514824, 4, 3, 1800)),
                     "block of scan lines");
  // DWAB's 256-line blocks: 4 M texels wide is only 24 MB of image but 6 GB per block.
  expect_probe_error(write_file("dwab.exr", exr_scanlines(4000000, 1, 9, 1800)),
                     "block of scan lines");
  // A tall window needs one 8-byte offset per chunk, which OpenEXR allocates before reading.
  expect_probe_error(write_file("tall.exr", exr_scanlines(1, 196605012, 0, 64)), "offset table");
  expect_probe_error(write_file("method.exr", exr_scanlines(8, 4, 42, 64)), "compression method");
  // The same header with an honest size is not refused by the guard: OpenImageIO opens it and
  // fails on the missing pixels instead.
  const std::string honest =
      error_of([&] { probes::load_probe(write_file("honest.exr", exr_scanlines(8, 4, 0, 32))); });
  EXPECT_TRUE(contains(honest, "honest.exr")) << honest;
  EXPECT_FALSE(contains(honest, "OpenEXR header")) << honest;
  EXPECT_FALSE(contains(honest, "offset table")) << honest;
}

// --- Stale temporaries ----------------------------------------------------------------------

pid_t dead_pid() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  int status = 0;
  ::waitpid(child, &status, 0);
  return child;
}

TEST(StaleTemporaries, OnlyThoseOfFinishedProcessesAreSwept) {
  const fs::path dir = test_support::scratch("robustness", "sweep");
  fs::remove_all(dir);
  fs::create_directories(dir);
  const auto touch = [&](const std::string& name) {
    std::ofstream(dir / name) << "x";
    return dir / name;
  };
  const fs::path stale = touch(".bake-1.prtx.tmp-" + std::to_string(dead_pid()) + "-42");
  const fs::path live = touch(".out.exr.tmp-" + std::to_string(::getppid()) + "-7");
  const fs::path ours = touch(".mine.tmp-" + std::to_string(::getpid()) + "-7");
  const fs::path user1 = touch(".notes.tmp-abc-1");
  const fs::path user2 = touch("bake.tmp-1-2");
  const auto removed = common::sweep_stale_temporaries(dir);
  ASSERT_EQ(removed.size(), 1u);
  EXPECT_EQ(removed[0], stale);
  EXPECT_FALSE(fs::exists(stale));
  for (const fs::path& kept : {live, ours, user1, user2}) EXPECT_TRUE(fs::exists(kept)) << kept;

  // A day-old temporary goes whatever its pid says: the pid may have been reused.
  fs::last_write_time(live, fs::file_time_type::clock::now() - std::chrono::hours(25));
  EXPECT_EQ(common::sweep_stale_temporaries(dir).size(), 1u);
  EXPECT_FALSE(fs::exists(live));

  // Image writers keep the extension (OpenImageIO picks the format from it): the same rule.
  const fs::path image_stale =
      touch(".frame_0001.exr.tmp-" + std::to_string(dead_pid()) + "-9.exr");
  const fs::path image_live =
      touch(".frame_0002.png.tmp-" + std::to_string(::getppid()) + "-9.png");
  const fs::path not_ours = touch(".frame.exr.tmp-" + std::to_string(dead_pid()) + "-9.e-x");
  EXPECT_EQ(common::sweep_stale_temporaries(dir), std::vector<fs::path>{image_stale});
  EXPECT_TRUE(fs::exists(image_live));
  EXPECT_TRUE(fs::exists(not_ours));

  // Writing a file sweeps its directory.
  const fs::path again = touch(".x.tmp-" + std::to_string(dead_pid()) + "-1");
  common::write_file_atomically(dir / "x", "y", 1);
  EXPECT_FALSE(fs::exists(again));
}

TEST(StaleTemporaries, TemporaryPathNamesTheWriterAndKeepsTheExtensionOnRequest) {
  const fs::path dir = test_support::scratch("robustness", "names");
  const std::string pid = std::to_string(::getpid());
  const fs::path plain = common::temporary_path(dir / "bake.prtx");
  const fs::path image = common::temporary_path(dir / "frame.exr", /*keep_extension=*/true);
  EXPECT_EQ(plain.parent_path(), dir);
  EXPECT_EQ(plain.filename().string().rfind(".bake.prtx.tmp-" + pid + "-", 0), 0u) << plain;
  EXPECT_EQ(image.filename().string().rfind(".frame.exr.tmp-" + pid + "-", 0), 0u) << image;
  EXPECT_EQ(image.extension(), ".exr");
  EXPECT_NE(common::temporary_path(dir / "bake.prtx"), plain);  // a fresh name each time
}

}  // namespace
