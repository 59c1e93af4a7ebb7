#include "corner_gather.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstring>
#include <limits>
#include <new>

#include <sys/mman.h>

namespace prt::detail {

namespace {
// n values rounded up to whole 2 MB huge pages.
template <class T>
std::size_t huge_page_bytes(std::size_t n) {
  constexpr std::size_t huge = std::size_t(2) << 20;
  return (n * sizeof(T) + huge - 1) / huge * huge;
}
}  // namespace

template <class T>
T* HugePageAllocator<T>::allocate(std::size_t n) {
  const std::size_t bytes = huge_page_bytes<T>(n);
  void* p = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (p == MAP_FAILED) throw std::bad_alloc();
  ::madvise(p, bytes, MADV_HUGEPAGE);
  return static_cast<T*>(p);
}
template <class T>
void HugePageAllocator<T>::deallocate(T* p, std::size_t n) {
  ::munmap(p, huge_page_bytes<T>(n));
}
template struct HugePageAllocator<float>;

namespace {
constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
constexpr std::size_t kMaxRun = 64;  // rows per read

}  // namespace

CornerGather::CornerGather(const meshes::Mesh& mesh, std::size_t floats_per_vertex,
                           std::size_t capacity_rows)
    : mesh_(mesh),
      per_vertex_(floats_per_vertex),
      slot_of_(mesh.vertex_count(), kNone),
      stamp_(mesh.vertex_count(), 0) {
  // Never more rows than the pass has.
  grow(std::clamp<std::size_t>(capacity_rows, 1, std::max<std::size_t>(1, mesh.vertex_count())));
}

void CornerGather::grow(std::size_t capacity_rows) {
  if (capacity_rows <= capacity_) return;
  // Only a vertex whose corners outnumber the cache gets here (a tiny cache): start afresh rather
  // than hold the old rows and their copy at once.
  clear();
  rows_ = {};
  capacity_ = capacity_rows;
  holder_.assign(capacity_, kNone);
  used_.assign(capacity_, 0);
  rows_.resize(capacity_ * per_vertex_);
}

void CornerGather::clear() {
  for (std::uint32_t& q : holder_) {
    if (q != kNone) slot_of_[q] = kNone;
    q = kNone;
  }
}

std::size_t CornerGather::collect(const std::vector<HitBlock>& hits, std::size_t first,
                                  std::size_t count) {
  if (++generation_ == 0) {  // wrapped: no stamp may look current
    std::fill(stamp_.begin(), stamp_.end(), 0);
    generation_ = 1;
  }
  group_.clear();
  std::size_t last = first;
  while (last < count) {
    const HitBlock& block = hits[last / kChunk];
    const std::size_t i = last % kChunk, before = group_.size();
    for (std::uint32_t h = block.offsets[i]; h < block.offsets[i + 1]; ++h) {
      for (std::uint32_t q : mesh_.triangles[block.records[h].triangle]) {
        if (stamp_[q] != generation_) {
          stamp_[q] = generation_;
          group_.push_back(q);
        }
      }
    }
    if (group_.size() > capacity_ && last > first) {
      // Over capacity: this vertex waits for the next group, unmarked.
      for (std::size_t k = before; k < group_.size(); ++k) stamp_[group_[k]] = 0;
      group_.resize(before);
      break;
    }
    ++last;
  }
  return last;
}

void CornerGather::load(const PassReader& read, const std::uint32_t* row_of) {
  auto row = [row_of](std::uint32_t q) -> std::uint64_t { return row_of ? row_of[q] : q; };
  grow(group_.size());  // a single vertex larger than the cache
  std::vector<std::uint32_t> missing;
  for (std::uint32_t q : group_) {
    if (slot_of_[q] == kNone) missing.push_back(q);
  }
  // Free slots for the missing rows: empty ones first, then those of the rows this group does
  // not read, least recently read first (the groups before saw nearly the same surfaces).
  std::vector<std::uint32_t> free_slots, evictable;
  for (std::size_t s = 0; s < capacity_; ++s) {
    const std::uint32_t q = holder_[s];
    if (q == kNone) {
      free_slots.push_back(std::uint32_t(s));
    } else if (stamp_[q] == generation_) {
      used_[s] = generation_;
    } else {
      evictable.push_back(std::uint32_t(s));
    }
  }
  if (free_slots.size() < missing.size()) {
    const std::size_t need = missing.size() - free_slots.size();
    std::nth_element(evictable.begin(), evictable.begin() + std::ptrdiff_t(need - 1),
                     evictable.end(),
                     [&](std::uint32_t a, std::uint32_t b) { return used_[a] < used_[b]; });
    for (std::size_t i = 0; i < need; ++i) {
      slot_of_[holder_[evictable[i]]] = kNone;
      holder_[evictable[i]] = kNone;
      free_slots.push_back(evictable[i]);
    }
    std::sort(free_slots.begin(), free_slots.end());
  }
  std::sort(missing.begin(), missing.end(),
            [&](std::uint32_t a, std::uint32_t b) { return row(a) < row(b); });
  for (std::size_t i = 0; i < missing.size(); ++i) {
    slot_of_[missing[i]] = free_slots[i];
    holder_[free_slots[i]] = missing[i];
    used_[free_slots[i]] = generation_;
  }
  // Runs of consecutive rows: the pass is in spatial order, so a group's missing corners come
  // in runs, each read at once, straight into its slots where they are consecutive too, else
  // through a small staging buffer (runs are cut at kMaxRun rows to keep it in cache).
  std::vector<std::size_t> runs;  // start index into `missing`
  for (std::size_t i = 0; i < missing.size(); ++i) {
    if (i == 0 || row(missing[i]) != row(missing[i - 1]) + 1 || i - runs.back() == kMaxRun)
      runs.push_back(i);
  }
  runs.push_back(missing.size());
  tbb::enumerable_thread_specific<std::vector<float>> staging;
  tbb::parallel_for(std::size_t(0), runs.size() - 1, [&](std::size_t r) {
    const std::size_t begin = runs[r], count = runs[r + 1] - begin;
    float* first_slot = rows_.data() + std::size_t(slot_of_[missing[begin]]) * per_vertex_;
    if (slot_of_[missing[begin + count - 1]] - slot_of_[missing[begin]] == count - 1) {
      read(row(missing[begin]), count, first_slot);  // free slots ascend with the rows
      return;
    }
    std::vector<float>& buffer = staging.local();
    buffer.resize(kMaxRun * per_vertex_);
    read(row(missing[begin]), count, buffer.data());
    for (std::size_t i = 0; i < count; ++i) {
      std::memcpy(rows_.data() + std::size_t(slot_of_[missing[begin + i]]) * per_vertex_,
                  buffer.data() + i * per_vertex_, per_vertex_ * sizeof(float));
    }
  });
  rows_read_ += missing.size();
}

}  // namespace prt::detail
