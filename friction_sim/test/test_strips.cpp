// Force evaluation in strips (the fused integrator step's sweep): each model's strips give the forces of
// one sweep and keep the hook contract of model.h.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "friction_sim/chain_1d.h"
#include "friction_sim/lattice_2d.h"
#include "test_helpers.h"

namespace friction {
namespace {

/// Evaluates `model` in strips of each size, with hooks that drift the state when a dof is prepared
/// and kick its velocity when it is finished, against one sweep over the drifted state. The forces and
/// normal forces must be the same bit for bit: a dof read before it was prepared, or a velocity read
/// after its dof was finished, would change them. The damping power is a sum taken strip by strip, so
/// it may differ from the one sweep's in the last digits (`power_tolerance`, relative).
void expectStripsGiveOneSweep(const Model& model, const Vector& u, double stage_position,
                              const std::vector<int>& strip_sizes, double power_tolerance) {
  const int n = model.dofCount();
  Vector v(n), shift(n), kick(n);
  for (int i = 0; i < n; ++i) {
    v[i] = 1e-3 * std::cos(0.21 * i);
    shift[i] = 1e-7 * std::cos(0.13 * i * i);
    kick[i] = 1e-4 * std::sin(0.7 * i + 0.3);
  }
  ForceEvaluation whole;
  model.evaluate(u + shift, v, stage_position, whole);
  ASSERT_GT(whole.shear_force, 0.0);
  const int first_interface_dof = model.interfaceDof(0);
  for (int strip_nodes : strip_sizes) {
    SCOPED_TRACE(strip_nodes);
    Vector u_strips = u, v_strips = v;
    ForceEvaluation strips;
    strips.force = Vector::Constant(n, std::nan(""));
    testing::RecordingHooks hooks(u_strips, shift, strips.force);
    hooks.kickAtFinish(v_strips, kick);
    hooks.recordNormalForces(strips.normal_force, first_interface_dof);
    model.evaluateInStrips(u_strips, v_strips, stage_position, strips.force, strips, hooks, strip_nodes);
    EXPECT_TRUE(hooks.eachOnce());
    EXPECT_TRUE(hooks.untouchedForceAtPrepare());
    EXPECT_TRUE((strips.force.array() == whole.force.array()).all());
    EXPECT_TRUE((hooks.forcesAtFinish().array() == whole.force.array()).all());
    EXPECT_TRUE((strips.normal_force.array() == whole.normal_force.array()).all());
    // A finished strip's interface normal forces are final (the simulation applies friction then).
    for (int node = 0; node < model.interfaceNodeCount(); ++node) {
      EXPECT_EQ(hooks.normalForcesAtFinish()[model.interfaceDof(node)], whole.normal_force[node]) << node;
    }
    EXPECT_EQ(strips.shear_force, whole.shear_force);
    EXPECT_EQ(strips.normal_load, whole.normal_load);
    EXPECT_NEAR(strips.viscous_power, whole.viscous_power, power_tolerance * whole.viscous_power);
  }
}

/// The loaded slider at 21 × 11 nodes, with the top load and pusher of `variant`.
Scene latticeStripScene(int variant) {
  Scene scene = testing::pmmaScene(21, 11);
  if (variant == 1) {
    // A spring mattress that holds the top row in x as well, and a pusher band up to the top row.
    scene.load.top = TopLoadKind::SpringMattress;
    scene.load.mattress_horizontal_stiffness = 1e7;
    scene.pusher.band_min = 0.02;
    scene.pusher.band_max = scene.geometry.height;
  }
  return scene;
}

/// m, a rough displacement field of `n` degrees of freedom; with `pressed_in`, the second half (a
/// lattice's u_z) shifted down so that the bottom row presses on the track.
Vector roughDisplacements(int n, bool pressed_in) {
  Vector u(n);
  for (int i = 0; i < n; ++i) u[i] = 2e-6 * std::sin(0.37 * i * i + 1.0) - (pressed_in && i >= n / 2 ? 1e-6 : 0.0);
  return u;
}

/// 23 blocks, with tilt and the torque term, so that every normal force depends on F_X.
Scene tiltedTorqueChainScene() {
  Scene scene = testing::torqueChainScene(23);
  scene.chain.tilt = 0.3;
  return scene;
}

TEST(LatticeStrips, StripsGiveTheForcesOfOneSweepAndKeepTheHookContract) {
  for (int variant : {0, 1}) {
    SCOPED_TRACE(variant);
    const Lattice2D lattice(latticeStripScene(variant));
    const Vector u = roughDisplacements(lattice.dofCount(), true);
    // Strips of whole rows: one, two and three rows of 21 nodes. The power is summed column by column
    // over the whole sweep, so it is the same bit for bit.
    expectStripsGiveOneSweep(lattice, u, 1e-5, {1, 2 * 21, 3 * 21}, 0.0);
  }
}

TEST(ChainStrips, SideDrivenStripsGiveTheForcesOfOneSweepAndKeepTheHookContract) {
  const Chain1D chain(tiltedTorqueChainScene());
  const Vector u = roughDisplacements(chain.dofCount(), false);
  // Strips of single blocks, of 4 and 5 (a shorter last strip) and one strip.
  expectStripsGiveOneSweep(chain, u, 1e-5, {1, 4, 5, 23}, 1e-12);
}

/// Two velocity Verlet evaluations (VerletPasses hooks, the forces used as accelerations) of `model`
/// from (u, v, a) with the stage at `stage_first` then `stage_second`, swept together
/// (evaluateTwoInStrips) and one after the other: the state and both evaluations must be the same bit
/// for bit. `between` must find the interface's forces final, and when it declines the second
/// evaluation the first must still complete alone.
void expectTwoSweepsGiveTwoEvaluations(const Model& model, const Vector& u, double stage_first, double stage_second,
                                       const std::vector<int>& strip_sizes) {
  const int n = model.dofCount();
  const double dt = 2e-9;
  Vector v(n), a(n);
  for (int i = 0; i < n; ++i) {
    v[i] = 1e-3 * std::cos(0.21 * i);
    a[i] = 1e3 * std::sin(0.7 * i + 0.3);
  }
  for (int strip_nodes : strip_sizes) {
    auto evaluateOnce = [&](Vector& u_now, Vector& v_now, Vector& a_now, double stage, ForceEvaluation& out) {
      VerletPasses passes(u_now, v_now, a_now, dt);
      model.evaluateInStrips(u_now, v_now, stage, a_now, out, passes, strip_nodes);
    };
    Vector u_one = u, v_one = v, a_one = a;
    ForceEvaluation first_one, second_one;
    evaluateOnce(u_one, v_one, a_one, stage_first, first_one);
    const Vector interface_after_first = a_one.segment(model.interfaceDof(0), model.interfaceNodeCount());
    const Vector u_after_first = u_one, v_after_first = v_one, a_after_first = a_one;
    evaluateOnce(u_one, v_one, a_one, stage_second, second_one);
    for (bool go_on : {true, false}) {
      SCOPED_TRACE(::testing::Message() << strip_nodes << (go_on ? " both" : " first only"));
      Vector u_two = u, v_two = v, a_two = a;
      ForceEvaluation first_two, second_two;
      VerletPasses first_passes(u_two, v_two, a_two, dt), second_passes(u_two, v_two, a_two, dt);
      int calls = 0;
      const bool both = model.evaluateTwoInStrips(
          {u_two, v_two, stage_first, a_two, first_two, first_passes},
          {u_two, v_two, stage_second, a_two, second_two, second_passes}, strip_nodes, [&] {
            ++calls;
            EXPECT_TRUE((a_two.segment(model.interfaceDof(0), model.interfaceNodeCount()).array() ==
                         interface_after_first.array()).all());
            return go_on;
          });
      EXPECT_EQ(calls, 1);
      EXPECT_EQ(both, go_on);
      EXPECT_EQ(first_two.shear_force, first_one.shear_force);
      EXPECT_EQ(first_two.normal_load, first_one.normal_load);
      EXPECT_EQ(first_two.viscous_power, first_one.viscous_power);
      EXPECT_TRUE((first_two.normal_force.array() == first_one.normal_force.array()).all());
      if (!go_on) {
        EXPECT_TRUE((u_two.array() == u_after_first.array()).all());
        EXPECT_TRUE((v_two.array() == v_after_first.array()).all());
        EXPECT_TRUE((a_two.array() == a_after_first.array()).all());
        EXPECT_EQ(second_two.normal_force.size(), 0);
        continue;
      }
      EXPECT_TRUE((u_two.array() == u_one.array()).all());
      EXPECT_TRUE((v_two.array() == v_one.array()).all());
      EXPECT_TRUE((a_two.array() == a_one.array()).all());
      EXPECT_EQ(second_two.shear_force, second_one.shear_force);
      EXPECT_EQ(second_two.normal_load, second_one.normal_load);
      EXPECT_EQ(second_two.viscous_power, second_one.viscous_power);
      EXPECT_TRUE((second_two.normal_force.array() == second_one.normal_force.array()).all());
    }
  }
}

TEST(LatticeStrips, TwoStepsSweptTogetherGiveTheTwoStepsOneAfterTheOther) {
  for (int variant : {0, 1}) {
    SCOPED_TRACE(variant);
    const Lattice2D lattice(latticeStripScene(variant));
    const Vector u = roughDisplacements(lattice.dofCount(), true);
    // Strips of one, two and three rows of 21 nodes, and the whole lattice as one strip.
    expectTwoSweepsGiveTwoEvaluations(lattice, u, 1e-5, 1.1e-5, {21, 2 * 21, 3 * 21, lattice.dofCount()});
  }
}

TEST(ChainStrips, TwoStepsEvaluatedTogetherGiveTheTwoStepsOneAfterTheOther) {
  const Chain1D chain(tiltedTorqueChainScene());
  expectTwoSweepsGiveTwoEvaluations(chain, roughDisplacements(chain.dofCount(), false), 1e-5, 1.1e-5, {4, 23});
}

}  // namespace
}  // namespace friction
