// The streaming bake (prt/bake.h, bake_to_file): the passes of bake() over blocks of
// vertices, each block written out as it finishes. Design and measurements:
// docs/ARCHITECTURE.md, "Scale".
#include "prt/bake.h"

#include "bake_engine.h"
#include "common/atomic_file.h"
#include "common/mapped_file.h"
#include "meshes/spatial_order.h"
#include "prt/transfer_file.h"
#include "prt/transfer_shard.h"

#include <algorithm>
#include <functional>
#include <future>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace prt {
namespace {

namespace fs = std::filesystem;
using detail::HitBlock;
using detail::HitRecord;
using detail::kChunk;
using detail::VertexList;

// A pass's intermediate data on disk: an AtomicFile beside the output that is never
// committed, so it vanishes with the bake (or is swept after a crash), read back through
// its own descriptor or a map.
class Scratch {
 public:
  explicit Scratch(const fs::path& target) : file_(target) {
    fd_ = ::open(file_.temporary().c_str(), O_RDONLY | O_CLOEXEC);
    if (fd_ < 0) throw common::IoError(file_.temporary().string() + ": cannot reopen to read");
  }
  ~Scratch() { ::close(fd_); }
  Scratch(const Scratch&) = delete;
  Scratch& operator=(const Scratch&) = delete;

  std::uint64_t write(const void* data, std::size_t bytes) {
    const std::uint64_t at = size_;
    if (bytes > 0) file_.write(data, bytes);
    size_ += bytes;
    return at;
  }
  void read(void* out, std::size_t bytes, std::uint64_t offset) const {
    if (bytes > 0) common::read_exact(fd_, out, bytes, offset, file_.temporary().c_str());
  }
  const fs::path& path() const { return file_.temporary(); }

 private:
  common::AtomicFile file_;
  int fd_ = -1;
  std::uint64_t size_ = 0;
};

// The shadow pass's front hits, kept on disk for every bounce: per chunk, its offsets in
// memory (4 bytes a vertex) and where its records start in the scratch file.
class HitStore {
 public:
  explicit HitStore(const fs::path& target) : file_(target) {}
  void store(const std::vector<HitBlock>& blocks) {
    for (const HitBlock& b : blocks) {
      at_.push_back(file_.write(b.records.data(), b.records.size() * sizeof(HitRecord)));
      offsets_.push_back(b.offsets);
    }
  }
  // The chunks [first_chunk, first_chunk + count) as shadow() produced them.
  void load(std::size_t first_chunk, std::size_t count, std::vector<HitBlock>& out) const {
    out.resize(count);
    for (std::size_t c = 0; c < count; ++c) {
      const std::vector<std::uint32_t>& offsets = offsets_[first_chunk + c];
      out[c].offsets = offsets;
      out[c].records.resize(offsets.back());
      file_.read(out[c].records.data(), out[c].records.size() * sizeof(HitRecord),
                 at_[first_chunk + c]);
    }
  }

 private:
  Scratch file_;
  std::vector<std::uint64_t> at_;
  std::vector<std::vector<std::uint32_t>> offsets_;
};

fs::path scratch_target(const fs::path& path, const std::string& what) {
  return path.parent_path() / (path.filename().string() + "." + what);
}

// One task at a time beside the computation: a block's file writes run while the next block
// is computed, instead of holding up both cores' threads. run() waits for the previous task
// (and rethrows its failure), so a task may use a buffer until the task after it is started;
// callers alternate between two.
class Overlap {
 public:
  Overlap() = default;
  Overlap(const Overlap&) = delete;
  Overlap& operator=(const Overlap&) = delete;
  ~Overlap() {
    if (pending_.valid()) pending_.wait();  // an exception is already on its way
  }
  void run(std::function<void()> task) {
    wait();
    pending_ = std::async(std::launch::async, std::move(task));
  }
  void wait() {
    if (pending_.valid()) pending_.get();
  }

