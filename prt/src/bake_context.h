// prt/src/bake_context.h (private to prt): what every part of the baker shares: the shared
// direction set and its SH values (Setup), the inputs and ray scene both passes read
// (BakeContext), and the progress callback's serialiser. The parts: bake_origins.cpp (where
// rays start), bake_shadow.cpp (the shadow pass), bake_bounce.cpp (the interreflection
// passes), bake.cpp (the engine that runs them). The formulation is in prt/bake.h.
#pragma once

#include "bake_origins.h"
#include "prt/bake.h"
#include "prt/ray_scene.h"

#include <Eigen/Core>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <mutex>
#include <vector>

namespace prt::detail {

using Clock = std::chrono::steady_clock;
using MatF = Eigen::MatrixXf;  // column-major
using RowMatF = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// What every vertex shares: the local direction set and its SH values.
struct Setup {
  int order = 0, n = 0, samples = 0;
  float weight = 0;
  Eigen::Matrix3Xf directions;        // local frame, z = normal
  MatF y;                             // n x S, column k = y(direction k)
  MatF gram;                          // w Y Y^T: the unoccluded shadow transfer
  Eigen::VectorXf cosine_projection;  // w sum_k z_k y_k: the unoccluded diffuse transfer
  std::vector<MatF> brdf;             // per channel, n x n (glossy only)
  Eigen::Vector3f rho_over_pi;        // diffuse albedo / pi per channel
};

inline Eigen::Matrix3f frame_of(const meshes::Mesh& mesh, std::size_t p) {
  Eigen::Matrix3f f;
  f.col(0) = mesh.tangents[p];
  f.col(1) = mesh.bitangents[p];
  f.col(2) = mesh.normals[p];
  return f;
}

// Calls the user's progress callback from workers, serialised and rate-limited.
class ProgressReporter {
 public:
  ProgressReporter(const std::function<void(const BakeProgress&)>& fn, int passes,
                   std::uint64_t total)
      : fn_(fn), passes_(passes), total_(total) {}
  void start_pass(int pass) {
    pass_ = pass;
    done_ = 0;
    report(true);
  }
  void add(std::uint64_t vertices) {
    done_ += vertices;
    report(false);
  }
  void finish_pass() { report(true); }

 private:
  void report(bool force) {
    if (!fn_) return;
    std::unique_lock<std::mutex> lock(mutex_, std::defer_lock);
    if (force) {
      lock.lock();
    } else if (!lock.try_lock()) {
      return;
    }
    const auto now = Clock::now();
    if (!force && now - last_ < std::chrono::milliseconds(50)) return;
    last_ = now;
    fn_(BakeProgress{pass_, passes_, std::min<std::uint64_t>(done_.load(), total_), total_});
  }
  const std::function<void(const BakeProgress&)>& fn_;
  int passes_;
  std::uint64_t total_;
  int pass_ = 0;
  std::atomic<std::uint64_t> done_{0};
  std::mutex mutex_;
  Clock::time_point last_{};
};

// What both passes read: the inputs, the shared direction set and the ray scene.
struct BakeContext {
  BakeContext(const meshes::Mesh& m, const BakeOptions& o, const Setup& s, const RayScene* r)
      : mesh(m), options(o), setup(s), scene(r) {}
  const meshes::Mesh& mesh;
  const BakeOptions& options;
  const Setup& setup;
  const RayScene* scene;  // null once tracing ends (BakeEngine::end_tracing)
  int channels = 0;
  bool glossy = false;
  float offset = 0;  // ray-origin offset in world units
  OriginFaces faces;
  std::uint64_t vertex_count = 0;
  std::size_t per_vertex = 0, per_channel = 0;  // floats of the output layout
};

}  // namespace prt::detail
