// Loop subdivision through OpenMesh's own subdivider; see loop_subdivision.h.
#include "loop_subdivision.h"

#include "common/atomic_file.h"

#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Tools/Subdivider/Uniform/LoopT.hh>

#include <cstdint>
#include <string>
#include <vector>

namespace prtr_app {
namespace {

using OmMesh = OpenMesh::TriMesh_ArrayKernelT<>;

}  // namespace

meshes::Mesh loop_subdivide(const meshes::Mesh& mesh, int steps) {
  OmMesh om;
  std::vector<OmMesh::VertexHandle> handles;
  handles.reserve(mesh.vertex_count());
  for (const meshes::Vec3& p : mesh.positions) {
    handles.push_back(om.add_vertex(OmMesh::Point(p.x(), p.y(), p.z())));
  }
  for (std::size_t f = 0; f < mesh.triangle_count(); ++f) {
    const meshes::Triangle& t = mesh.triangles[f];
    if (!om.add_face(handles[t[0]], handles[t[1]], handles[t[2]]).is_valid()) {
      // The half-edge structure the subdivider walks cannot hold a non-manifold edge or a
      // flipped neighbour; dropping the face would open a hole, so refuse instead.
      throw meshes::MeshError("triangle " + std::to_string(f) + " (vertices " +
                              std::to_string(t[0]) + ", " + std::to_string(t[1]) + ", " +
                              std::to_string(t[2]) +
                              ") makes the surface non-manifold or inconsistently oriented; "
                              "Loop subdivision needs an edge-manifold, consistently wound mesh");
    }
  }
  if (steps > 0) {
    OpenMesh::Subdivider::Uniform::LoopT<OmMesh> loop;
    loop.attach(om);
    loop(static_cast<std::size_t>(steps));
    loop.detach();
  }
  meshes::Mesh out;
  out.positions.reserve(om.n_vertices());
  for (const OmMesh::VertexHandle v : om.vertices()) {
    const OmMesh::Point& p = om.point(v);
    out.positions.emplace_back(p[0], p[1], p[2]);
  }
  out.triangles.reserve(om.n_faces());
  for (const OmMesh::FaceHandle f : om.faces()) {
    meshes::Triangle t{};
    int c = 0;
    for (const OmMesh::VertexHandle v : om.fv_range(f)) t[c++] = std::uint32_t(v.idx());
    out.triangles.push_back(t);
  }
  return out;
}

void write_ply(const std::filesystem::path& path, const meshes::Mesh& mesh) {
  const std::string header = "ply\nformat binary_little_endian 1.0\nelement vertex " +
                             std::to_string(mesh.vertex_count()) +
                             "\nproperty float x\nproperty float y\nproperty float z\n"
                             "element face " +
                             std::to_string(mesh.triangle_count()) +
                             "\nproperty list uchar int vertex_indices\nend_header\n";
  std::vector<unsigned char> bytes(header.begin(), header.end());
  bytes.reserve(header.size() + 12 * mesh.vertex_count() + 13 * mesh.triangle_count());
  const auto put = [&](const void* data, std::size_t n) {
    const auto* b = static_cast<const unsigned char*>(data);
    bytes.insert(bytes.end(), b, b + n);
  };
  for (const meshes::Vec3& p : mesh.positions) put(p.data(), 3 * sizeof(float));
  for (const meshes::Triangle& t : mesh.triangles) {
    const unsigned char corners = 3;
    put(&corners, 1);
    const std::int32_t idx[3] = {std::int32_t(t[0]), std::int32_t(t[1]), std::int32_t(t[2])};
    put(idx, sizeof idx);
  }
  common::write_file_atomically(path, bytes.data(), bytes.size());
}

}  // namespace prtr_app
