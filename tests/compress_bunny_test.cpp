// CPCA on a real bake of the Stanford bunny (glmark2-data), at reduced order and sample count
// so it runs in seconds: geometry coherence and the overdraw-aware reassignment must lower
// the number of triangles that span several clusters, at a comparable error.
#include "cpca/compress.h"
#include "meshes/load.h"
#include "prt/bake.h"

#include <gtest/gtest.h>

#include <filesystem>

namespace {

constexpr const char* kBunny = "/usr/share/glmark2/models/bunny.obj";

class BunnyCompression : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!std::filesystem::exists(kBunny)) return;
    mesh_ = new meshes::Mesh(meshes::load_mesh(kBunny));
    prt::BakeOptions bake;
    bake.order = 4;  // 256 numbers per vertex
    bake.samples = 128;
    bake.bounces = 0;
    transfer_ = new prt::TransferSet(prt::bake(*mesh_, bake));
    geometry_ = new cpca::Geometry;
    geometry_->positions = mesh_->positions;
    for (const auto& t : mesh_->triangles) geometry_->triangles.push_back({t[0], t[1], t[2]});
  }
  static void TearDownTestSuite() {
    delete mesh_;
    delete transfer_;
    delete geometry_;
  }
  void SetUp() override {
    if (!mesh_) GTEST_SKIP() << kBunny << " missing: install glmark2-data (scripts/setup.sh)";
  }
  static cpca::CompressReport run(const cpca::CompressOptions& o) {
    const Eigen::Map<const cpca::DataMatrix> data(transfer_->data.data(),
                                                  Eigen::Index(transfer_->vertex_count),
                                                  Eigen::Index(transfer_->floats_per_vertex()));
    cpca::CompressReport report;
    cpca::compress(data, o, geometry_, &report);
    return report;
  }
  // The plain LBG run both tests compare against, computed once.
  static const cpca::CompressReport& plain() {
    static const cpca::CompressReport report = run(options());
    return report;
  }
  static cpca::CompressOptions options() {
    cpca::CompressOptions o;
    o.clusters = 64;
    o.components = 4;
    return o;
  }
  static inline meshes::Mesh* mesh_ = nullptr;
  static inline prt::TransferSet* transfer_ = nullptr;
  static inline cpca::Geometry* geometry_ = nullptr;
};

TEST_F(BunnyCompression, GeometryCoherenceLowersMultiClusterTriangles) {
  const cpca::CompressReport& plain = BunnyCompression::plain();
  cpca::CompressOptions o = options();
  o.alpha = 2.0;
  const cpca::CompressReport coherent = run(o);
  EXPECT_LT(coherent.span.multi(), plain.span.multi());
  EXPECT_LT(coherent.error.average_squared_error, 1.1 * plain.error.average_squared_error);
  std::printf("multi-cluster triangles: plain %llu, alpha 2: %llu; Average SE %.4g vs %.4g\n",
              (unsigned long long)plain.span.multi(), (unsigned long long)coherent.span.multi(),
              plain.error.average_squared_error, coherent.error.average_squared_error);
}

TEST_F(BunnyCompression, OverdrawReductionLowersMultiClusterTriangles) {
  const cpca::CompressReport& plain = BunnyCompression::plain();
  cpca::CompressOptions o = options();
  o.overdraw_reduction = true;
  const cpca::CompressReport reduced = run(o);
  EXPECT_GT(reduced.overdraw.moves, 0u);
  EXPECT_LT(reduced.span.multi(), plain.span.multi() * 0.97);
  EXPECT_LT(reduced.error.average_squared_error, 1.1 * plain.error.average_squared_error);
  std::printf("multi-cluster triangles: plain %llu, reduced %llu; Average SE %.4g vs %.4g\n",
              (unsigned long long)plain.span.multi(), (unsigned long long)reduced.span.multi(),
              plain.error.average_squared_error, reduced.error.average_squared_error);
}

}  // namespace
