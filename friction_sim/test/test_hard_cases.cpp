// Hard cases (issue 5): each runs with finite values and a closed energy balance, or is refused up
// front with a clear message.
#include <gtest/gtest.h>

#include <cmath>

#include "friction_sim/integrator.h"
#include "friction_sim/simulation.h"
#include "test_helpers.h"

namespace friction {
namespace {

/// Runs to the stop condition; asserts finite state and a closed energy budget (to `tolerance`).
Simulation& expectSound(Simulation& simulation, double tolerance = 1e-4) {
  simulation.run();
  EXPECT_TRUE(simulation.displacements().allFinite());
  EXPECT_TRUE(simulation.velocities().allFinite());
  EXPECT_TRUE(std::isfinite(simulation.loadCells().shear_force));
  EXPECT_LT(std::abs(simulation.energy().relativeResidual()), tolerance);
  return simulation;
}

TEST(HardCases, TimeStepJustBelowTheLimitRunsAndJustAboveIsRefused) {
  Scene scene = testing::coarseSliderScene();
  scene.stop.time = 0.01;
  const double limit = sceneStabilityLimit(scene);
  scene.integrator.time_step = 0.9 * limit;
  Simulation below(scene);
  expectSound(below);
  EXPECT_LT(below.velocities().lpNorm<Eigen::Infinity>(), 1.0);  // no blow-up
  scene.integrator.time_step = 1.1 * limit;
  try {
    Simulation above(scene);
    FAIL() << "accepted";
  } catch (const SceneError& error) {
    EXPECT_NE(std::string(error.what()).find("stability limit"), std::string::npos);
  }
}

TEST(HardCases, EqualStaticAndKineticFrictionAndZeroKineticFriction) {
  for (double kinetic : {0.4, 0.0}) {
    SCOPED_TRACE("mu_k = " + std::to_string(kinetic));
    Scene scene = testing::coarseSliderScene();
    scene.friction.kinetic_coefficient = kinetic;
    scene.stop.time = 0.06;
    Simulation simulation(scene);
    expectSound(simulation);
    // With µ_k = µ_s the trailing edge creeps steadily instead of slipping in events; either way the
    // interface has slipped by now.
    EXPECT_GT(simulation.interfaceFrame().slip.front(), 0.0);
  }
}

TEST(HardCases, NoDampingAndAStiffFoundation) {
  Scene undamped = testing::coarseSliderScene();
  undamped.material.damping_coefficient = 0.0;
  undamped.stop.time = 0.02;
  Simulation first(undamped);
  expectSound(first, 1e-3);  // undamped ringing: the quadrature error is not damped away
  Scene stiff = testing::coarseSliderScene();
  stiff.lattice.foundation_ratio = 50.0;  // k_f = 100 × the default k/2
  stiff.integrator.time_step = 0.9 * sceneStabilityLimit(stiff);
  stiff.stop.time = 0.02;
  EXPECT_LT(stiff.integrator.time_step, 0.9 * sceneStabilityLimit(testing::coarseSliderScene()));
  Simulation second(stiff);
  expectSound(second);
}

TEST(HardCases, PusherAtTheBottomCornerAndAtTheTop) {
  for (double height : {0.0, 0.075}) {
    SCOPED_TRACE("h = " + std::to_string(height));
    Scene scene = testing::coarseSliderScene();
    scene.pusher.height = height;
    Simulation simulation(scene);
    expectSound(simulation);
    EXPECT_EQ(simulation.globalEventCount(), 1);
  }
}

TEST(HardCases, EdgeLiftsOffAndComesBack) {
  // 100 N pressed, pushed at the top: the moment lifts the trailing edge.
  Scene scene = testing::coarseSliderScene();
  scene.load.normal_force = 100.0;
  scene.pusher.height = 0.075;
  scene.stop.global_events = 2;
  Simulation simulation(scene);
  std::vector<char> lifted(simulation.contact().size(), 0);
  int lift_offs = 0, recontacts = 0;
  while (!simulation.finished()) {
    simulation.step();
    for (int node = 0; node < simulation.contact().size(); ++node) {
      const bool detached = simulation.contact().state(node) == ContactState::Detached;
      if (detached != bool(lifted[node])) ++(detached ? lift_offs : recontacts);
      lifted[node] = detached;
    }
  }
  EXPECT_GT(lift_offs, 0);
  EXPECT_GT(recontacts, 0);
  EXPECT_TRUE(simulation.displacements().allFinite());
  EXPECT_LT(std::abs(simulation.energy().relativeResidual()), 1e-3);
}

TEST(HardCases, SmallestSystems) {
  Scene chain = loadScene(testing::scenePath("pmma_1d_side"));
  chain.chain.blocks = 2;
  chain.integrator.time_step = 0.05 * sceneStabilityLimit(chain);
  chain.stop.global_events = 3;
  Simulation two_blocks(chain);
  expectSound(two_blocks, 1e-4);
  EXPECT_EQ(two_blocks.globalEventCount(), 3);
  Scene lattice = testing::coarseSliderScene();
  lattice.lattice.nodes_x = 2;
  lattice.lattice.nodes_z = 2;
  lattice.geometry.length = lattice.geometry.height = 0.075;
  lattice.integrator.time_step = 0.05 * sceneStabilityLimit(lattice);
  lattice.stop.global_events = 2;
  Simulation four_nodes(lattice);
  expectSound(four_nodes, 1e-4);
  EXPECT_EQ(four_nodes.globalEventCount(), 2);
}

TEST(HardCases, FastStageAndSuddenStageJump) {
  Scene fast = testing::coarseSliderScene();
  fast.stage.max_speed = 20.0;
  fast.stage.program = {StageSegment{StageMode::Velocity, 10.0}};
  fast.stop.time = 2e-4;
  Simulation racing(fast);
  // The stage moves 4 µm per step: the trapezoid rule for the pusher's work is then good to ~1e-3.
  expectSound(racing, 5e-3);
  Scene jump = testing::coarseSliderScene();
  jump.stage.max_speed = 1e3;
  jump.stage.program = {StageSegment{StageMode::Position, 1e3, 5e-5}};  // 50 µm in 50 ns
  jump.stop.time = 5e-3;
  Simulation jumping(jump);
  // 200 N of pusher force appear within one step; the work trapezoid is good to a few 1e-3 then.
  expectSound(jumping, 5e-3);
  EXPECT_DOUBLE_EQ(jumping.stage().position(), 5e-5);
}

TEST(HardCases, HundredStickSlipCyclesWithoutDrift) {
  Scene scene = testing::singleBlockScene(IntegratorKind::VelocityVerlet, 0.8, 1e-8);
  scene.stop.global_events = 100;
  Simulation simulation(scene);
  simulation.run();
  const auto& events = simulation.events();
  ASSERT_EQ(events.size(), 100u);
  const double drop_first = events[1].onset_shear_force - events[1].end_shear_force;
  const double drop_last = events[99].onset_shear_force - events[99].end_shear_force;
  EXPECT_NEAR(drop_last, drop_first, 1e-6 * drop_first);
  const double period_first = events[2].onset_time - events[1].onset_time;
  const double period_last = events[99].onset_time - events[98].onset_time;
  EXPECT_NEAR(period_last, period_first, 1e-6 * period_first);
  EXPECT_LT(std::abs(simulation.energy().relativeResidual()), 1e-6);
}

TEST(HardCases, UnresolvedWeakeningLengthIsWarned) {
  Scene scene = testing::coarseSliderScene();
  scene.friction.law = FrictionLawKind::SlipWeakening;
  scene.friction.weakening_length = 1e-4;  // 0.1 mm, far below l = 5 mm
  const auto warnings = sceneWarnings(scene);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("shorter than one node spacing"), std::string::npos);
  scene.friction.weakening_length = 0.02;
  EXPECT_TRUE(sceneWarnings(scene).empty());
}

TEST(HardCases, LargeLatticeTakesAFewSteps) {
  Scene scene = testing::coarseSliderScene();
  scene.lattice.nodes_x = 449;
  scene.lattice.nodes_z = 241;
  scene.geometry.length = 0.0025 * 448;
  scene.geometry.height = 0.0025 * 240;
  scene.integrator.time_step = 1e-7;
  Simulation simulation(scene);
  for (int i = 0; i < 5; ++i) simulation.step();
  EXPECT_TRUE(simulation.displacements().allFinite());
  EXPECT_NEAR(simulation.loadCells().interface_normal_sum, scene.load.normal_force, 1e-6 * scene.load.normal_force);
}

}  // namespace
}  // namespace friction
