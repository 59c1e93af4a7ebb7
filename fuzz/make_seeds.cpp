// fuzz/make_seeds: writes the seed corpus of the mesh and probe fuzz targets from the real
// inputs, small: a patch of the Stanford bunny and glmark2's cube and low-poly asteroid in
// every mesh format we read, and downsampled Blender studio lights as HDR and EXR. (The
// .prtx and .prtc seeds are written by prtr itself; see scripts/fuzz.sh.)
// Seeds must be small (libFuzzer mutates whole files; -max_len caps them) and valid, so that
// mutations start inside each format rather than at its first check.
//
// Usage: make_seeds OUTPUT_DIR BUNNY_OBJ MODELS_DIR PROBES_DIR
#include "common/base64.h"
#include "meshes/load.h"
#include "probes/cube_map.h"
#include "probes/load.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

namespace fs = std::filesystem;
using meshes::Mesh;

namespace {

void write(const fs::path& p, const std::string& bytes) {
  fs::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary) << bytes;
}

template <class T>
void put(std::string& out, T v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof v);
}

// The triangles of `mesh` that use only its first `limit` vertices.
Mesh patch(const Mesh& mesh, std::uint32_t limit) {
  Mesh out;
  std::unordered_map<std::uint32_t, std::uint32_t> index;
  for (const meshes::Triangle& t : mesh.triangles) {
    if (t[0] >= limit || t[1] >= limit || t[2] >= limit) continue;
    meshes::Triangle n;
    for (int k = 0; k < 3; ++k) {
      auto [it, fresh] = index.try_emplace(t[k], std::uint32_t(out.positions.size()));
      if (fresh) out.positions.push_back(mesh.positions[t[k]]);
      n[k] = it->second;
    }
    out.triangles.push_back(n);
  }
  return out;
}

std::string obj(const Mesh& m) {
  std::ostringstream s;
  s << "# seed\n";
  for (const auto& p : m.positions) s << "v " << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
  for (std::size_t i = 0; i < m.triangles.size(); ++i) {
    const auto& t = m.triangles[i];
    // Every corner spelling, so that mutations start from each.
    if (i % 3 == 0) s << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
    if (i % 3 == 1) s << "f " << t[0] + 1 << "//1 " << t[1] + 1 << "//1 " << t[2] + 1 << "//1\n";
    if (i % 3 == 2) s << "f " << t[0] + 1 << "/1/1 " << t[1] + 1 << "/1 -1\n";
  }
  return s.str();
}

std::string off(const Mesh& m) {
  std::ostringstream s;
  s << "OFF\n" << m.positions.size() << ' ' << m.triangles.size() << " 0\n";
  for (const auto& p : m.positions) s << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
  for (const auto& t : m.triangles) s << "3 " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
  return s.str();
}

std::string ply(const Mesh& m, bool binary) {
  std::ostringstream h;
  h << "ply\nformat " << (binary ? "binary_little_endian" : "ascii")
    << " 1.0\ncomment seed\nelement vertex " << m.positions.size()
    << "\nproperty float x\nproperty float y\nproperty float z\nelement face " << m.triangles.size()
    << "\nproperty list uchar int vertex_indices\nend_header\n";
  std::string s = h.str();
  if (binary) {
    for (const auto& p : m.positions) {
      for (int k = 0; k < 3; ++k) put(s, p[k]);
    }
    for (const auto& t : m.triangles) {
      put(s, std::uint8_t(3));
      for (int k = 0; k < 3; ++k) put(s, std::int32_t(t[k]));
    }
    return s;
  }
  std::ostringstream b;
  for (const auto& p : m.positions) b << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
  for (const auto& t : m.triangles) b << "3 " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
  return s + b.str();
}

std::string stl(const Mesh& m, bool binary) {
  if (binary) {
    std::string s(80, ' ');
    put(s, std::uint32_t(m.triangles.size()));
    for (const auto& t : m.triangles) {
      for (int k = 0; k < 3; ++k) put(s, 0.f);
      for (int c = 0; c < 3; ++c) {
        for (int k = 0; k < 3; ++k) put(s, m.positions[t[c]][k]);
      }
      put(s, std::uint16_t(0));
    }
    return s;
  }
  std::ostringstream s;
  s << "solid seed\n";
  for (const auto& t : m.triangles) {
    s << "facet normal 0 0 0\nouter loop\n";
    for (int c = 0; c < 3; ++c) {
      const auto& p = m.positions[t[c]];
      s << "vertex " << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
    }
    s << "endloop\nendfacet\n";
  }
  s << "endsolid seed\n";
  return s.str();
}