 private:
  std::future<void> pending_;
};

// The vertices of a bake with bounces in spatial order (meshes::spatial_order), and where
// each one's row is: every pass and running sum is stored in that order.
struct Layout {
  explicit Layout(const meshes::Mesh& mesh)
      : order(meshes::spatial_order(mesh)), row_of(meshes::inverse_permutation(order)) {}
  VertexList block(std::uint64_t begin, std::uint64_t end) const {
    return VertexList(order).subspan(begin, end - begin);
  }
  std::vector<std::uint32_t> order, row_of;
};

// A pass of every vertex in one file beside the output, which each rank of a distributed
// bake writes its slice of and then maps whole. Not an AtomicFile: every rank opens the
// same path. Reused across runs, since each run rewrites every byte it reads.
class SharedPass {
 public:
  explicit SharedPass(fs::path path) : path_(std::move(path)) {
    fd_ = ::open(path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0) throw common::IoError(path_.string() + ": cannot open the shared pass file");
  }
  ~SharedPass() { ::close(fd_); }
  SharedPass(const SharedPass&) = delete;
  SharedPass& operator=(const SharedPass&) = delete;

  void write(const float* data, std::size_t floats, std::uint64_t first_float) {
    common::write_exact(fd_, data, floats * sizeof(float), first_float * sizeof(float),
                        path_.c_str());
  }
  void read(void* out, std::size_t bytes, std::uint64_t offset) const {
    common::read_exact(fd_, out, bytes, offset, path_.c_str());
  }
  const fs::path& path() const { return path_; }
  std::uint64_t size() const {
    struct stat st {};
    if (::fstat(fd_, &st) != 0) throw common::IoError(path_.string() + ": cannot stat");
    return std::uint64_t(st.st_size);
  }

