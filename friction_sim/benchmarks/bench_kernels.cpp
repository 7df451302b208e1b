// Google Benchmark of the explicit step, the hot loop: ns per node-step of the 2D lattice and per
// block-step of the 1D chain, over system sizes. Run: .build/devel/lib/friction_sim/bench_kernels
#include <benchmark/benchmark.h>

#include <cmath>

#include "friction_sim/integrator.h"
#include "friction_sim/scene_io.h"
#include "friction_sim/simulation.h"

namespace friction {
namespace {

/// The default slider's material and loads at a given lattice resolution (same physical slider when
/// nz − 1 = (nx − 1)·H/L), stage holding, so that every step is a plain explicit step.
Scene latticeScene(int nx, int nz) {
  Scene scene;
  scene.lattice.nodes_x = nx;
  scene.lattice.nodes_z = nz;
  scene.geometry.length = 0.0025 * (nx - 1);
  scene.geometry.height = 0.0025 * (nz - 1);
  scene.stage.program = {StageSegment{StageMode::Hold, 0.0}};
  scene.stop.time = 1e9;
  return scene;
}

void latticeStep(benchmark::State& state, SpringForm form) {
  Scene scene = latticeScene(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  scene.lattice.spring_form = form;
  Simulation simulation(scene);
  const double nodes = static_cast<double>(state.range(0) * state.range(1));
  for (auto _ : state) simulation.step();
  state.counters["ns_per_node_step"] =
      benchmark::Counter(nodes * state.iterations() * 1e-9, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["nodes"] = nodes;
}
BENCHMARK_CAPTURE(latticeStep, geometric, SpringForm::Geometric)->Args({57, 31})->Args({32, 32})->Args({113, 61})->Args({225, 121})->Args({449, 241})
    ->Args({1001, 1001})->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(latticeStep, linearised, SpringForm::Linearised)->Args({57, 31})->Args({449, 241})
    ->Unit(benchmark::kMicrosecond);

void chainStep(benchmark::State& state) {
  Scene scene;
  scene.model = ModelKind::Chain1D;
  scene.chain.blocks = static_cast<int>(state.range(0));
  scene.stage.program = {StageSegment{StageMode::Hold, 0.0}};
  scene.stop.time = 1e9;
  const double stability_limit = sceneStabilityLimit(scene);
  scene.integrator.time_step = 0.5 * stability_limit;
  Simulation simulation(scene, stability_limit);
  for (auto _ : state) simulation.step();
  state.counters["ns_per_block_step"] = benchmark::Counter(
      static_cast<double>(state.range(0)) * state.iterations() * 1e-9, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(chainStep)->Arg(57)->Arg(1000)->Arg(100000)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace friction

BENCHMARK_MAIN();
