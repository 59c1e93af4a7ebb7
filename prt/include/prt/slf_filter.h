// prt/slf_filter.h: the surface light field's texels smoothed over the surface, a
// cross-bilateral filter over the atlas (Tomasi & Manduchi 1998; as lightmap bakers denoise
// their texels): each row becomes a weighted mean of the rows of its neighbours within
// `radius` texels that sample the same chart, with a Gaussian weight in texel distance and
// none for a neighbour whose normal turns more than `max_normal_degrees` away. It trades the
// bake's Monte Carlo noise, independent from texel to texel, for a blur of the surface's own
// variation over a few texels (docs/BENCHMARKS.md, "Texel filter").
#pragma once

#include "meshes/atlas.h"
#include "meshes/mesh.h"
#include "prt/slf_bake.h"

namespace prt {

struct SlfFilterOptions {
  // Texels; 0 leaves the matrix as it is. In [0, 8]. 1 was chosen on the icosphere under
  // the city probe and held on the bunny (docs/BENCHMARKS.md, "Texel filter").
  int radius = 1;
  float max_normal_degrees = 20.f;  // in (0, 180]
  // Throws std::invalid_argument naming the option as its CLI flag.
  void validate() const;
};

// Filters the whole matrix (rows of every owned texel, slf_rows order) in place; memory
// beyond the matrix is radius + 2 atlas rows of it. `atlas` must be the one the matrix was
// baked on (make_atlas(mesh, ...)); std::invalid_argument when the shapes say otherwise.
void filter_slf_texels(SlfMatrix& matrix, const meshes::Mesh& mesh, const meshes::Atlas& atlas,
                       const SlfFilterOptions& options);

}  // namespace prt
