#include "rgbe_file.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <vector>

namespace probes::detail {

namespace {

// A header is a few lines; Radiance's own writers stay far below this.
constexpr std::size_t kMaxHeaderBytes = 64 * 1024;
constexpr int kMaxSide = 1 << 20;

bool starts_with(const std::string& s, const char* prefix) {
  return s.compare(0, std::strlen(prefix), prefix) == 0;
}

class RgbeFile final : public common::ImageFile {
 public:
  RgbeFile(std::ifstream in, common::ImageHeader header, bool flip)
      : in_(std::move(in)), header_(std::move(header)), flip_(flip) {}

  const common::ImageHeader& header() const override { return header_; }

  bool read(int channels, float* pixels, std::string* error) override {
    const int w = header_.width, h = header_.height;
    std::vector<std::uint8_t> line(std::size_t(w) * 4);
    for (int y = 0; y < h; ++y) {
      if (!read_scanline(line, error)) {
        *error = "scanline " + std::to_string(y) + " of " + std::to_string(h) + ": " + *error;
        return false;
      }
      // "+Y H" stores the bottom row first; rows are returned top first.
      float* row = pixels + std::size_t(flip_ ? h - 1 - y : y) * std::size_t(w) * channels;
      for (int x = 0; x < w; ++x) {
        const std::uint8_t* p = &line[std::size_t(x) * 4];
        const float scale = p[3] == 0 ? 0.f : std::ldexp(1.f, int(p[3]) - 136);
        float rgb[3] = {p[0] * scale, p[1] * scale, p[2] * scale};
        for (int c = 0; c < channels; ++c) row[std::size_t(x) * channels + c] = rgb[c < 3 ? c : 2];
      }
    }
    return true;
  }

 private:
  bool get(std::uint8_t* bytes, std::size_t n, std::string* error) {
    in_.read(reinterpret_cast<char*>(bytes), std::streamsize(n));
    if (std::size_t(in_.gcount()) == n) return true;
    *error = "the file ends inside it";
    return false;
  }

  // One scanline into RGBE quadruples, whichever of the three encodings it uses.
  bool read_scanline(std::vector<std::uint8_t>& line, std::string* error) {
    const int w = header_.width;
    std::uint8_t first[4];
    if (!get(first, 4, error)) return false;
    const bool new_rle = w >= 8 && w <= 0x7fff && first[0] == 2 && first[1] == 2 && first[2] < 128;
    if (!new_rle) return read_old(line, first, error);
    if ((int(first[2]) << 8 | first[3]) != w) {
      *error = "its run-length header gives width " +
               std::to_string(int(first[2]) << 8 | first[3]) + ", the image's is " +
               std::to_string(w);
      return false;
    }
    // Four planes (R, G, B, E), each of runs: n > 128 repeats the next byte n - 128 times,
    // 0 < n <= 128 copies the next n bytes.
    for (int c = 0; c < 4; ++c) {
      int x = 0;
      while (x < w) {
        std::uint8_t n = 0;
        if (!get(&n, 1, error)) return false;
        const bool run = n > 128;
        const int count = run ? n - 128 : n;
        if (count == 0 || x + count > w) {
          *error = count == 0 ? "a run of length 0"
                              : "a run past the end of the line (at " + std::to_string(x) + " + " +
                                    std::to_string(count) + " of " + std::to_string(w) + ")";
          return false;
        }
        if (run) {
          std::uint8_t value = 0;
          if (!get(&value, 1, error)) return false;
          for (int i = 0; i < count; ++i) line[std::size_t(x + i) * 4 + c] = value;
        } else {
          std::uint8_t bytes[128];
          if (!get(bytes, std::size_t(count), error)) return false;
          for (int i = 0; i < count; ++i) line[std::size_t(x + i) * 4 + c] = bytes[i];
        }
        x += count;
      }
    }
    return true;
  }

