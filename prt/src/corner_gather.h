// prt/src/corner_gather.h (private to prt): the rows of a previous pass that a bounce reads,
// held in a bounded cache, so that a streaming bake's bounce keeps a buffer of fixed size
// instead of mapping the whole pass (docs/ARCHITECTURE.md, "Scale"). A bounce runs a group of
// vertices at a time: collect() takes vertices while their hits' corners fit the cache, load()
// reads the corners not already held, evicting only rows the group does not need. Groups
// follow the spatial order, so neighbouring groups see the same surfaces and most of a
// group's rows are still held from the group before.
#pragma once

#include "bake_engine.h"
#include "meshes/mesh.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace prt::detail {

template <class T>
struct HugePageAllocator {
  using value_type = T;
  HugePageAllocator() = default;
  template <class U>
  HugePageAllocator(const HugePageAllocator<U>&) {}
  T* allocate(std::size_t n);
  void deallocate(T* p, std::size_t n);
  bool operator==(const HugePageAllocator&) const { return true; }
};

class CornerGather {
 public:
  // A cache of capacity_rows rows (grown when a single vertex needs more).
  CornerGather(const meshes::Mesh& mesh, std::size_t floats_per_vertex, std::size_t capacity_rows);

  // Collects the corners of the hits of vertices [first, last) of a list of `count` whose
  // hits are `hits` (one HitBlock per kChunk of them), taking vertices from `first` on while
  // their corners fit the cache (always at least one vertex); returns last.
  std::size_t collect(const std::vector<HitBlock>& hits, std::size_t first, std::size_t count);
  // Makes every collected corner's row of the previous pass resident: reads the missing ones
  // with read() (one call per run of consecutive rows, in parallel; row_of: vertex q's row of
  // the pass, null for row q) into slots freed by rows the group does not need.
  void load(const PassReader& read, const std::uint32_t* row_of);

  // rows() + slot_of()[q] * floats_per_vertex is vertex q's row, for every collected q.
  const float* rows() const { return rows_.data(); }
  const std::uint32_t* slot_of() const { return slot_of_.data(); }
  // Forgets every row held: the next load() reads a new pass.
  void clear();
  // Rows read since construction.
  std::uint64_t rows_read() const { return rows_read_; }

 private:
  void grow(std::size_t capacity_rows);

  const meshes::Mesh& mesh_;
  std::size_t per_vertex_, capacity_ = 0;
  std::vector<std::uint32_t> slot_of_;  // vertex -> its slot, or kNone
  std::vector<std::uint32_t> holder_;   // slot -> the vertex held there, or kNone
  std::vector<std::uint32_t> used_;     // slot -> the last collect() call that read it
  std::vector<std::uint32_t> stamp_;    // vertex -> the collect() call that last took it
  std::uint32_t generation_ = 0;
  std::vector<std::uint32_t> group_;  // the vertices collected
  std::vector<float, HugePageAllocator<float>> rows_;
  std::uint64_t rows_read_ = 0;
};

}  // namespace prt::detail
