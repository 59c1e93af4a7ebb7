// Micro-benchmarks of the SH toolkit (prt/sh.h). Figures are per item so runs on
// different machines compare; quote them as ratios against a baseline from the same run.
#include "probes/load.h"
#include "probes/procedural.h"
#include "prt/projection.h"
#include "prt/sampling.h"
#include "prt/sh.h"
#include "prt/sh_rotation.h"

#include <benchmark/benchmark.h>

#include <filesystem>

namespace {

Eigen::Matrix3Xf random_directions(int count) {
  const prt::DirectionSet set = prt::sphere_directions(count, 1);
  return set.directions.cast<float>();
}

void BM_ShEvalSingle(benchmark::State& state) {
  const int order = static_cast<int>(state.range(0));
  const Eigen::Matrix3Xf dirs = random_directions(1024);
  float out[prt::kMaxOrder * prt::kMaxOrder];
  Eigen::Index k = 0;
  for (auto _ : state) {
    prt::sh_eval(order, dirs(0, k), dirs(1, k), dirs(2, k), out);
    benchmark::DoNotOptimize(out);
    k = (k + 1) & 1023;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ShEvalSingle)->Arg(6)->Arg(10);

void BM_ShEvalBatch(benchmark::State& state) {
  const int order = static_cast<int>(state.range(0));
  const Eigen::Matrix3Xf dirs = random_directions(1024);
  prt::ShBatchF out;
  for (auto _ : state) {
    prt::sh_eval_batch(order, dirs, out);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * dirs.cols());
}
BENCHMARK(BM_ShEvalBatch)->Arg(6)->Arg(10);

// Baseline for the SH figures: one float3 normalisation per direction.
void BM_NormaliseBaseline(benchmark::State& state) {
  Eigen::Matrix3Xf dirs = random_directions(1024);
  for (auto _ : state) {
    dirs.colwise().normalize();
    benchmark::DoNotOptimize(dirs.data());
  }
  state.SetItemsProcessed(state.iterations() * dirs.cols());
}
BENCHMARK(BM_NormaliseBaseline);

void BM_ShRotateRgbLighting(benchmark::State& state) {
  const int order = static_cast<int>(state.range(0));
  prt::Pcg32 rng(3);
  const Eigen::Matrix3d r = prt::random_rotation(rng);
  const Eigen::MatrixXd lighting = Eigen::MatrixXd::Random(prt::sh_count(order), 3);
  Eigen::MatrixXd out(lighting.rows(), 3);
  for (auto _ : state) {
    const prt::ShRotation d(order, r);  // build D(R) and apply: what a frame pays
    d.apply(lighting, out);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ShRotateRgbLighting)->Arg(6)->Arg(10)->Unit(benchmark::kMicrosecond);

void BM_ProjectProbe(benchmark::State& state) {
  const std::filesystem::path forest = "/usr/share/blender/datafiles/studiolights/world/forest.exr";
  const probes::Probe probe = std::filesystem::exists(forest)
                                  ? probes::load_probe(forest)
                                  : probes::make_constant(1024, 512, probes::Rgb::Ones());
  state.SetLabel(std::filesystem::exists(forest) ? "forest 1024x512" : "constant 1024x512");
  for (auto _ : state) {
    const prt::ShLighting l = prt::project(probe, static_cast<int>(state.range(0)));
    benchmark::DoNotOptimize(l.data());
  }
}
BENCHMARK(BM_ProjectProbe)->Arg(6)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
