#include "prt/mapped_transfer.h"

#include "common/hash.h"
#include "prt/transfer_file.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace prt {

MappedTransfer::MappedTransfer(const std::filesystem::path& path)
    : header_(read_transfer_header(path)), file_(path) {
  const std::string name = path.string();
  const std::uint64_t floats = header_.vertex_count * header_.floats_per_vertex();
  if (file_.size() != kTransferHeaderBytes + floats * sizeof(float))
    throw TransferFileError(name + ": the file changed size while it was opened; try again");
  // The checksum and the finite check in one pass of 64 MiB chunks, each released after,
  // so that validating a file larger than memory does not make it resident.
  constexpr std::uint64_t kChunkFloats = std::uint64_t(16) << 20;
  const float* data = payload();
  std::uint64_t hash = common::kFnvOffset;
  for (std::uint64_t begin = 0; begin < floats; begin += kChunkFloats) {
    const std::uint64_t n = std::min(kChunkFloats, floats - begin);
    hash = common::fnv1a(data + begin, n * sizeof(float), hash);
    const float* bad =
        std::find_if(data + begin, data + begin + n, [](float v) { return !std::isfinite(v); });
    if (bad != data + begin + n) {
      const std::uint64_t i = std::uint64_t(bad - data);
      throw TransferFileError(name + ": non-finite value at vertex " +
                              std::to_string(i / header_.floats_per_vertex()) +
                              "; the file is damaged: bake it again with prtr bake");
    }
    file_.release(kTransferHeaderBytes + begin * sizeof(float), n * sizeof(float));
  }
  if (hash != header_.payload_checksum)
    throw TransferFileError(name +
                            ": payload checksum does not match the header; the file is damaged "
                            "or truncated: bake it again with prtr bake");
}

const float* MappedTransfer::payload() const {
  // The header is 128 bytes and the mapping page-aligned: the floats are aligned.
  return reinterpret_cast<const float*>(file_.data() + kTransferHeaderBytes);
}

void MappedTransfer::read_rows(const std::uint32_t* rows, std::size_t count, float* out) const {
  const std::uint64_t row = header_.floats_per_vertex() * sizeof(float);
  for (std::size_t i = 0; i < count;) {
    std::size_t run = 1;
    while (i + run < count && rows[i + run] == rows[i] + run) ++run;
    file_.read(kTransferHeaderBytes + rows[i] * row, out + i * header_.floats_per_vertex(),
               run * row);
    i += run;
  }
}

void MappedTransfer::release(std::uint64_t first, std::uint64_t count) const {
  const std::uint64_t row = header_.floats_per_vertex() * sizeof(float);
  file_.release(kTransferHeaderBytes + first * row, count * row);
}

}  // namespace prt
