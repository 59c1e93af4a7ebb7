#include "read_3ds.h"

#include <cstring>
#include <fstream>
#include <iterator>
#include <vector>

namespace meshes::detail {
namespace {

constexpr std::uint16_t kMain = 0x4D4D, kEditor = 0x3D3D, kObject = 0x4000, kTriMesh = 0x4100,
                        kVertices = 0x4110, kFaces = 0x4120;

template <class T>
bool read_at(const std::vector<char>& bytes, std::size_t offset, T& value) {
  if (offset + sizeof(T) > bytes.size()) return false;
  std::memcpy(&value, bytes.data() + offset, sizeof(T));
  return true;
}

struct Parser {
  const std::vector<char>& bytes;
  Raw3ds& out;
  std::string problem;

  // Walks the chunk tree under [begin, end). Containers nest as deep as the file says, so the
  // walk keeps its own stack of open containers on the heap instead of recursing: depth costs
  // 16 bytes per level and is bounded by the file size (a chunk takes at least 6 bytes).
  bool walk(std::size_t begin, std::size_t end) {
    struct Open {
      std::size_t at, end;
    };
    std::vector<Open> open{{begin, end}};
    std::size_t base = 0;  // index of the current object's first vertex
    while (!open.empty()) {
      Open& top = open.back();
      if (top.at + 6 > top.end) {
        open.pop_back();
        continue;
      }
      const std::size_t at = top.at;
      std::uint16_t id = 0;
      std::uint32_t length = 0;
      read_at(bytes, at, id);
      read_at(bytes, at + 2, length);
      if (length < 6 || length > top.end - at) {
        problem = "chunk 0x" + hex(id) + " at byte " + std::to_string(at) + " claims " +
                  std::to_string(length) + " bytes, past its parent's end; the file is damaged";
        return false;
      }
      const std::size_t body = at + 6, stop = at + length;
      top.at = stop;  // before the push below, which may move `top`
      if (id == kMain || id == kEditor || id == kTriMesh) {
        if (id == kTriMesh) base = out.positions.size();
        open.push_back({body, stop});
      } else if (id == kObject) {
        std::size_t name_end = body;
        while (name_end < stop && bytes[name_end] != 0) ++name_end;  // object name
        open.push_back({name_end + 1, stop});
      } else if (id == kVertices) {
        std::uint16_t n = 0;
        if (!read_at(bytes, body, n) || body + 2 + std::size_t(n) * 12 > stop)
          return fail("vertex list", at);
        for (std::size_t i = 0; i < n; ++i) {
          float p[3];
          std::memcpy(p, bytes.data() + body + 2 + i * 12, 12);
          out.positions.emplace_back(p[0], p[2], -p[1]);
        }
      } else if (id == kFaces) {
        std::uint16_t n = 0;
        if (!read_at(bytes, body, n) || body + 2 + std::size_t(n) * 8 > stop)
          return fail("face list", at);
        for (std::size_t i = 0; i < n; ++i) {
          std::uint16_t f[4];
          std::memcpy(f, bytes.data() + body + 2 + i * 8, 8);
          for (int c = 0; c < 3; ++c) out.corners.push_back(std::uint32_t(base + f[c]));
        }
      }
    }
    return true;
  }

  bool fail(const char* what, std::size_t at) {
    problem = std::string(what) + " chunk at byte " + std::to_string(at) +
              " is shorter than its count says; the file is damaged";
    return false;
  }

  static std::string hex(std::uint16_t v) {
    char buf[8];
    std::snprintf(buf, sizeof buf, "%04x", v);
    return buf;
  }
};

}  // namespace

std::string read_3ds(const std::filesystem::path& path, Raw3ds& out) {
  std::ifstream in(path, std::ios::binary);
  const std::vector<char> bytes((std::istreambuf_iterator<char>(in)),
                                std::istreambuf_iterator<char>());
  std::uint16_t id = 0;
  if (!read_at(bytes, 0, id) || id != kMain)
    return "not a 3DS file (it does not start with the main chunk 0x4d4d)";
  Parser parser{bytes, out, {}};
  if (!parser.walk(0, bytes.size())) return parser.problem;
  return {};
}

}  // namespace meshes::detail