 private:
  fs::path path_;
  int fd_ = -1;
};

// The shadow pass of the layout's vertices [first, end), a block at a time: each block's rows
// and hits go to `store(rows, begin, end, hits)` on a task beside the next block's
// computation.
void shadow_in_layout_order(detail::BakeEngine& engine, const Layout& layout, std::uint64_t first,
                            std::uint64_t end, std::uint64_t block,
                            const std::function<void(const float*, std::uint64_t, std::uint64_t,
                                                     const std::vector<HitBlock>&)>& store) {
  const std::size_t per_vertex = engine.floats_per_vertex();
  std::vector<float> buffers[2];
  std::vector<HitBlock> hit_blocks[2];
  Overlap overlap;
  engine.start_pass(0);
  for (std::uint64_t begin = first, k = 0; begin < end; begin += block, ++k) {
    const std::uint64_t stop = std::min(end, begin + block);
    std::vector<float>& rows = buffers[k % 2];
    std::vector<HitBlock>& hits = hit_blocks[k % 2];
    rows.resize(std::min(block, end - first) * per_vertex);
    engine.shadow(layout.block(begin, stop), rows.data(), &hits);
    overlap.run([&store, &rows, &hits, begin, stop] { store(rows.data(), begin, stop, hits); });
  }
  overlap.wait();
  engine.finish_pass();
}

// Bounce pass `pass` over the layout's vertices [first, end), a block at a time: the engine
// computes the block's M^b, reading M^(b-1) through `read`; then, on a task beside the next
// block's computation, S^b = S^(b-1) + M^b (S^(b-1) read from `previous_sum`, whose row 0 is
// vertex `first` of the layout) and store(M^b, S^b, begin, end).
void bounce_in_layout_order(
    detail::BakeEngine& engine, const Layout& layout, int pass, std::uint64_t first,
    std::uint64_t end, std::uint64_t block, const HitStore& hits, const detail::PassReader& read,
    const Scratch& previous_sum,
    const std::function<void(const float*, const float*, std::uint64_t, std::uint64_t)>& store) {
  const std::size_t per_vertex = engine.floats_per_vertex();
  // Every block but the last has `block` vertices, so the same number of chunks.
  const std::uint64_t chunks_per_block = (block + kChunk - 1) / kChunk;
  std::vector<float> current[2], sum(std::min(block, end - first) * per_vertex);
  for (std::vector<float>& c : current) c.resize(sum.size());
  std::vector<HitBlock> hit_blocks;
  Overlap overlap;
  engine.start_pass(pass);
  for (std::uint64_t begin = first, k = 0; begin < end; begin += block, ++k) {
    const std::uint64_t stop = std::min(end, begin + block), n = (stop - begin) * per_vertex;
    const std::uint64_t local = begin - first;
    hits.load(local / block * chunks_per_block, (stop - begin + kChunk - 1) / kChunk, hit_blocks);
    float* const m = current[k % 2].data();
    engine.bounce(layout.block(begin, stop), hit_blocks, read, kGatherBlocks * block, m);
    overlap.run([&, begin, stop, local, n, m] {
      previous_sum.read(sum.data(), n * sizeof(float), local * per_vertex * sizeof(float));
      for (std::size_t i = 0; i < n; ++i) sum[i] += m[i];
      store(m, sum.data(), begin, stop);
    });
  }
  overlap.wait();
  engine.finish_pass();
}

// The last bounce's sums of the layout's vertices [begin, end), each row placed at its
// vertex's index in the output: the output is in index order, the bounces in layout order.
template <class Writer>
void place_in_index_order(Writer& writer, const Layout& layout, const float* sums,
                          std::uint64_t begin, std::uint64_t end, std::size_t per_vertex) {
  for (std::uint64_t i = begin; i < end; ++i)
    writer.place(layout.order[i], sums + (i - begin) * per_vertex, 1);
}

// The bounce passes of one process: bounce b reads M^(b-1) through the row cache from the
// previous pass's scratch file, and writes M^b and S^b to scratch files, or, for the last
// bounce, S^b row by row to its place in the output. (A last pass reading S^b back in index
// order to append it wrote and read the whole payload once more.)
void stream_bounces(detail::BakeEngine& engine, const Layout& layout, int bounces,
                    std::uint64_t block, const fs::path& path, const HitStore& hits,
                    std::shared_ptr<Scratch> previous_pass, TransferFileWriter& writer) {
  const std::uint64_t v = engine.vertex_count();
  const std::size_t per_vertex = engine.floats_per_vertex();
  const std::size_t row_bytes = per_vertex * sizeof(float);
  std::shared_ptr<Scratch> previous_sum = previous_pass;  // S^0 = M^0
  for (int b = 1; b <= bounces; ++b) {
    const bool last = b == bounces;
    auto pass = last ? nullptr : std::make_shared<Scratch>(scratch_target(path, "bounce"));
    auto running = last ? nullptr : std::make_shared<Scratch>(scratch_target(path, "sum"));
    const Scratch& previous_rows = *previous_pass;
    const detail::PassReader read = [&](std::uint64_t first, std::uint64_t rows, float* out) {
      previous_rows.read(out, rows * row_bytes, first * row_bytes);
    };
    bounce_in_layout_order(
        engine, layout, b, 0, v, block, hits, read, *previous_sum,
        [&](const float* m, const float* sum, std::uint64_t begin, std::uint64_t end) {
          const std::uint64_t bytes = (end - begin) * row_bytes;
          if (last) return place_in_index_order(writer, layout, sum, begin, end, per_vertex);
          pass->write(m, bytes);
          running->write(sum, bytes);
        });
    previous_pass = pass;
    previous_sum = running;
  }
}

// The shadow pass of vertices [first, end) in index order, appended to `writer` a block at a
// time: the whole bake when nothing reads another vertex's transfer (no bounces).
template <class Writer>
void shadow_in_index_order(detail::BakeEngine& engine, std::uint64_t first, std::uint64_t end,
                           std::uint64_t block, Writer& writer) {
  const std::size_t per_vertex = engine.floats_per_vertex();
  std::vector<float> buffer(std::min(end - first, block) * per_vertex);
  engine.start_pass(0);
  for (std::uint64_t begin = first; begin < end; begin += block) {
    const std::uint64_t stop = std::min(end, begin + block);
    engine.shadow(detail::index_range(begin, stop), buffer.data(), nullptr);
    writer.append(buffer.data(), (stop - begin) * per_vertex);
  }
  engine.finish_pass();
}

}  // namespace

