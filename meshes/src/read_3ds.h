// meshes/src/read_3ds.h (private): a reader for the triangle meshes of Autodesk 3DS files
// (glmark2-data ships its horse and cat this way; OpenMesh has no 3DS reader).
//
// Only geometry is read: every object's vertex list (chunk 0x4110) and face list (0x4120),
// concatenated. Positions are converted from 3DS's Z-up to our +Y-up world:
// (x, y, z) -> (x, z, -y), which keeps the handedness and the winding.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace meshes::detail {

struct Raw3ds {
  std::vector<Eigen::Vector3f> positions;
  std::vector<std::uint32_t> corners;  // three per face
};

// Returns an empty string on success, else the problem (without the path).
std::string read_3ds(const std::filesystem::path& path, Raw3ds& out);

}  // namespace meshes::detail
