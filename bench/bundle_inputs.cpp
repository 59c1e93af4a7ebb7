// bundle_inputs MESH OUT_DIR [SAMPLES] [ROUNDS] [FROM]: the GPU benchmark's inputs, made where it
// runs (scripts/run_gpu.sh), because compressed sets of the subdivided bunnies are larger
// than the bundle may be (the x2 .prtc alone is 32 MB of floats, which do not compress).
// For each round count FROM..ROUNDS (default 0..2): MESH after that many rounds of Loop
// subdivision, written as OUT_DIR/bunny_xN.ply, baked from that PLY as `prtr bake` would
// (glossy order 6, SAMPLES hemisphere samples, default 64, no bounces) and compressed as
// `prtr compress` would (256 clusters x 8 PCs, LBG + power PCA) into OUT_DIR/bunny_xN.prtc.
// Render timing depends on the mesh and the clustering, not on how finely the transfer was
// sampled.
#include "cpca/compressed_file.h"
#include "meshes/load.h"
#include "meshes/subdivide.h"
#include "meshes/write_ply.h"
#include "pipeline/pipeline.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: bundle_inputs MESH OUT_DIR [SAMPLES] [ROUNDS] [FROM]\n");
    return 2;
  }
  const std::filesystem::path mesh_path = argv[1], out = argv[2];
  const int samples = argc > 3 ? std::atoi(argv[3]) : 64;
  const int rounds = argc > 4 ? std::atoi(argv[4]) : 2;
  const int from = argc > 5 ? std::atoi(argv[5]) : 0;
  if (samples < 1 || rounds < 0 || rounds > 4 || from < 0 || from > rounds) {
    std::fprintf(stderr, "bundle_inputs: SAMPLES >= 1, ROUNDS in 0..4, FROM in 0..ROUNDS\n");
    return 2;
  }
  try {
    std::filesystem::create_directories(out);
    const meshes::Mesh source = meshes::load_mesh(mesh_path);
    for (int n = from; n <= rounds; ++n) {
      const auto t0 = std::chrono::steady_clock::now();
      const std::string name = "bunny_x" + std::to_string(n);
      const std::filesystem::path ply = out / (name + ".ply");
      meshes::write_ply(ply, n ? meshes::loop_subdivide(source, n) : source);
      // Loaded back, as prtr bake loads the PLY: the same welding, normals and frames.
      const meshes::Mesh mesh = meshes::load_mesh(ply);
      prt::BakeOptions bake;
      bake.samples = samples;
      bake.bounces = 0;
      const prt::TransferSet transfer = pipeline::run_bake(mesh, ply.string(), bake, {});
      cpca::CompressOptions compress;
      compress.clusters = 256;
      compress.components = 8;
      cpca::write_compressed(out / (name + ".prtc"),
                             pipeline::run_compress(transfer, mesh, ply.string(), compress, {}));
      std::printf("bundle_inputs: %s, %zu vertices, %.1f s\n", name.c_str(), mesh.vertex_count(),
                  std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      std::fflush(stdout);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bundle_inputs: %s\n", e.what());
    return 1;
  }
  return 0;
}
