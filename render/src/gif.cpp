#include "render/gif.h"

#include "common/atomic_file.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace render {
namespace {

constexpr int kBins = 1 << 15;   // 5 bits per channel
constexpr int kMaxCodes = 4096;  // GIF's 12-bit code limit

int bin_channel(int bin, int axis) {
  return (bin >> (10 - 5 * axis)) & 31;
}

// Pixels of the frames that fall into each 5-bit bin, with their colour sums, so that a
// palette entry is the mean of the pixels it stands for rather than a bin centre.
struct Histogram {
  std::vector<std::uint64_t> count = std::vector<std::uint64_t>(kBins, 0);
  std::vector<std::array<std::uint64_t, 3>> sum =
      std::vector<std::array<std::uint64_t, 3>>(kBins, {0, 0, 0});
};

Histogram histogram(const std::vector<Rgb8Image>& frames) {
  Histogram h;
  for (const Rgb8Image& frame : frames)
    for (std::size_t i = 0; i + 2 < frame.rgb.size(); i += 3) {
      const std::uint8_t* p = &frame.rgb[i];
      const std::size_t bin =
          std::size_t(p[0] >> 3) << 10 | std::size_t(p[1] >> 3) << 5 | std::size_t(p[2] >> 3);
      ++h.count[bin];
      for (int c = 0; c < 3; ++c) h.sum[bin][c] += p[c];
    }
  return h;
}

struct Box {
  std::vector<int> bins;  // occupied bins
  std::uint64_t pixels = 0;
  int longest_axis = 0, extent = 0;  // extent: the longest side in bins, minus one
};

Box make_box(std::vector<int> bins, const Histogram& h) {
  Box box;
  box.bins = std::move(bins);
  int lo[3] = {31, 31, 31}, hi[3] = {0, 0, 0};
  for (int bin : box.bins) {
    box.pixels += h.count[std::size_t(bin)];
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], bin_channel(bin, a));
      hi[a] = std::max(hi[a], bin_channel(bin, a));
    }
  }
  for (int a = 0; a < 3; ++a)
    if (hi[a] - lo[a] > box.extent) box.extent = hi[a] - lo[a], box.longest_axis = a;
  return box;
}

// Splits at the pixel median along the longest side; both halves keep at least one bin.
std::pair<Box, Box> split(Box box, const Histogram& h) {
  const int axis = box.longest_axis;
  std::sort(box.bins.begin(), box.bins.end(),
            [axis](int a, int b) { return bin_channel(a, axis) < bin_channel(b, axis); });
  std::uint64_t below = 0;
  std::size_t cut = 1;
  for (; cut < box.bins.size(); ++cut) {
    below += h.count[std::size_t(box.bins[cut - 1])];
    if (2 * below >= box.pixels) break;
  }
  cut = std::min(cut, box.bins.size() - 1);
  std::vector<int> upper(box.bins.begin() + std::ptrdiff_t(cut), box.bins.end());
  box.bins.resize(cut);
  return {make_box(std::move(box.bins), h), make_box(std::move(upper), h)};
}

// Codes packed least-significant bit first, as GIF reads them.
class BitWriter {
 public:
  void put(int code, int width) {
    buffer_ |= std::uint64_t(code) << bits_;
    bits_ += width;
    while (bits_ >= 8) {
      bytes_.push_back(std::uint8_t(buffer_ & 0xff));
      buffer_ >>= 8;
      bits_ -= 8;
    }
  }
  std::vector<std::uint8_t> finish() {
    if (bits_ > 0) bytes_.push_back(std::uint8_t(buffer_ & 0xff));
    bits_ = 0;
    buffer_ = 0;
    return std::move(bytes_);
  }

 private:
  std::vector<std::uint8_t> bytes_;
  std::uint64_t buffer_ = 0;
  int bits_ = 0;
};

// (prefix code, next index) -> code, by open addressing; cleared with the code table.
class LzwTable {
 public:
  LzwTable() { clear(); }
  void clear() { std::fill(keys_.begin(), keys_.end(), -1); }
  int find(int prefix, int symbol) const {
    const int key = prefix << 8 | symbol;
    for (std::size_t slot = hash(key);; slot = (slot + 1) & kMask) {
      if (keys_[slot] == key) return codes_[slot];
      if (keys_[slot] < 0) return -1;
    }
  }
  void insert(int prefix, int symbol, int code) {
    const int key = prefix << 8 | symbol;
    std::size_t slot = hash(key);
    while (keys_[slot] >= 0) slot = (slot + 1) & kMask;
    keys_[slot] = key;
    codes_[slot] = std::int16_t(code);
  }

