// Google Benchmark of the explicit step, the hot loop: ns per node-step of the 2D lattice and per
// block-step of the 1D chain, over system sizes, and the memory floor of a lattice step (stateStream,
// and leapfrogStream for a scheme without stored accelerations), the divider's floor under the 2D
// step (bondDividerFloor), a static solve through the direct factor (staticSolve), and the start-up's
// static work: the stiffness matrix's assembly (stiffnessAssembly) and the whole solver (staticFactor).
// Three cases separate causes: the 1001 × 61 lattice has the rows of the 10⁶-node one with a state that
// fits the last-level cache (row width against memory traffic); 32 × 32 and 33 × 31 have 10³ nodes
// each, but 32 × 32's runs of 31 bonds leave 7 over from whole 8-wide vectors (the other lattices' runs
// are whole vectors but for one bond); and the 2-block chain's step is almost all the step's fixed cost.
// Run: .build/devel/lib/friction_sim/bench_kernels
#include <benchmark/benchmark.h>

#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "friction_sim/model/lattice_2d.h"
#include "friction_sim/run/simulation.h"
#include "friction_sim/scene/scene_io.h"
#include "friction_sim/solvers/integrator.h"
#include "friction_sim/solvers/static_solver.h"
#include "naive_lattice.h"
#include "process_memory.h"

