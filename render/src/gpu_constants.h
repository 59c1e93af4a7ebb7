// render/src/gpu_constants.h (private): the per-frame lighting constants of render/shading.h
// computed on the GPU. The clusters' transfer rows are uploaded once; each frame uploads only
// the rotated lighting (n x 3 floats) and one compute dispatch writes every constant, in the
// slot layout the shaders read, straight into the path's constant buffer.
//
// Why: on the CPU the products stream every cluster's rows from memory each frame (36 MB for
// the thesis configuration's 256 clusters x 8 PCs at order 6) and upload ~1 MB of results;
// on an NVIDIA H200 with 16 cores that was 2.2 ms of a 5.2 ms frame (docs/BENCHMARKS.md,
// "On a GPU"). On a GPU the same products are a few microseconds of memory traffic.
#pragma once

#include "gl_program.h"
#include "render/shading.h"

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace render {

class GpuConstants {
 public:
  // `slot_of` as ShadingConstants::compute takes it; `total_floats` is the size of the
  // constant buffer, every float of which each frame writes (gaps as zero).
  // Throws GlError when the rows exceed the context's shader storage block size.
  GpuConstants(const ShadingConstants& constants, const std::vector<std::uint32_t>& slot_of,
               std::size_t total_floats);
  ~GpuConstants();
  GpuConstants(const GpuConstants&) = delete;
  GpuConstants& operator=(const GpuConstants&) = delete;

  // The bytes the rows take on the GPU: what a caller checks against the context's
  // GlInfo::max_ssbo_size before choosing this.
  static std::size_t row_bytes(const ShadingConstants& constants);

  // Writes every frame constant into `buffer` (total_floats floats) and orders the writes
  // before later uniform and storage reads. `lighting` is n x 3.
  void compute(const Eigen::Ref<const Eigen::MatrixXd>& lighting, GLuint buffer);

 private:
  GlProgram program_;
  GLuint rows_ = 0, sources_ = 0, lighting_ = 0;
  int n_ = 0;
  std::uint32_t count_ = 0;
  std::vector<float> host_lighting_;
};

}  // namespace render