std::string chunk(std::uint16_t id, const std::string& body) {
  std::string s;
  put(s, id);
  put(s, std::uint32_t(6 + body.size()));
  return s + body;
}

std::string three_ds(const Mesh& m) {
  std::string v, f;
  put(v, std::uint16_t(m.positions.size()));
  for (const auto& p : m.positions) {
    put(v, p.x());
    put(v, -p.z());  // back to 3DS's Z-up
    put(v, p.y());
  }
  put(f, std::uint16_t(m.triangles.size()));
  for (const auto& t : m.triangles) {
    for (int k = 0; k < 3; ++k) put(f, std::uint16_t(t[k]));
    put(f, std::uint16_t(0));
  }
  const std::string object =
      chunk(0x4000, std::string("seed\0", 5) + chunk(0x4100, chunk(0x4110, v) + chunk(0x4120, f)));
  return chunk(0x4D4D, chunk(0x3D3D, object));
}

// glTF 2.0: one mesh (float positions, uint32 indices) under a node with a TRS transform,
// as JSON with a base64 data URI and as a .glb with a binary chunk.
std::string gltf_json(const Mesh& m, std::size_t bin_bytes, const std::string& uri) {
  const std::size_t vbytes = 12 * m.positions.size();
  std::ostringstream s;
  s << R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],)"
    << R"("nodes":[{"mesh":0,"translation":[1,2,3],"rotation":[0,0.6,0,0.8],"scale":[2,2,2]}],)"
    << R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],)"
    << R"("accessors":[{"bufferView":0,"componentType":5126,"type":"VEC3","count":)"
    << m.positions.size() << R"(},{"bufferView":1,"componentType":5125,"type":"SCALAR","count":)"
    << 3 * m.triangles.size() << "}],"
    << R"("bufferViews":[{"buffer":0,"byteLength":)" << vbytes << R"(},{"buffer":0,"byteOffset":)"
    << vbytes << R"(,"byteLength":)" << 12 * m.triangles.size() << "}],"
    << R"("buffers":[{"byteLength":)" << bin_bytes
    << (uri.empty() ? std::string() : R"(,"uri":")" + uri + '"') << "}]}";
  return s.str();
}

std::string gltf_bin(const Mesh& m) {
  std::string bin;
  for (const auto& p : m.positions) bin.append(reinterpret_cast<const char*>(p.data()), 12);
  for (const auto& t : m.triangles) {
    for (int k = 0; k < 3; ++k) put(bin, std::uint32_t(t[k]));
  }
  return bin;
}

std::string gltf(const Mesh& m) {
  const std::string bin = gltf_bin(m);
  return gltf_json(m, bin.size(),
                   "data:application/octet-stream;base64," + common::base64_encode(bin));
}

std::string glb(const Mesh& m) {
  const std::string bin = gltf_bin(m);  // a multiple of 4 bytes
  std::string text = gltf_json(m, bin.size(), "");
  while (text.size() % 4 != 0) text += ' ';
  std::string out;
  put(out, std::uint32_t(0x46546C67));  // "glTF"
  put(out, std::uint32_t(2));
  put(out, std::uint32_t(28 + text.size() + bin.size()));
  put(out, std::uint32_t(text.size()));
  put(out, std::uint32_t(0x4E4F534A));  // "JSON"
  out += text;
  put(out, std::uint32_t(bin.size()));
  put(out, std::uint32_t(0x004E4942));  // "BIN"
  return out + bin;
}

void mesh_seeds(const fs::path& out, const std::string& name, const Mesh& m) {
  write(out / "mesh_obj" / (name + ".obj"), obj(m));
  write(out / "mesh_off" / (name + ".off"), off(m));
  write(out / "mesh_ply" / (name + "_ascii.ply"), ply(m, false));
  write(out / "mesh_ply" / (name + "_binary.ply"), ply(m, true));
  write(out / "mesh_stl" / (name + "_ascii.stl"), stl(m, false));
  write(out / "mesh_stl" / (name + "_binary.stl"), stl(m, true));
  if (m.positions.size() < 65536 && m.triangles.size() < 65536) {
    write(out / "mesh_3ds" / (name + ".3ds"), three_ds(m));
  }
  write(out / "mesh_gltf" / (name + ".gltf"), gltf(m));
  write(out / "mesh_glb" / (name + ".glb"), glb(m));
}