  // Flat pixels, where (1, 1, 1, n) repeats the previous pixel n times, the count's bytes
  // shifting left by 8 for each repeat marker in a row (the old scheme).
  bool read_old(std::vector<std::uint8_t>& line, const std::uint8_t* first, std::string* error) {
    const int w = header_.width;
    std::uint8_t p[4] = {first[0], first[1], first[2], first[3]};
    int x = 0, shift = 0;
    bool have = true;
    while (x < w) {
      if (!have && !get(p, 4, error)) return false;
      have = false;
      if (p[0] == 1 && p[1] == 1 && p[2] == 1) {
        if (x == 0) {
          *error = "a repeat before the line's first pixel";
          return false;
        }
        const long long count = (long long)(p[3]) << shift;
        if (shift > 16 || x + count > w) {
          *error = "a repeat past the end of the line";
          return false;
        }
        for (long long i = 0; i < count; ++i, ++x)
          std::memcpy(&line[std::size_t(x) * 4], &line[std::size_t(x - 1) * 4], 4);
        shift += 8;
      } else {
        std::memcpy(&line[std::size_t(x) * 4], p, 4);
        ++x;
        shift = 0;
      }
    }
    return true;
  }

  std::ifstream in_;
  common::ImageHeader header_;
  bool flip_ = false;
};

}  // namespace

bool is_rgbe(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  char magic[10] = {};
  in.read(magic, sizeof magic);
  const std::string start(magic, std::size_t(in.gcount()));
  return starts_with(start, "#?RADIANCE") || starts_with(start, "#?RGBE");
}

std::unique_ptr<common::ImageFile> open_rgbe(const std::filesystem::path& path,
                                             std::string* error) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    *error = "cannot be opened";
    return nullptr;
  }
  // Header lines up to an empty one, then the resolution line.
  std::size_t header_bytes = 0;
  auto next_line = [&](std::string* line) {
    line->clear();
    for (char c; in.get(c);) {
      if (++header_bytes > kMaxHeaderBytes) return false;
      if (c == '\n') return true;
      *line += c;
    }
    return false;
  };
  std::string line;
  common::ImageHeader header;
  header.channels = 3;
  header.floating_point = true;
  header.format = "hdr";
  bool first = true;
  while (true) {
    if (!next_line(&line)) {
      *error = header_bytes > kMaxHeaderBytes
                   ? "its Radiance header runs past " + std::to_string(kMaxHeaderBytes) + " bytes"
                   : "its Radiance header has no end (an empty line, then the resolution)";
      return nullptr;
    }
    if (first && !starts_with(line, "#?")) {
      *error = "not a Radiance file (no #? line)";
      return nullptr;
    }
    first = false;
    if (line.empty()) break;
    if (starts_with(line, "FORMAT=") && line != "FORMAT=32-bit_rle_rgbe") {
      *error = "its pixels are " + line.substr(7) +
               ", not 32-bit_rle_rgbe; convert the map to RGB radiance";
      return nullptr;
    }
  }
  if (!next_line(&line)) {
    *error = "no resolution line after the header";
    return nullptr;
  }
  char ys = 0, xs = 0, ya = 0, xa = 0, extra = 0;
  long long h = 0, w = 0;
  if (std::sscanf(line.c_str(), "%c%c %lld %c%c %lld %c", &ys, &ya, &h, &xs, &xa, &w, &extra) !=
          6 ||
      ya != 'Y' || xa != 'X' || (ys != '-' && ys != '+') || xs != '+') {
    *error = "resolution line \"" + line.substr(0, 40) +
             "\" is not \"-Y H +X W\" or \"+Y H +X W\" (transposed and mirrored maps are not "
             "read; re-export the map)";
    return nullptr;
  }
  if (w < 1 || h < 1 || w > kMaxSide || h > kMaxSide) {
    *error = "resolution " + std::to_string(w) + " x " + std::to_string(h) +
             " out of range (1 to " + std::to_string(kMaxSide) +
             " a side); the header is damaged, re-export the map";
    return nullptr;
  }
  header.width = int(w);
  header.height = int(h);
  header.full_width = header.width;
  header.full_height = header.height;
  return std::make_unique<RgbeFile>(std::move(in), std::move(header), ys == '+');
}

}  // namespace probes::detail