TransferSet bake_rank(const meshes::Mesh& mesh, const BakeOptions& o, const fs::path& path,
                      std::uint32_t index, std::uint32_t count,
                      const std::function<void()>& barrier, std::uint64_t block_vertices,
                      BakeStats* stats) {
  if (count == 0 || index >= count) {
    throw std::invalid_argument("rank " + std::to_string(index) + " of " + std::to_string(count) +
                                ": needs 0 <= rank < ranks");
  }
  BakeStats local_stats;
  detail::BakeEngine engine(mesh, o, stats ? *stats : local_stats);
  const TransferSet shape = engine.shape();
  const std::uint64_t v = engine.vertex_count();
  const ShardRange range = shard_range(v, index, count);
  const std::size_t per_vertex = engine.floats_per_vertex();
  const std::size_t row_bytes = per_vertex * sizeof(float);
  const std::uint64_t block = std::max<std::uint64_t>(
      1, std::min(range.end - range.first,
                  block_vertices > 0 ? block_vertices : default_block_vertices(per_vertex)));
  TransferSliceWriter writer(path, shape, range.first, range.end);
  if (o.bounces == 0) {
    shadow_in_index_order(engine, range.first, range.end, block, writer);
    writer.close();
    engine.finish();
    return shape;
  }
  // Bounces: the rank computes a range of the layout, and writes its index range at the end.
  const Layout layout(mesh);
  engine.set_row_order(layout.row_of.data());
  SharedPass passes[2] = {SharedPass(path.string() + ".pass0"),
                          SharedPass(path.string() + ".pass1")};
  HitStore hits(scratch_target(path, "hits"));
  auto running = std::make_shared<Scratch>(scratch_target(path, "sum"));
  shadow_in_layout_order(engine, layout, range.first, range.end, block,
                         [&](const float* rows, std::uint64_t begin, std::uint64_t end,
                             const std::vector<HitBlock>& blocks) {
                           const std::uint64_t n = (end - begin) * per_vertex;
                           passes[0].write(rows, n, begin * per_vertex);
                           running->write(rows, n * sizeof(float));
                           hits.store(blocks);
                         });
  engine.end_tracing();
  barrier();  // every rank's M^0 is in passes[0]
  for (int b = 1; b <= o.bounces; ++b) {
    const bool last = b == o.bounces;
    auto next_running = last ? nullptr : std::make_shared<Scratch>(scratch_target(path, "sum"));
    const SharedPass& previous = passes[(b - 1) % 2];
    if (previous.size() < v * row_bytes)
      throw common::IoError(previous.path().string() +
                            ": shorter than a pass; is the output directory shared by all ranks?");
    const detail::PassReader read = [&](std::uint64_t first, std::uint64_t rows, float* out) {
      previous.read(out, rows * row_bytes, first * row_bytes);
    };
    // The last sums go straight to their place in the output: the ranks' ranges of the
    // layout together are every vertex once.
    bounce_in_layout_order(
        engine, layout, b, range.first, range.end, block, hits, read, *running,
        [&](const float* m, const float* sum, std::uint64_t begin, std::uint64_t end) {
          const std::uint64_t n = (end - begin) * per_vertex;
          if (last) return place_in_index_order(writer, layout, sum, begin, end, per_vertex);
          passes[b % 2].write(m, n, begin * per_vertex);
          next_running->write(sum, n * sizeof(float));
        });
    running = next_running;
    // Every rank's M^b is written, and nobody reads M^(b-1) any more, whose file pass b + 1
    // overwrites.
    if (!last) barrier();
  }
  writer.close();
  engine.finish();
  return shape;
}

