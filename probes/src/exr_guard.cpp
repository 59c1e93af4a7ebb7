// The OpenEXR file layout read here is the one in "OpenEXR File Layout" (openexr.com): magic
// and version, then per part a list of attributes (name\0 type\0 int32 size, value) ended by
// an empty name, then a table of one 8-byte offset per chunk.
#include "exr_guard.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <unordered_map>
#include <vector>

namespace probes::detail {

namespace {

// The number of bytes OpenEXR reads for an attribute value of `type` starting at `at`, which
// for most types is fixed by the type and not by the size the file declares; -1 for types
// whose value is as long as the declared size (strings, vectors, unknown types), -2 when a
// value does not end within `limit`.
std::int64_t exr_value_bytes(const std::string& type, const std::vector<char>& bytes,
                             std::size_t at, std::size_t limit) {
  static const std::unordered_map<std::string, std::int64_t> kFixed = {
      {"box2i", 16},      {"box2f", 16},   {"chromaticities", 32},
      {"compression", 1}, {"double", 8},   {"envmap", 1},
      {"float", 4},       {"int", 4},      {"keycode", 28},
      {"lineOrder", 1},   {"m33f", 36},    {"m33d", 72},
      {"m44f", 64},       {"m44d", 128},   {"rational", 8},
      {"tiledesc", 9},    {"timecode", 8}, {"v2i", 8},
      {"v2f", 8},         {"v2d", 16},     {"v3i", 12},
      {"v3f", 12},        {"v3d", 24},     {"deepImageState", 1}};
  if (const auto it = kFixed.find(type); it != kFixed.end()) return it->second;
  if (type == "chlist") {
    // Channel records (name\0, then 16 bytes) up to an empty name.
    std::size_t pos = at;
    while (pos < limit && bytes[pos] != 0) {
      while (pos < limit && bytes[pos] != 0) ++pos;
      pos += 1 + 16;
    }
    return pos < limit ? std::int64_t(pos + 1 - at) : -2;
  }
  if (type == "preview") {
    // Width and height, then 4 bytes per pixel: the size of the buffer OpenEXR allocates.
    if (at + 8 > limit) return -2;
    std::uint32_t wh[2];
    std::memcpy(wh, bytes.data() + at, 8);
    return std::int64_t(8 + 4 * std::uint64_t(wh[0]) * wh[1]);
  }
  return -1;
}

// What one part's header says about the buffers OpenEXR will size from it. The defaults are
// OpenEXR's own for a header that leaves the attribute out (a 64 x 64 window, ZIP).
struct PartLayout {
  std::int64_t width = 64, height = 64;
  int compression = 3;
  bool tiled = false;
  std::int64_t tile_x = 0, tile_y = 0;
  int level_mode = 0;  // one level, mipmap, ripmap
  double pixel_bytes = 0;
  std::int64_t chunk_count = -1;  // the "chunkCount" attribute, when present
  std::string type;
};

template <class T>
T read_at(const char* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

// Records the attributes that size buffers. `value` holds `size` bytes, already checked.
void note_attribute(PartLayout& part, const std::string& name, const std::string& type,
                    const char* value, std::size_t size) {
  if (name == "dataWindow" && type == "box2i") {
    const auto x0 = read_at<std::int32_t>(value), y0 = read_at<std::int32_t>(value + 4);
    const auto x1 = read_at<std::int32_t>(value + 8), y1 = read_at<std::int32_t>(value + 12);
    part.width = std::int64_t(x1) - x0 + 1;
    part.height = std::int64_t(y1) - y0 + 1;
  } else if (name == "compression" && type == "compression") {
    part.compression = static_cast<unsigned char>(value[0]);
  } else if (name == "tiles" && type == "tiledesc") {
    part.tiled = true;
    part.tile_x = read_at<std::uint32_t>(value);
    part.tile_y = read_at<std::uint32_t>(value + 4);
    part.level_mode = static_cast<unsigned char>(value[8]) & 0x0f;
  } else if (name == "chunkCount" && type == "int") {
    part.chunk_count = read_at<std::int32_t>(value);
  } else if (name == "type" && type == "string") {
    part.type.assign(value, size);
  } else if (name == "channels" && type == "chlist") {
    part.pixel_bytes = 0;
    for (std::size_t pos = 0; pos < size && value[pos] != 0;) {
      pos += std::strlen(value + pos) + 1;
      if (pos + 16 > size) break;
      part.pixel_bytes += read_at<std::int32_t>(value + pos) == 1 ? 2 : 4;  // half : uint, float
      pos += 16;
    }
  }
}

// Scan lines per chunk for each of OpenEXR's compression methods, NONE to DWAB.
constexpr int kLinesPerChunk[] = {1, 1, 1, 16, 32, 16, 32, 32, 32, 256};

// The fewest chunks a tiled part of this size has (levels rounded down), in floating point so
// that a hostile header cannot overflow it.
double tile_count(const PartLayout& p) {
  const auto tiles = [&](std::int64_t w, std::int64_t h) {
    return std::ceil(double(std::max<std::int64_t>(w, 1)) / double(p.tile_x)) *
           std::ceil(double(std::max<std::int64_t>(h, 1)) / double(p.tile_y));
  };
  const auto levels = [](std::int64_t n) { return int(std::floor(std::log2(double(n)))) + 1; };
  double count = 0;
  if (p.level_mode == 1) {
    for (int l = 0; l < levels(std::max(p.width, p.height)); ++l) {
      count += tiles(p.width >> l, p.height >> l);
    }
  } else if (p.level_mode == 2) {
    for (int lx = 0; lx < levels(p.width); ++lx) {
      for (int ly = 0; ly < levels(p.height); ++ly) count += tiles(p.width >> lx, p.height >> ly);
    }
  } else {
    count = tiles(p.width, p.height);
  }
  return count;
}

std::string megabytes(double bytes) {
  return std::to_string(std::int64_t(std::ceil(bytes / 1e6))) + " MB";
}

// Checks one part's layout against the file's size; adds its chunks to `chunks`.
std::string check_part(const PartLayout& p, std::uintmax_t file_size, double& chunks) {
  const std::string window = "its OpenEXR data window (" + std::to_string(p.width) + " x " +
                             std::to_string(p.height) + ")";
  if (p.type.rfind("deep", 0) == 0) return "deep OpenEXR images are not environment maps";
  if (p.width <= 0 || p.height <= 0) return window + " is empty; the file is damaged, re-export it";
  if (p.compression >= int(std::size(kLinesPerChunk))) {
    return "its OpenEXR compression method " + std::to_string(p.compression) +
           " is unknown; re-export it with ZIP, PIZ or no compression";
  }
  if (p.tiled && (p.tile_x <= 0 || p.tile_y <= 0 || p.level_mode > 2)) {
    return "its OpenEXR tile description is invalid; the file is damaged, re-export it";
  }
  const double pixel_bytes = std::max(p.pixel_bytes, 2.0);
  const double chunk_bytes = p.tiled
                                 ? double(p.tile_x) * double(p.tile_y) * pixel_bytes
                                 : double(p.width) * pixel_bytes * kLinesPerChunk[p.compression];
  const double limit = std::max(kAlwaysAllowedBytes, double(file_size) * kMaxExpansion);
  if (chunk_bytes > limit) {
    return window + " makes each " + (p.tiled ? "tile" : "block of scan lines") + " decode to " +
           megabytes(chunk_bytes) + ", more than a " + std::to_string(file_size) +
           "-byte file can hold; the header is damaged, re-export the map";
  }
  const double count =
      p.tiled ? tile_count(p) : std::ceil(double(p.height) / kLinesPerChunk[p.compression]);
  chunks += std::max(count, double(p.chunk_count));
  return {};
}

}  // namespace

std::string check_exr_header(const std::filesystem::path& path, std::uintmax_t file_size) {
  std::ifstream in(path, std::ios::binary);
  // Headers are small; what matters is that no attribute claims more than the file holds.
  constexpr std::size_t kHeaderWindow = 1 << 20;
  std::vector<char> bytes(std::min<std::uintmax_t>(file_size, kHeaderWindow));
  in.read(bytes.data(), std::streamsize(bytes.size()));
  bytes.resize(std::size_t(in.gcount()));
  if (bytes.size() < 8 || std::memcmp(bytes.data(), "\x76\x2f\x31\x01", 4) != 0) return {};
  const bool multipart = (read_at<std::uint32_t>(bytes.data() + 4) & 0x1000u) != 0;
  std::size_t at = 8;
  // A null-terminated name of at most 255 characters at `pos`.
  const auto name_at = [&](std::size_t& pos, std::string& name) {
    const std::size_t limit = std::min(bytes.size(), pos + 256);
    const auto end = std::find(bytes.begin() + std::ptrdiff_t(std::min(pos, limit)),
                               bytes.begin() + std::ptrdiff_t(limit), '\0');
    if (end == bytes.begin() + std::ptrdiff_t(limit)) return false;
    name.assign(bytes.begin() + std::ptrdiff_t(pos), end);
    pos = std::size_t(end - bytes.begin()) + 1;
    return true;
  };
  double chunks = 0;
  for (int header = 0; header < 1024; ++header) {
    PartLayout part;
    bool any = false;
    while (true) {
      std::string name, type;
      if (!name_at(at, name)) return {};  // past what we read: OpenEXR reports it
      if (name.empty()) break;
      any = true;
      if (!name_at(at, type) || at + 4 > bytes.size()) return {};
      const auto size = read_at<std::int32_t>(bytes.data() + at);
      at += 4;
      const std::string what = "its OpenEXR header attribute '" + name + "' (" + type + ")";
      if (size < 0 || std::uintmax_t(size) > file_size - std::min<std::uintmax_t>(at, file_size)) {
        return what + " claims " + std::to_string(size) + " bytes, but the file has only " +
               std::to_string(file_size) +
               " bytes in all; the file is damaged or truncated, re-export it";
      }
      if (std::size_t(size) > bytes.size() - at) return {};
      const std::int64_t takes = exr_value_bytes(type, bytes, at, bytes.size());
      if (takes != -1 && takes != size) {
        return what + " declares " + std::to_string(size) + " bytes, but its value " +
               (takes == -2 ? std::string("does not end within the file")
                            : "takes " + std::to_string(takes)) +
               "; the file is damaged, re-export it";
      }
      note_attribute(part, name, type, bytes.data() + at, std::size_t(size));
      at += std::size_t(size);
    }
    if (multipart && !any) break;
    if (std::string problem = check_part(part, file_size, chunks); !problem.empty()) {
      return problem;
    }
    if (!multipart) break;
  }
  // Every chunk has an 8-byte entry in the offset table that follows the headers, and
  // OpenEXR sizes the table from the header before reading it.
  if (chunks * 8 > double(file_size)) {
    return "its OpenEXR header describes " + std::to_string(std::int64_t(chunks)) +
           " chunks of pixels, but the file's " + std::to_string(file_size) +
           " bytes cannot hold even their offset table; the header is damaged, re-export it";
  }
  return {};
}

}  // namespace probes::detail