// Nearest-texel downsample of a probe to width x width/2, written by OpenImageIO.
void probe_seeds(const fs::path& out, const fs::path& source, int width) {
  const probes::Probe p = probes::load_probe(source);
  const int height = width / 2;
  std::vector<float> pixels(std::size_t(width) * height * 3);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const auto& t = p.texels()[std::size_t(y * p.height() / height) * p.width() +
                                 std::size_t(x * p.width() / width)];
      for (int c = 0; c < 3; ++c) pixels[(std::size_t(y) * width + x) * 3 + c] = t[c];
    }
  }
  const std::string stem = source.stem().string() + "_" + std::to_string(width);
  struct Variant {
    std::string dir, file, compression;
    OIIO::TypeDesc type;
  };
  for (const Variant& v : {Variant{"probe_hdr", stem + ".hdr", "", OIIO::TypeDesc::FLOAT},
                           Variant{"probe_exr", stem + "_zip.exr", "zip", OIIO::TypeDesc::HALF},
                           Variant{"probe_exr", stem + "_raw.exr", "none", OIIO::TypeDesc::FLOAT},
                           Variant{"probe_exr", stem + "_piz.exr", "piz", OIIO::TypeDesc::HALF}}) {
    const fs::path path = out / v.dir / v.file;
    fs::create_directories(path.parent_path());
    auto file = OIIO::ImageOutput::create(path.string());
    OIIO::ImageSpec spec(width, height, 3, v.type);
    if (!v.compression.empty()) spec.attribute("compression", v.compression);
    if (!file || !file->open(path.string(), spec) ||
        !file->write_image(OIIO::TypeDesc::FLOAT, pixels.data()) || !file->close()) {
      throw std::runtime_error("cannot write " + path.string());
    }
  }
  // Cube crosses of the same probe (faces width / 4), so the cube-map reader is reached too.
  const probes::CubeMap cube = probes::latlong_to_cube(p, std::max(width / 4, 1));
  for (const auto kind : {probes::CrossKind::kHorizontal, probes::CrossKind::kVertical}) {
    int w = 0, h = 0;
    const std::vector<probes::Rgb> cross = probes::cube_to_cross(cube, kind, &w, &h);
    const char* tag = kind == probes::CrossKind::kHorizontal ? "_hcross" : "_vcross";
    for (const char* dir : {"probe_exr", "probe_hdr"}) {
      const bool exr = std::string(dir) == "probe_exr";
      const fs::path path = out / dir / (stem + tag + (exr ? ".exr" : ".hdr"));
      auto file = OIIO::ImageOutput::create(path.string());
      OIIO::ImageSpec spec(w, h, 3, exr ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::FLOAT);
      if (!file || !file->open(path.string(), spec) ||
          !file->write_image(OIIO::TypeDesc::FLOAT, cross.data()) || !file->close()) {
        throw std::runtime_error("cannot write " + path.string());
      }
    }
  }
}

