// The 3DS guard of asset_guard.h: every chunk's claimed length against its parent's end, the
// keyframe tracks' and lists' counts against their chunk, and face indices against their
// mesh, walked iteratively before Assimp's recursive reader sees the file.
#include "asset_guard.h"
#include "guard_refusal.h"

#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

namespace meshes::detail {

namespace {

// Chunks whose body is a list of chunks (0x4000 after its name). Every chunk's claimed length
// is checked against its parent's end, iteratively, before Assimp's own walk.
// The keyframer (0xB000) holds node tags 0xB001..0xB007, which hold tracks.
bool is_3ds_container(std::uint16_t id) {
  return id == 0x4D4D || id == 0x3D3D || id == 0x4000 || id == 0x4100 || id == 0xAFFF ||
         (id >= 0xB000 && id <= 0xB007);
}

// Keyframe tracks (0xB020 position ... 0xB029 hide): a 10-byte header, a 32-bit key count,
// then keys of at least 6 bytes (frame and flags). Assimp reserves the count times 24 bytes
// before reading a key, so a 150-byte file could ask for 51 GB; the count must fit the chunk.
void check_3ds_track(std::string_view b, std::size_t at, std::uint64_t length) {
  constexpr std::uint64_t kHeader = 6 + 10 + 4;
  constexpr std::uint64_t kSmallestKey = 6;
  const std::uint64_t keys = length >= kHeader ? le32(b, at + 16) : 0;
  if (length < kHeader || keys > (length - kHeader) / kSmallestKey) {
    char hex[8];
    std::snprintf(hex, sizeof hex, "%04x", le16(b, at));
    refuse("keyframe track 0x" + std::string(hex) + " at byte " + std::to_string(at) + " claims " +
           std::to_string(keys) + " keys in " + std::to_string(length) +
           " bytes; the file is damaged");
  }
}

// Vertex (0x4110, 12 bytes each), face (0x4120, 8) and texture coordinate (0x4140, 8) lists:
// a 16-bit count, then the records. Assimp would stop at the chunk's end with a message that
// names nothing; this one says which list is short.
void check_3ds_list(std::string_view b, std::size_t at, std::uint64_t length) {
  const std::uint16_t id = le16(b, at);
  const std::uint64_t record = id == 0x4110 ? 12 : 8;
  const std::uint64_t count = length >= 8 ? le16(b, at + 6) : 0;
  if (length < 8 || 8 + count * record > length) {
    const char* what = id == 0x4110 ? "vertex" : id == 0x4120 ? "face" : "texture coordinate";
    refuse(std::string(what) + " list chunk at byte " + std::to_string(at) + " claims " +
           std::to_string(count) + " records of " + std::to_string(record) + " bytes in " +
           std::to_string(length) + " bytes; the file is damaged");
  }
}

// The vertices of the triangle mesh chunk (0x4100) at `at`: the sum of its vertex lists
// (Assimp appends them). Malformed children are left to the walk, which refuses them.
std::uint64_t trimesh_vertices(std::string_view b, std::size_t at, std::uint64_t length) {
  std::uint64_t vertices = 0;
  for (std::size_t child = at + 6; child + 8 <= at + length;) {
    const std::uint64_t child_length = le32(b, child + 2);
    if (child_length < 6 || child_length > at + length - child) break;
    if (le16(b, child) == 0x4110) vertices += le16(b, child + 6);
    child += child_length;
  }
  return vertices;
}

// Every face of a face list (0x4120, after check_3ds_list) must name a vertex of its mesh:
// Assimp replaces an index out of range by the last vertex, which keeps a wrong triangle.
void check_3ds_faces(std::string_view b, std::size_t at, std::uint64_t vertices) {
  const std::uint64_t faces = le16(b, at + 6);
  for (std::uint64_t f = 0; f < faces; ++f) {
    for (std::size_t c = 0; c < 3; ++c) {
      const std::uint64_t index = le16(b, at + 8 + 8 * f + 2 * c);
      if (index >= vertices) {
        refuse("face " + std::to_string(f) + " of the face list at byte " + std::to_string(at) +
               " names vertex " + std::to_string(index) + ", but its mesh has " +
               std::to_string(vertices) + " vertices; the file is damaged");
      }
    }
  }
}

void check_3ds_bytes(std::string_view b) {
  if (b.size() < 6 || le16(b, 0) != 0x4D4D) {
    refuse("it does not start with a 3DS main chunk (0x4d4d); it is not a 3DS file");
  }
  if (le32(b, 2) < 6 || le32(b, 2) > b.size()) {
    refuse("chunk 0x4d4d at byte 0 claims " + std::to_string(le32(b, 2)) +
           " bytes, but the file has " + std::to_string(b.size()) + "; the file is damaged");
  }
  // The ends of the chunks enclosing `at`, innermost last.
  std::vector<std::size_t> open{le32(b, 2)};
  std::size_t at = 6;
  std::uint64_t mesh_vertices = 0;  // of the innermost triangle mesh chunk
  bool any_mesh = false;
  while (!open.empty()) {
    const std::size_t end = open.back();
    if (at >= end) {
      at = end;
      open.pop_back();
      continue;
    }
    if (end - at < 6)
      refuse("a chunk header at byte " + std::to_string(at) +
             " is cut off; "
             "the file is damaged");
    const std::uint16_t id = le16(b, at);
    const std::uint64_t length = le32(b, at + 2);
    if (length < 6 || length > end - at) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "%04x", id);
      refuse("chunk 0x" + std::string(hex) + " at byte " + std::to_string(at) + " claims " +
             std::to_string(length) + " bytes, past its parent's end; the file is damaged");
    }
    if (id >= 0xB020 && id <= 0xB029) check_3ds_track(b, at, length);
    if (id == 0x4110 || id == 0x4120 || id == 0x4140) check_3ds_list(b, at, length);
    if (id == 0x4100) {
      mesh_vertices = trimesh_vertices(b, at, length);
      any_mesh = true;
    }
    if (id == 0x4120) check_3ds_faces(b, at, mesh_vertices);
    if (!is_3ds_container(id)) {
      at += length;
      continue;
    }
    if (open.size() > std::size_t(kMax3dsDepth)) {
      refuse("its chunks nest deeper than " + std::to_string(kMax3dsDepth) +
             " levels; no 3DS file needs that, the file is damaged");
    }
    std::size_t body = at + 6;
    if (id == 0x4000) {  // a zero-terminated object name comes first
      while (body < at + length && b[body] != '\0') ++body;
      ++body;
    }
    open.push_back(std::size_t(at + length));
    at = body;
  }
  // Assimp would refuse it too, but leaks what it read first (a light: 1,132 bytes).
  if (!any_mesh) {
    refuse(
        "it holds no triangle mesh (no 0x4100 chunk; only lights, cameras or materials); "
        "export the geometry");
  }
}

}  // namespace

std::string check_3ds(const std::filesystem::path& path, std::uint64_t size) {
  return guarded(size, [&] { check_3ds_bytes(read_all(path)); });
}

}  // namespace meshes::detail