 private:
  static constexpr std::size_t kSlots = 8192;  // at most 4096 entries: half full
  static constexpr std::size_t kMask = kSlots - 1;
  static std::size_t hash(int key) { return (std::uint32_t(key) * 2654435761u >> 13) & kMask; }
  std::vector<int> keys_ = std::vector<int>(kSlots);
  std::vector<std::int16_t> codes_ = std::vector<std::int16_t>(kSlots);
};

void put16(std::vector<std::uint8_t>& out, int value) {
  out.push_back(std::uint8_t(value & 0xff));
  out.push_back(std::uint8_t(value >> 8 & 0xff));
}

void put_bytes(std::vector<std::uint8_t>& out, std::initializer_list<int> bytes) {
  for (int b : bytes) out.push_back(std::uint8_t(b));
}

}  // namespace

GifPalette median_cut_palette(const std::vector<Rgb8Image>& frames, int colours) {
  if (colours < 1 || colours > 256)
    throw std::invalid_argument("a GIF palette holds 1 to 256 colours, not " +
                                std::to_string(colours));
  const Histogram h = histogram(frames);
  std::vector<int> occupied;
  for (int bin = 0; bin < kBins; ++bin)
    if (h.count[std::size_t(bin)] > 0) occupied.push_back(bin);
  GifPalette palette;
  palette.lookup.assign(kBins, 0);
  if (occupied.empty()) {
    palette.colours.push_back({0, 0, 0});
    return palette;
  }
  // Heckbert splits the box with the most pixels; weighting by the longest side as well
  // keeps a large flat background from taking entries a small colourful object needs.
  std::vector<Box> boxes{make_box(std::move(occupied), h)};
  while (int(boxes.size()) < colours) {
    auto best = boxes.end();
    double best_score = 0;
    for (auto it = boxes.begin(); it != boxes.end(); ++it) {
      const double score = double(it->pixels) * double(it->extent);
      if (it->bins.size() > 1 && score >= best_score) best = it, best_score = score;
    }
    if (best == boxes.end()) break;  // every box is a single bin: the colours are exact
    auto [lower, upper] = split(std::move(*best), h);
    *best = std::move(lower);
    boxes.push_back(std::move(upper));
  }
  for (const Box& box : boxes) {
    std::array<std::uint64_t, 3> sum{0, 0, 0};
    for (int bin : box.bins)
      for (int c = 0; c < 3; ++c) sum[c] += h.sum[std::size_t(bin)][c];
    std::array<std::uint8_t, 3> colour{};
    for (int c = 0; c < 3; ++c)
      colour[c] = std::uint8_t((sum[c] + box.pixels / 2) / std::max<std::uint64_t>(box.pixels, 1));
    palette.colours.push_back(colour);
  }
  // Every bin maps to its nearest entry, so bins no frame used still map sensibly.
  for (int bin = 0; bin < kBins; ++bin) {
    int best = 0, best_distance = 1 << 30;
    for (std::size_t i = 0; i < palette.colours.size(); ++i) {
      int distance = 0;
      for (int c = 0; c < 3; ++c) {
        const int d = (bin_channel(bin, c) << 3 | 4) - palette.colours[i][std::size_t(c)];
        distance += d * d;
      }
      if (distance < best_distance) best_distance = distance, best = int(i);
    }
    palette.lookup[std::size_t(bin)] = std::uint8_t(best);
  }
  // A bin's own pixels map to the entry that holds them, which the nearest-centre rule
  // above can miss by a hair.
  for (std::size_t i = 0; i < boxes.size(); ++i)
    for (int bin : boxes[i].bins) palette.lookup[std::size_t(bin)] = std::uint8_t(i);
  return palette;
}