// The second hostile-input round's cases (docs/ROBUSTNESS.md has each with its answer).
void hostile_seeds(const fs::path& out) {
  const std::string triangle_buffer =
      "data:application/octet-stream;base64,"
      "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIAAQD//wAA";
  const std::string tail =
      R"("nodes":[{"mesh":0}],"meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],)"
      R"("buffers":[{"byteLength":48,"uri":")" +
      triangle_buffer +
      R"("}],"bufferViews":[{"buffer":0,"byteLength":36},{"buffer":0,"byteOffset":36,)"
      R"("byteLength":12}],"accessors":[{"bufferView":0,"componentType":5126,"count":3,)"
      R"("type":"VEC3"},{"bufferView":1,"componentType":5123,"count":)";
  const std::string head = R"({"asset":{"version":"2.0"},"scenes":[{"nodes":[)";
  // Indices 0 1 2 1 65535 0 into 3 vertices, and the first face alone under 16 roots.
  write(out / "mesh_gltf" / "index_65535.gltf", head + "0]}]," + tail + R"(6,"type":"SCALAR"}]})");
  write(out / "mesh_gltf" / "roots.gltf",
        head + "0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0]}]," + tail + R"(3,"type":"SCALAR"}]})");
  std::string v, f;
  put(v, std::uint16_t(3));
  for (float x : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) put(v, x);
  put(f, std::uint16_t(1));
  for (std::uint16_t i : {0, 1, 60000, 0}) put(f, i);
  const std::string mesh = chunk(0x4100, chunk(0x4110, v) + chunk(0x4120, f));
  write(out / "mesh_3ds" / "index_60000.3ds",
        chunk(0x4D4D, chunk(0x3D3D, chunk(0x4000, std::string("q", 2) + mesh))));
  write(out / "mesh_3ds" / "light_only.3ds",
        chunk(0x4D4D, chunk(0x3D3D, chunk(0x4000, std::string("l", 2) +
                                                      chunk(0x4600, std::string(12, '\0'))))));
  write(out / "mesh_stl" / "two_coordinates.stl",
        "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 2\n"
        "endloop\nendfacet\nendsolid t\n");
  std::string nan_stl(80, ' ');
  put(nan_stl, std::uint32_t(1));
  for (float x : {0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, NAN, 0.f}) put(nan_stl, x);
  put(nan_stl, std::uint16_t(0));
  write(out / "mesh_stl" / "nan_binary.stl", nan_stl);
  write(out / "mesh_obj" / "cr_only.obj", "v 0 0 0\rv 1 0 0\rv 0 1 0\rf 1 2 3\r");
  const std::string ply_vertices =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\n";
  write(out / "mesh_ply" / "zero_corners.ply",
        ply_vertices +
            "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
            "0 0 0\n1 0 0\n0 1 0\n0\n");
  write(out / "mesh_ply" / "duplicate_x.ply",
        ply_vertices + "property float x\nend_header\n0 0 0 0\n1 0 0 1\n0 1 0 0\n");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: make_seeds OUTPUT_DIR BUNNY_OBJ MODELS_DIR PROBES_DIR\n");
    return 2;
  }
  try {
    const fs::path out = argv[1], bunny = argv[2], models = argv[3], probe_dir = argv[4];
    mesh_seeds(out, "bunny_patch", patch(meshes::load_mesh(bunny), 400));
    // Hostile cases that once got past the guards: a line loop whose indices name the float
    // position accessor (crashed Assimp), and an OBJ whose mtllib names /dev/zero.
    write(
        out / "mesh_gltf" / "float_indices.gltf",
        R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)"
        R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":0,"mode":2}]}],)"
        R"("buffers":[{"byteLength":72,"uri":"data:application/octet-stream;base64,)"
        R"(AAAAAAAiYnl0ZUxlbmd0aCI6IDcyfV0sICJidWZmZXJWaWV3cwAED6AAAAAAAIA/AAACAAEAAAABAAMAAAADAAIAAQECAAMA"}],)"
        R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":48},{"buffer":0,"byteOffset":48,)"
        R"("byteLength":24}],"accessors":[{"bufferView":0,"componentType":5126,"count":4,)"
        R"("type":"VEC3","min":[0,0,0],"max":[1,1,1]},{"bufferView":1,"componentType":5123,)"
        R"("count":12,"type":"SCALAR"}]})");
    write(out / "mesh_obj" / "mtllib.obj",
          "mtllib ../../../../../../../../dev/zero\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    hostile_seeds(out);
    for (const char* name : {"cube", "asteroid-low"}) {
      const fs::path p = models / (std::string(name) + ".3ds");
      fs::create_directories(out / "mesh_3ds");
      fs::copy_file(p, out / "mesh_3ds" / p.filename(), fs::copy_options::overwrite_existing);
      mesh_seeds(out, name, meshes::load_mesh(p));
    }
    for (const char* name : {"studio", "night", "city"}) {
      probe_seeds(out, probe_dir / (std::string(name) + ".exr"), 32);
    }
    probe_seeds(out, probe_dir / "studio.exr", 8);

  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_seeds: %s\n", e.what());
    return 1;
  }
  return 0;
}
