// render/false_colour.h: flat false-colour pictures of a mesh (for prtr overdraw): the overdraw
// picture
// (each triangle coloured by how many passes draw it: 1, 2, 3+, with a legend drawn into the
// image) and the cluster picture (one colour per cluster), plus the small 2D drawing kit the
// legend uses.
//
// Conventions:
//  - A Picture holds display colours: 8-bit sRGB-encoded RGB, row 0 at the top. Unlike
//    render::Image (linear radiance, tone-mapped on output) nothing is tone mapped: a palette
//    colour is written to the PNG byte for byte, which is what a legend needs.
//  - Rasterisation is on the CPU with the same camera as the GL renderer (render/camera.h):
//    pixel (x, y) is covered by a triangle when its centre (x + 0.5, y + 0.5) lies inside the
//    projected triangle (edges inclusive); the nearest triangle (NDC depth) wins, ties to the
//    lower triangle index. No culling, so open meshes show both sides. Triangles with a vertex
//    behind the near plane are skipped (the framing cameras keep the mesh in front).
//  - Shading: when `shade` is on, a pixel's colour is scaled by 0.35 + 0.65 |cos| between the
//    face normal and the direction to the eye, so the shape stays readable; off, the picture
//    holds the exact palette colours (tests use that).
#pragma once

#include "meshes/mesh.h"
#include "render/camera.h"

#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace render {

using Colour8 = std::array<std::uint8_t, 3>;

struct Picture {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;  // width * height * 3, row-major from the top row

  Picture() = default;
  Picture(int w, int h, const Colour8& fill);
  Colour8 at(int x, int y) const;
  void set(int x, int y, const Colour8& c);
};

// --- Rasterisation ---------------------------------------------------------------------------

// Per pixel: the visible triangle (-1: background), the screen-space barycentric coordinates
// of the pixel centre in it, and the shading factor described above.
struct TriangleIdBuffer {
  int width = 0, height = 0;
  std::vector<std::int32_t> triangle;
  std::vector<std::array<float, 3>> barycentric;
  std::vector<float> shade;
};

// Throws std::invalid_argument for an invalid camera (Camera::validate).
TriangleIdBuffer rasterize_triangle_ids(const meshes::Mesh& mesh, const Camera& camera);

// --- Palettes --------------------------------------------------------------------------------

inline constexpr Colour8 kPictureBackground{255, 255, 255};
// Draw counts 1, 2, 3+ (index count - 1, clamped): blue, amber, red; distinct in grey too.
inline constexpr std::array<Colour8, 3> kPassCountPalette{
    {{{70, 110, 200}}, {{240, 180, 40}}, {{210, 40, 40}}}};

// A saturated colour per cluster id: hues by the golden ratio so that consecutive ids differ
// strongly, with value alternating in three steps. Deterministic.
Colour8 cluster_colour(std::uint32_t cluster);

// --- The two pictures --------------------------------------------------------------------------

struct PictureOptions {
  bool shade = true;
  bool legend = true;  // overdraw picture only
  Colour8 background = kPictureBackground;
};

// Each triangle in kPassCountPalette[min(count, 3) - 1]; `pass_counts` has one entry (1..3)
// per triangle (cpca::triangle_pass_counts). A legend (swatches "1 pass", "2 passes",
// "3 passes", with the share of triangles) sits in the top-left corner. Throws
// std::invalid_argument when the count of entries differs from the triangle count or an entry
// is 0.
Picture overdraw_picture(const meshes::Mesh& mesh, const Camera& camera,
                         std::span<const std::uint8_t> pass_counts,
                         const PictureOptions& options = {});

// Each pixel in the colour of the cluster of the visible triangle's vertex nearest to it (the
// largest barycentric coordinate), so cluster borders run through triangles the way the
// per-vertex clustering splits them. `cluster_of` has one entry per vertex.
Picture cluster_picture(const meshes::Mesh& mesh, const Camera& camera,
                        std::span<const std::uint32_t> cluster_of,
                        const PictureOptions& options = {});

// Where overdraw_picture puts the swatch of draw count c (1..3): the rectangle
// [x0, x1) x [y0, y1) in pixels, for a picture of the given height.
struct Rect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};
Rect legend_swatch(int picture_height, int count);

// --- Drawing kit (the legends) ------------------------------------------------------------

void fill_rect(Picture& picture, Rect rect, const Colour8& colour);  // clipped to the picture
// Text with its baseline starting at (x, y), `size` pixels high, in the first of the fonts
// OpenImageIO finds (DejaVu Sans on Debian). Returns false, drawing nothing, when no font is
// available: text is decoration, the pictures stay valid without it.
bool draw_text(Picture& picture, int x, int y, const std::string& text, int size,
               const Colour8& colour);

// 8-bit sRGB PNG, byte for byte, written atomically (temporary file, then rename). Throws
// render::ImageError naming the path when writing fails.
void write_picture_png(const std::filesystem::path& path, const Picture& picture);

}  // namespace render