std::vector<std::uint8_t> gif_lzw(std::span<const std::uint8_t> indices, int min_code_size) {
  if (min_code_size < 2 || min_code_size > 8)
    throw std::invalid_argument("GIF's LZW minimum code size is 2 to 8, not " +
                                std::to_string(min_code_size));
  const int clear = 1 << min_code_size, end = clear + 1;
  BitWriter out;
  LzwTable table;
  int width = min_code_size + 1, next = end + 1;
  // The decoder defines a table entry for every code after the first one following a clear,
  // one code behind the encoder, and widens its codes once its next entry needs another
  // bit: the encoder widens after the same code.
  auto defined_one = [&] {
    ++next;
    if (next > (1 << width) && width < 12) ++width;
  };
  out.put(clear, width);
  if (indices.empty()) {
    out.put(end, width);
    return out.finish();
  }
  int prefix = indices[0];
  for (std::size_t i = 1; i < indices.size(); ++i) {
    const int symbol = indices[i];
    if (symbol >= clear) throw std::invalid_argument("a GIF index is past the palette");
    const int found = table.find(prefix, symbol);
    if (found >= 0) {
      prefix = found;
      continue;
    }
    out.put(prefix, width);
    if (next >= kMaxCodes - 1) {  // full: start a new table rather than code past 12 bits
      out.put(clear, width);
      table.clear();
      width = min_code_size + 1;
      next = end + 1;
    } else {
      table.insert(prefix, symbol, next);
      defined_one();
    }
    prefix = symbol;
  }
  out.put(prefix, width);
  defined_one();  // the decoder defines an entry for the last code too
  out.put(end, width);
  return out.finish();
}

void write_gif(const std::filesystem::path& path, const std::vector<Rgb8Image>& frames,
               double fps) {
  if (frames.empty()) throw std::invalid_argument("a GIF needs at least one frame");
  const int width = frames[0].width, height = frames[0].height;
  if (width < 1 || height < 1 || width > 65535 || height > 65535)
    throw std::invalid_argument("a GIF frame is 1 to 65535 pixels a side, not " +
                                std::to_string(width) + " x " + std::to_string(height));
  for (const Rgb8Image& frame : frames)
    if (frame.width != width || frame.height != height ||
        frame.rgb.size() != std::size_t(width) * std::size_t(height) * 3)
      throw std::invalid_argument("the frames of a GIF must share one size");
  if (!(fps > 0) || !std::isfinite(fps))
    throw std::invalid_argument("a GIF's frame rate must be positive and finite");

  const GifPalette palette = median_cut_palette(frames);
  int table_bits = 1;  // the colour table holds 2^table_bits entries
  while ((1 << table_bits) < int(palette.colours.size())) ++table_bits;
  const int min_code_size = std::max(2, table_bits);
  const int delay = int(std::clamp(std::lround(100.0 / fps), 2L, 65535L));

  std::vector<std::uint8_t> out;
  const std::string header = "GIF89a";
  out.insert(out.end(), header.begin(), header.end());
  put16(out, width);
  put16(out, height);
  put_bytes(out, {0x80 | 0x70 | (table_bits - 1), 0, 0});  // global table, 8-bit source
  for (int i = 0; i < (1 << table_bits); ++i)
    for (int c = 0; c < 3; ++c)
      out.push_back(i < int(palette.colours.size()) ? palette.colours[std::size_t(i)][c] : 0);
  const std::string netscape = "NETSCAPE2.0";
  put_bytes(out, {0x21, 0xff, 11});
  out.insert(out.end(), netscape.begin(), netscape.end());
  put_bytes(out, {3, 1, 0, 0, 0});  // loop count 0: forever

  std::vector<std::uint8_t> indices(std::size_t(width) * std::size_t(height));
  for (const Rgb8Image& frame : frames) {
    put_bytes(out, {0x21, 0xf9, 4, 0x04});  // graphic control: keep the frame, no transparency
    put16(out, delay);
    put_bytes(out, {0, 0});
    put_bytes(out, {0x2c});  // image descriptor: the whole screen, no local table
    put16(out, 0);
    put16(out, 0);
    put16(out, width);
    put16(out, height);
    out.push_back(0);
    for (std::size_t i = 0; i < indices.size(); ++i) indices[i] = palette.index(&frame.rgb[3 * i]);
    const std::vector<std::uint8_t> codes = gif_lzw(indices, min_code_size);
    out.push_back(std::uint8_t(min_code_size));
    for (std::size_t at = 0; at < codes.size(); at += 255) {
      const std::size_t n = std::min<std::size_t>(255, codes.size() - at);
      out.push_back(std::uint8_t(n));
      out.insert(out.end(), codes.begin() + std::ptrdiff_t(at),
                 codes.begin() + std::ptrdiff_t(at + n));
    }
    out.push_back(0);
  }
  out.push_back(0x3b);
  common::write_file_atomically(path, out.data(), out.size());
}

}  // namespace render
