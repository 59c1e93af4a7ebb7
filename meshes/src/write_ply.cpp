// Binary PLY output; see meshes/write_ply.h.
#include "meshes/write_ply.h"

#include "common/atomic_file.h"

#include <cstdint>
#include <string>
#include <vector>

namespace meshes {

void write_ply(const std::filesystem::path& path, const Mesh& mesh) {
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
  for (const Vec3& p : mesh.positions) put(p.data(), 3 * sizeof(float));
  for (const Triangle& t : mesh.triangles) {
    const unsigned char corners = 3;
    put(&corners, 1);
    const std::int32_t idx[3] = {std::int32_t(t[0]), std::int32_t(t[1]), std::int32_t(t[2])};
    put(idx, sizeof idx);
  }
  common::write_file_atomically(path, bytes.data(), bytes.size());
}

}  // namespace meshes
