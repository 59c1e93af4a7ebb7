// prt/src/bake_engine.h (private to prt): the bake's passes over a range of vertices, so
// that the whole-mesh bake (bake.cpp) and the streaming bake (bake_stream.cpp) run the same
// per-vertex code and produce the same bits. The formulation is in prt/bake.h.
#pragma once

#include "prt/bake.h"

#include <cstdint>
#include <memory>
#include <vector>

namespace prt::detail {

inline constexpr std::uint64_t kChunk = 64;  // vertices per scheduling unit (and hit block)

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

  // Shadow pass of vertices [begin, end) into dst ((end - begin) x floats_per_vertex). With
  // bounces, `hits` gets the front hits of each kChunk vertices from begin.
  void shadow(std::uint64_t begin, std::uint64_t end, float* dst, std::vector<HitBlock>* hits);
  // One bounce of vertices [begin, end) into dst, from the whole previous pass `previous`
  // (vertex_count x floats_per_vertex) and the range's hits as shadow() gave them.
  void bounce(std::uint64_t begin, std::uint64_t end, const std::vector<HitBlock>& hits,
              const float* previous, float* dst);
  // Fills the remaining stats (ray counts, flagged vertices, total time).
  void finish();

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace prt::detail