namespace friction {
namespace {

/// The default slider's material and loads at a given lattice resolution (same physical slider when
/// nz − 1 = (nx − 1)·H/L), stage holding and no fast-forward, so that every step is a plain explicit step.
Scene latticeScene(int nx, int nz) {
  Scene scene;
  scene.lattice.nodes_x = nx;
  scene.lattice.nodes_z = nz;
  scene.geometry.length = 0.0025 * (nx - 1);
  scene.geometry.height = 0.0025 * (nz - 1);
  scene.stage.program = {StageSegment{StageMode::Hold, 0.0}};
  scene.integrator.fast_forward = false;
  scene.stop.time = 1e9;
  return scene;
}

/// ns per node-step (or block-step) of a case that took `node_steps` node-steps (or block-steps) in all.
benchmark::Counter nsPerNodeStep(double node_steps) {
  return benchmark::Counter(node_steps * 1e-9, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

/// Google Benchmark calls a case once per trial of its iteration count, and building a 10⁶-node
/// simulation (loading solve, stability limit) takes about half a minute, so a case builds its
/// simulation once and steps it on. Its state is a held equilibrium, so every step costs the same.
Simulation& reusedSimulation(const std::string& key, const std::function<std::unique_ptr<Simulation>()>& build) {
  static std::string built_for;
  static std::unique_ptr<Simulation> simulation;
  if (key != built_for || !simulation) {
    simulation.reset();  // before building the next, so that two large lattices never coexist
    simulation = build();
    built_for = key;
  }
  return *simulation;
}

/// Advances `simulation` as the offline runner does between its samples, several plain steps per advance
/// where it may (here every step is plain), and sets the counter `name` to the ns per node-step (or
/// block-step) of `nodes` nodes.
void advanceAndCount(benchmark::State& state, Simulation& simulation, double nodes, const char* name) {
  const long long steps_before = simulation.steps();
  for (auto _ : state) simulation.advance(simulation.scene().stop.time, std::numeric_limits<double>::infinity());
  state.counters[name] = nsPerNodeStep(nodes * static_cast<double>(simulation.steps() - steps_before));
}

/// The lattice of the case's (nx, nz) with springs of `form`, built once for its consecutive cases.
Simulation& reusedLattice(const benchmark::State& state, SpringForm form) {
  const std::string key = "lattice/" + std::to_string(static_cast<int>(form)) + "/" + std::to_string(state.range(0)) +
                          "/" + std::to_string(state.range(1));
  return reusedSimulation(key, [&] {
    Scene scene = latticeScene(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
    scene.lattice.spring_form = form;
    return std::make_unique<Simulation>(scene);
  });
}

void latticeStep(benchmark::State& state, SpringForm form) {
  const double nodes = static_cast<double>(state.range(0) * state.range(1));
  advanceAndCount(state, reusedLattice(state, form), nodes, "ns_per_node_step");
  state.counters["nodes"] = nodes;
}
// The 10⁶-node lattice last, so that the next case reuses it.
BENCHMARK_CAPTURE(latticeStep, geometric, SpringForm::Geometric)
    ->Args({57, 31})
    ->Args({32, 32})
    ->Args({33, 31})
    ->Args({113, 61})
    ->Args({225, 121})
    ->Args({449, 241})
    ->Args({1001, 61})
    ->Args({1001, 1001})
    ->Unit(benchmark::kMicrosecond);

/// The same lattice with each step's sweep split into blocks of rows on state.range(2) threads (one step
/// per sweep then): against latticeStep (one thread) at the same size, what the threads gain.
void latticeStepOnThreads(benchmark::State& state) {
  Simulation& simulation = reusedLattice(state, SpringForm::Geometric);
  simulation.setThreads(static_cast<int>(state.range(2)));
  advanceAndCount(state, simulation, static_cast<double>(state.range(0) * state.range(1)), "ns_per_node_step");
  simulation.setThreads(1);
}
BENCHMARK(latticeStepOnThreads)
    ->Args({57, 31, 2})
    ->Args({113, 61, 2})
    ->Args({225, 121, 2})
    ->Args({449, 241, 2})
    ->Args({1001, 1001, 2})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

/// The same lattice stepped one step per advance, each step a sweep of its own: what sweeping several
/// steps at once saves.
void latticeStepOneAtATime(benchmark::State& state) {
  Simulation& simulation = reusedLattice(state, SpringForm::Geometric);
  for (auto _ : state) simulation.step();
  state.counters["ns_per_node_step"] =
      nsPerNodeStep(static_cast<double>(state.range(0) * state.range(1)) * static_cast<double>(state.iterations()));
}
BENCHMARK(latticeStepOneAtATime)->Args({1001, 1001})->Args({225, 121})->Args({57, 31})->Unit(benchmark::kMicrosecond);

/// A naive step of the same lattice's bulk (naive_lattice.h), for scale: its springs and damping with the
/// model's constants, stepped one step per sweep, as latticeStepOneAtATime. At rest, an equilibrium, so
/// that every step costs the same (a bond's square root and division cost the same at any stretch).
/// Counted per node as the model's, bottom row included (the naive step holds it and skips its forces).
void naiveLatticeStep(benchmark::State& state) {
  const Lattice2D lattice(latticeScene(static_cast<int>(state.range(0)), static_cast<int>(state.range(1))));
  NaiveLattice naive(lattice.nodesX(), lattice.nodesZ(), lattice.spacing(), lattice.springStiffness(),
                     lattice.dampingRate(), lattice.nodeMass());
  for (auto _ : state) naive.step(1e-8);
  state.counters["ns_per_node_step"] =
      nsPerNodeStep(static_cast<double>(state.range(0) * state.range(1)) * static_cast<double>(state.iterations()));
}
BENCHMARK(naiveLatticeStep)->Args({57, 31})->Args({225, 121})->Args({1001, 1001})->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(latticeStep, linearised, SpringForm::Linearised)
    ->Args({57, 31})
    ->Args({449, 241})
    ->Unit(benchmark::kMicrosecond);

void chainStep(benchmark::State& state) {
  Simulation& simulation = reusedSimulation("chain/" + std::to_string(state.range(0)), [&] {
    Scene scene;
    scene.model = ModelKind::Chain1D;
    scene.chain.blocks = static_cast<int>(state.range(0));
    scene.stage.program = {StageSegment{StageMode::Hold, 0.0}};
    scene.integrator.fast_forward = false;
    scene.stop.time = 1e9;
    const double stability_limit = sceneStabilityLimit(scene);
    scene.integrator.time_step = 0.5 * stability_limit;
    return std::make_unique<Simulation>(scene, stability_limit);
  });
  advanceAndCount(state, simulation, static_cast<double>(state.range(0)), "ns_per_block_step");
}
BENCHMARK(chainStep)->Arg(2)->Arg(57)->Arg(1000)->Arg(100000)->Unit(benchmark::kMicrosecond);

/// The memory floor of a lattice step: velocity Verlet's traffic alone, each node's displacements,
/// velocities and accelerations (6 numbers) read and written once, with a force that costs nothing.
/// Compared with latticeStep at the same size it tells how much of a large lattice's step is waiting
/// for memory.
void stateStream(benchmark::State& state) {
  const std::size_t nodes = static_cast<std::size_t>(state.range(0));
  std::vector<double> ux(nodes, 1e-6), uz(nodes, -1e-6), vx(nodes, 0.0), vz(nodes, 0.0), ax(nodes, 0.0), az(nodes, 0.0);
  const double dt = 1e-8, half_dt = 0.5 * dt, stiffness_per_mass = 1e10;
  for (auto _ : state) {
    double* __restrict pux = ux.data();
    double* __restrict puz = uz.data();
    double* __restrict pvx = vx.data();
    double* __restrict pvz = vz.data();
    double* __restrict pax = ax.data();
    double* __restrict paz = az.data();
    for (std::size_t i = 0; i < nodes; ++i) {
      const double half_vx = pvx[i] + half_dt * pax[i], half_vz = pvz[i] + half_dt * paz[i];
      pux[i] += dt * half_vx;
      puz[i] += dt * half_vz;
      pax[i] = -stiffness_per_mass * pux[i];
      paz[i] = -stiffness_per_mass * puz[i];
      pvx[i] = half_vx + half_dt * pax[i];
      pvz[i] = half_vz + half_dt * paz[i];
    }
    benchmark::ClobberMemory();
  }
  state.counters["ns_per_node_step"] =
      nsPerNodeStep(static_cast<double>(nodes) * static_cast<double>(state.iterations()));
}
BENCHMARK(stateStream)->Arg(57 * 31)->Arg(1001 * 1001)->Unit(benchmark::kMicrosecond);

/// The same floor for leapfrog with half-step velocities, which needs no accelerations between steps:
/// 4 numbers per node read and written instead of 6. Tells whether storing half-step velocities in
/// place of the accelerations would make a large lattice's step cheaper.
void leapfrogStream(benchmark::State& state) {
  const std::size_t nodes = static_cast<std::size_t>(state.range(0));
  std::vector<double> ux(nodes, 1e-6), uz(nodes, -1e-6), vx(nodes, 0.0), vz(nodes, 0.0);
  const double dt = 1e-8, stiffness_per_mass = 1e10;
  for (auto _ : state) {
    double* __restrict pux = ux.data();
    double* __restrict puz = uz.data();
    double* __restrict pvx = vx.data();
    double* __restrict pvz = vz.data();
    for (std::size_t i = 0; i < nodes; ++i) {
      pvx[i] -= dt * stiffness_per_mass * pux[i];
      pvz[i] -= dt * stiffness_per_mass * puz[i];
      pux[i] += dt * pvx[i];
      puz[i] += dt * pvz[i];
    }
    benchmark::ClobberMemory();
  }
  state.counters["ns_per_node_step"] =
      nsPerNodeStep(static_cast<double>(nodes) * static_cast<double>(state.iterations()));
}
BENCHMARK(leapfrogStream)->Arg(57 * 31)->Arg(1001 * 1001)->Unit(benchmark::kMicrosecond);

/// The divider's floor under the 2D step: the square root and the division that each geometric bond
/// takes (tension per length k (|b| − L₀)/|b|), alone, for the default 57 × 31 lattice's bonds (about 4
/// per node, in cache). Neither instruction is fully pipelined, so on a host where this is most of
/// latticeStep/geometric/57/31 no rearrangement of the bond loops can bring the step much below it.
void bondDividerFloor(benchmark::State& state) {
  const int nx = 57, nz = 31;
  const std::size_t bonds = (nx - 1) * nz + nx * (nz - 1) + 2 * (nx - 1) * (nz - 1);
  std::vector<double> squared_length(bonds), tension_per_length(bonds);
  for (std::size_t i = 0; i < bonds; ++i) squared_length[i] = 1.0 + 1e-4 * static_cast<double>(i % 17);
  for (auto _ : state) {
    const double* __restrict squared = squared_length.data();
    double* __restrict tension = tension_per_length.data();
    for (std::size_t i = 0; i < bonds; ++i) {
      const double length = std::sqrt(squared[i]);
      tension[i] = (length - 1.0) / length;
    }
    benchmark::DoNotOptimize(tension_per_length.data());
    benchmark::ClobberMemory();
  }
  state.counters["ns_per_node_step"] =
      nsPerNodeStep(static_cast<double>(nx * nz) * static_cast<double>(state.iterations()));
}
BENCHMARK(bondDividerFloor)->Unit(benchmark::kMicrosecond);

/// The stiffness matrix's assembly, as a run's static solver starts with it (µs per matrix).
void stiffnessAssembly(benchmark::State& state) {
  const std::unique_ptr<Model> model =
      buildModel(latticeScene(static_cast<int>(state.range(0)), static_cast<int>(state.range(1))));
  for (auto _ : state) benchmark::DoNotOptimize(model->stiffnessMatrix());
}
BENCHMARK(stiffnessAssembly)->Args({57, 31})->Args({225, 121})->Unit(benchmark::kMicrosecond);

/// A static solver's construction, as each run's start makes the loading solver's: the assembly, the
/// ordering, the analysis and the numeric factorisation with its single-precision copy (µs per solver).
void staticFactor(benchmark::State& state) {
  const std::unique_ptr<Model> model =
      buildModel(latticeScene(static_cast<int>(state.range(0)), static_cast<int>(state.range(1))));
  model->disconnectPusher();
  for (auto _ : state) benchmark::DoNotOptimize(StaticSolver(*model, model->blockedDofsDuringLoading()));
}
BENCHMARK(staticFactor)->Args({57, 31})->Args({225, 121})->Unit(benchmark::kMicrosecond);

/// A static solve through the direct factor in double, as fast-forward makes them: the loading solver of
/// the default slider's lattice, K⁻¹·f for a force on every free dof (µs per solve).
void staticSolve(benchmark::State& state) {
  const int nx = static_cast<int>(state.range(0)), nz = static_cast<int>(state.range(1));
  const std::unique_ptr<Model> model = buildModel(latticeScene(nx, nz));
  model->disconnectPusher();
  const StaticSolver solver(*model, model->blockedDofsDuringLoading());
  Vector force(model->dofCount());
  for (Eigen::Index i = 0; i < force.size(); ++i) force[i] = std::sin(0.1 * static_cast<double>(i));
  for (auto _ : state) benchmark::DoNotOptimize(solver.response(force));
}
BENCHMARK(staticSolve)->Args({57, 31})->Args({225, 121})->Unit(benchmark::kMicrosecond);

/// staticSolve's solve for 24 force vectors at once, as a creep's linearisation makes them (µs per vector).
void staticSolveColumns(benchmark::State& state) {
  const int nx = static_cast<int>(state.range(0)), nz = static_cast<int>(state.range(1));
  const std::unique_ptr<Model> model = buildModel(latticeScene(nx, nz));
  model->disconnectPusher();
  const StaticSolver solver(*model, model->blockedDofsDuringLoading());
  constexpr int kColumns = 24;
  Eigen::MatrixXd forces(model->dofCount(), kColumns);
  for (Eigen::Index i = 0; i < forces.size(); ++i) forces.data()[i] = std::sin(0.1 * static_cast<double>(i));
  for (auto _ : state) benchmark::DoNotOptimize(solver.responses(forces));
  state.counters["us_per_vector"] =
      benchmark::Counter(kColumns, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(staticSolveColumns)->Args({57, 31})->Args({225, 121})->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace friction

int main(int argc, char** argv) {
  // The heap a run has, so that the static benchmarks time the work and not first-touch page faults.
  friction::reuseFreedMemoryOnHugePages();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}
