// meshes/src/read_strict.h (private): our own readers for OFF, PLY and STL, and a strict pre-pass
// over OBJ face lines.
//
// OpenMesh's OFF and PLY readers trust their headers: they size buffers from header counts
// and keep reading after a parse failure with values they never set, so a 30-byte file can
// ask for gigabytes and the result depends on stack garbage. Its OBJ reader aborts (an
// assertion Debian keeps) on a face corner without a vertex index. These readers work on the
// whole file in memory, check every count against the bytes that are left before anything
// is allocated, and stop at the first malformed record with its position.
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace meshes::detail {

struct RawPolygons {
  std::vector<Eigen::Vector3f> positions;
  // Indices as written (0-based for OFF and PLY), range-checked by the caller so that it can
  // report the first bad face the same way for every format.
  std::vector<std::int64_t> corners;
  std::vector<std::size_t> face_offsets{0};  // face f is corners[offsets[f], offsets[f+1])
  // One per position when the file gives every vertex a normal, else empty.
  std::vector<Eigen::Vector3f> normals;
};

// Each returns an empty string on success, else the problem (without the path).
std::string read_off(std::string_view bytes, RawPolygons& out);
std::string read_ply(std::string_view bytes, RawPolygons& out);
// STL, binary (the caller decides which by the file's size) or ASCII. OpenMesh's ASCII reader
// left a coordinate it could not parse unset, so a damaged file loaded differently each run.
std::string read_stl_binary(std::string_view bytes, RawPolygons& out);
std::string read_stl_ascii(std::string_view bytes, RawPolygons& out);

// OpenMesh's OBJ reader splits lines at LF only, and copies a line into several token
// buffers. So lone CRs (classic Mac line ends, which made a whole file one line) become LFs,
// and a line longer than this limit is refused: a 300 MB 'v' line took 4.6 GB.
inline constexpr std::size_t kMaxObjLineBytes = std::size_t{1} << 20;
std::string normalise_obj_text(std::string& text);

// Checks every 'f' record of an OBJ file before OpenMesh sees it: at least one corner, and
// each corner v, v/vt, v//vn or v/vt/vn with v a non-zero integer that fits in an int.
std::string check_obj_faces(std::string_view bytes);

// What an OBJ file says about normals: its 'vn' records and, for every face in file order
// (each 'f' record with at least one corner), its corners' vertex and normal indices,
// resolved to 0-based (negative, relative indices counted back from the records read so
// far). A corner without a normal index has normal -1.
struct ObjNormals {
  std::vector<Eigen::Vector3f> normals;
  std::vector<std::int64_t> vertices;
  std::vector<std::int64_t> normal_of_corner;
  std::vector<std::size_t> face_offsets{0};
};

// Call after check_obj_faces accepted the text; malformed 'vn' records make `out.normals`
// stop short (the caller then finds indices out of range and keeps no normals).
void read_obj_normals(std::string_view bytes, ObjNormals& out);

// Blanks (with spaces, keeping line numbers and offsets) every 'mtllib' statement of an OBJ
// text, so that a reader given the text opens no material library.
void blank_obj_material_libraries(std::string& text);

}  // namespace meshes::detail
