// prt/src/bake_engine.h (private to prt): the bake's passes over a range of vertices, so
// that the whole-mesh bake (bake.cpp) and the streaming bake (bake_stream.cpp) run the same
// per-vertex code and produce the same bits. The formulation is in prt/bake.h.
#pragma once

#include "prt/bake.h"

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

namespace prt::detail {

inline constexpr std::uint64_t kChunk = 64;  // vertices per scheduling unit (and hit block)

// The vertices a pass computes, in the order their rows are written.
using VertexList = std::span<const std::uint32_t>;

// Faults in the whole pages of [start, start + bytes) from the worker threads (Linux's
// MADV_POPULATE_WRITE; a no-op where the kernel lacks it), so that a large fresh allocation's
// first writes on one thread run at memory bandwidth instead of one page fault per page.
void populate_pages(void* start, std::size_t bytes);

// The vertices [begin, end) in index order.
std::vector<std::uint32_t> index_range(std::uint64_t begin, std::uint64_t end);

// An occluded ray that hit the front of a triangle: what a bounce needs of it.
struct HitRecord {
  std::uint16_t direction;  // index into the shared direction set
  std::int32_t triangle;
  float u, v;
};

// Front-hit records of kChunk consecutive vertices; offsets has one entry per vertex + 1.
struct HitBlock {
  std::vector<HitRecord> records;
  std::vector<std::uint32_t> offsets;
};

// Reads `rows` consecutive rows of a previous pass from row `first` into out; called from
// worker threads at once.
using PassReader = std::function<void(std::uint64_t first, std::uint64_t rows, float* out)>;

class BakeEngine {
 public:
  // Validates the options and the mesh's frames, builds the direction set, the ray scene and
  // the ray start points. `stats` is reset here and filled as passes run.
  BakeEngine(const meshes::Mesh& mesh, const BakeOptions& options, BakeStats& stats);
  ~BakeEngine();

  // Every header field of the result; data empty.
  TransferSet shape() const;
  std::size_t floats_per_vertex() const;
  std::uint64_t vertex_count() const;

  // The progress callback's pass boundaries; a pass may span many ranges.
  void start_pass(int pass);
  void finish_pass();

  // Shadow pass of `vertices` into dst (vertices.size() x floats_per_vertex, row i for
  // vertices[i]). With bounces, `hits` gets the front hits of each kChunk of them.
  void shadow(VertexList vertices, float* dst, std::vector<HitBlock>* hits);
  // The shadow pass is done: frees the ray scene and the rays' start points, which the
  // bounces (reading stored hits) do not need; a streaming bake's bounces then hold the
  // memory of their row cache instead. shadow() may not be called after it.
  void end_tracing();
  // The row order every previous pass is stored in for bounce(): vertex q in row row_of[q]
  // (null, the default: row q). row_of must outlive the bounces.
  void set_row_order(const std::uint32_t* row_of);
  // One bounce of `vertices` into dst, from the whole previous pass `previous`
  // (vertex_count x floats_per_vertex, in the row order) and the list's hits as shadow()
  // gave them for the same list.
  void bounce(VertexList vertices, const std::vector<HitBlock>& hits, const float* previous,
              float* dst);
  // The same bounce, reading the previous pass through `read` instead of holding it: the rows
  // that a group of vertices' hits reach are read into a cache of cache_rows rows (grown only
  // for a single vertex that needs more), so memory stays bounded whatever the mesh
  // (corner_gather.h). The cache is made by the first call and kept across calls and passes.
  // Same bits as bounce().
  void bounce(VertexList vertices, const std::vector<HitBlock>& hits, const PassReader& read,
              std::size_t cache_rows, float* dst);
  // Fills the remaining stats (ray counts, flagged vertices, total time).
  void finish();

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace prt::detail
