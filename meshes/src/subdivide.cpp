// Loop subdivision through OpenMesh's own subdivider; see meshes/subdivide.h.
#include "meshes/subdivide.h"

#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Tools/Subdivider/Uniform/LoopT.hh>

#include <cstdint>
#include <string>
#include <vector>

namespace meshes {
namespace {

using OmMesh = OpenMesh::TriMesh_ArrayKernelT<>;

}  // namespace

Mesh loop_subdivide(const Mesh& mesh, int steps) {
  OmMesh om;
  std::vector<OmMesh::VertexHandle> handles;
  handles.reserve(mesh.vertex_count());
  for (const Vec3& p : mesh.positions) {
    handles.push_back(om.add_vertex(OmMesh::Point(p.x(), p.y(), p.z())));
  }
  for (std::size_t f = 0; f < mesh.triangle_count(); ++f) {
    const Triangle& t = mesh.triangles[f];
    if (!om.add_face(handles[t[0]], handles[t[1]], handles[t[2]]).is_valid()) {
      // The half-edge structure the subdivider walks cannot hold a non-manifold edge or a
      // flipped neighbour; dropping the face would open a hole, so refuse instead.
      throw MeshError("triangle " + std::to_string(f) + " (vertices " + std::to_string(t[0]) +
                      ", " + std::to_string(t[1]) + ", " + std::to_string(t[2]) +
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
  Mesh out;
  out.positions.reserve(om.n_vertices());
  for (const OmMesh::VertexHandle v : om.vertices()) {
    const OmMesh::Point& p = om.point(v);
    out.positions.emplace_back(p[0], p[1], p[2]);
  }
  out.triangles.reserve(om.n_faces());
  for (const OmMesh::FaceHandle f : om.faces()) {
    Triangle t{};
    int c = 0;
    for (const OmMesh::VertexHandle v : om.fv_range(f)) t[c++] = std::uint32_t(v.idx());
    out.triangles.push_back(t);
  }
  return out;
}

}  // namespace meshes