std::uint64_t default_block_vertices(std::size_t floats_per_vertex) {
  // ~16 MiB of transfer per block buffer: dozens of chunks for the threads, and small beside
  // the mesh, its ray scene and the bounces' row cache (kGatherBlocks blocks).
  const std::uint64_t bytes = std::uint64_t(16) << 20;
  const std::uint64_t v = bytes / (floats_per_vertex * sizeof(float));
  return std::max<std::uint64_t>(kChunk, v / kChunk * kChunk);
}

TransferSet bake_to_file(const meshes::Mesh& mesh, const BakeOptions& o, const fs::path& path,
                         std::uint64_t block_vertices, BakeStats* stats) {
  BakeStats local_stats;
  detail::BakeEngine engine(mesh, o, stats ? *stats : local_stats);
  const TransferSet shape = engine.shape();
  const std::uint64_t v = engine.vertex_count();
  const std::size_t per_vertex = engine.floats_per_vertex();
  const std::uint64_t block =
      std::min(v, block_vertices > 0 ? block_vertices : default_block_vertices(per_vertex));
  TransferFileWriter writer(path, shape);
  if (o.bounces == 0) {
    shadow_in_index_order(engine, 0, v, block, writer);
  } else {
    const Layout layout(mesh);
    engine.set_row_order(layout.row_of.data());
    auto shadow_pass = std::make_shared<Scratch>(scratch_target(path, "shadow"));
    HitStore hits(scratch_target(path, "hits"));
    shadow_in_layout_order(engine, layout, 0, v, block,
                           [&](const float* rows, std::uint64_t begin, std::uint64_t end,
                               const std::vector<HitBlock>& blocks) {
                             shadow_pass->write(rows, (end - begin) * per_vertex * sizeof(float));
                             hits.store(blocks);
                           });
    engine.end_tracing();
    // Handed over, so that each pass's scratch is removed as soon as the bounces are done
    // with it.
    stream_bounces(engine, layout, o.bounces, block, path, hits, std::move(shadow_pass), writer);
  }
  writer.commit();
  engine.finish();
  return shape;
}

TransferSet bake_shard_to_file(const meshes::Mesh& mesh, const BakeOptions& o, const fs::path& path,
                               std::uint32_t index, std::uint32_t count,
                               std::uint64_t block_vertices, BakeStats* stats) {
  if (count == 0 || index >= count) {
    throw std::invalid_argument("--shard " + std::to_string(index) + "/" + std::to_string(count) +
                                ": k/n needs 0 <= k < n");
  }
  if (o.bounces > 0) {
    // A bounce reads the previous pass at every vertex its rays hit, anywhere on the mesh,
    // so a vertex range alone cannot compute it (docs/ARCHITECTURE.md, "Scale").
    throw std::invalid_argument(
        "--shard needs --bounces 0: an interreflection pass reads every vertex's previous "
        "pass; bake with bounces in one process (prtr bake streams, so memory stays bounded)");
  }
  BakeStats local_stats;
  detail::BakeEngine engine(mesh, o, stats ? *stats : local_stats);
  const TransferSet shape = engine.shape();
  const ShardRange range = shard_range(engine.vertex_count(), index, count);
  const std::size_t per_vertex = engine.floats_per_vertex();
  const std::uint64_t block =
      block_vertices > 0 ? block_vertices : default_block_vertices(per_vertex);
  TransferShardWriter writer(path, shape, range);
  shadow_in_index_order(engine, range.first, range.end, block, writer);
  writer.commit();
  engine.finish();
  return shape;
}

}  // namespace prt
