// Force evaluation in strips (the fused integrator step's sweep): each model's strips give the forces of
// one sweep and keep the hook contract of model.h.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <vector>

#include "friction_sim/model/chain_1d.h"
#include "friction_sim/model/lattice_2d.h"
#include "test_helpers.h"

namespace friction {
namespace {

/// Evaluates `model` in strips of each size, with hooks that drift the state when a dof is prepared
/// and kick its velocity when it is finished, against one sweep over the drifted state. The forces and
/// normal forces must be the same bit for bit: a dof read before it was prepared, or a velocity read
/// after its dof was finished, would change them. The damping power is a sum taken strip by strip, so
/// it may differ from the one sweep's in the last digits (`power_tolerance`, relative). The one sweep is
/// `one_sweep`'s where given (the same model, unthreaded); a threaded sweep's `seam_rows` (each upper
/// block's first row) are where the hooks stall, to give the threads their worst order.
void expectStripsGiveOneSweep(const Model& model, const Vector& u, double stage_position,
                              const std::vector<int>& strip_sizes, double power_tolerance,
                              const Model* one_sweep = nullptr, const std::vector<int>& seam_rows = {}) {
  const int n = model.dofCount();
  Vector v(n), shift(n), kick(n);
  for (int i = 0; i < n; ++i) {
    v[i] = 1e-3 * std::cos(0.21 * i);
    shift[i] = 1e-7 * std::cos(0.13 * i * i);
    kick[i] = 1e-4 * std::sin(0.7 * i + 0.3);
  }
  ForceEvaluation whole;
  (one_sweep ? *one_sweep : model).evaluate(u + shift, v, stage_position, whole);
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
    const auto shape = model.gridShape();
    hooks.stallAtSeams(seam_rows, shape[0], shape[0] * shape[1]);
    model.evaluateInStrips(u_strips, v_strips, stage_position, strips.force, strips, hooks, strip_nodes);
    if (!seam_rows.empty()) {
      EXPECT_EQ(hooks.threads(), seam_rows.size() + 1);  // a thread for each block
    }
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

/// The loaded slider at nx × nz nodes, with the top load and pusher of `variant`.
Scene latticeStripScene(int variant, int nx = 21, int nz = 11) {
  Scene scene = testing::pmmaScene(nx, nz);
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

TEST(LatticeThreads, BlocksOfRowsOnThreadsGiveTheForcesOfOneSweepBitForBit) {
  for (int variant : {0, 1}) {
    SCOPED_TRACE(variant);
    // 1485 nodes, over the size where threads start; 33 rows are 5 bands of 8 rows, the last of 1.
    const Scene scene = latticeStripScene(variant, 45, 33);
    const Lattice2D one_thread(scene);
    const Vector u = roughDisplacements(one_thread.dofCount(), true);
    ASSERT_GE(one_thread.nodesX() * one_thread.nodesZ(), Lattice2D::kThreadedNodes);
    EXPECT_EQ(one_thread.threadedBlocks(), 1);
    EXPECT_EQ(one_thread.successiveEvaluations(), 3);
    // More threads than cores, as many as bands (one block per band) and more (a band each, no more).
    for (int threads : {2, 3, 5, 7}) {
      SCOPED_TRACE(threads);
      Lattice2D threaded(scene);
      threaded.setThreads(threads);
      const int blocks = threaded.threadedBlocks();
      EXPECT_EQ(blocks, std::min(threads, 5));
      EXPECT_EQ(threaded.successiveEvaluations(), 1);
      std::vector<int> seam_rows;
      for (int block = 1; block < blocks; ++block) {
        seam_rows.push_back(threaded.firstRowOfBlock(block, blocks));
        EXPECT_EQ(seam_rows.back() % Lattice2D::kPowerBandRows, 0);
        EXPECT_GT(seam_rows.back(), block == 1 ? 0 : seam_rows[block - 2]);
      }
      // Strips of one row, of several rows, of more rows than a band, and the whole lattice.
      expectStripsGiveOneSweep(threaded, u, 1e-5, {1, 5 * 45, 10 * 45, threaded.dofCount()}, 0.0, &one_thread,
                               seam_rows);
    }
  }
  // Below the size where threads pay, none are used.
  Lattice2D small(latticeStripScene(0));
  small.setThreads(2);
  EXPECT_EQ(small.threadedBlocks(), 1);
}

TEST(ChainStrips, SideDrivenStripsGiveTheForcesOfOneSweepAndKeepTheHookContract) {
  const Chain1D chain(tiltedTorqueChainScene());
  const Vector u = roughDisplacements(chain.dofCount(), false);
  // Strips of single blocks, of 4 and 5 (a shorter last strip) and one strip.
  expectStripsGiveOneSweep(chain, u, 1e-5, {1, 4, 5, 23}, 1e-12);
}

/// Successive velocity Verlet evaluations (VerletPasses hooks, the forces used as accelerations) of
/// `model` from (u, v, a), the stage at 1e-5 m, 1.1e-5 m, 1.2e-5 m, ..., swept together
/// (evaluateSuccessiveInStrips) for every count up to the model's most, and one after the other: the
/// state and every evaluation must be the same bit for bit. `next` must be asked for each evaluation
/// once the one before has its interface final, also for the one past the most.
void expectSuccessiveSweepsGiveSuccessiveEvaluations(const Model& model, const Vector& u,
                                                     const std::vector<int>& strip_sizes) {
  const int n = model.dofCount(), most = model.successiveEvaluations();
  const double dt = 2e-9;
  auto stage = [](int k) { return 1e-5 * (1.0 + 0.1 * k); };
  Vector v(n), a(n);
  for (int i = 0; i < n; ++i) {
    v[i] = 1e-3 * std::cos(0.21 * i);
    a[i] = 1e3 * std::sin(0.7 * i + 0.3);
  }
  auto interfaceOf = [&](const Vector& acceleration) {
    return Vector(acceleration.segment(model.interfaceDof(0), model.interfaceNodeCount()));
  };
  for (int strip_nodes : strip_sizes) {
    // One after the other: the state after each evaluation, and the evaluations.
    std::vector<Vector> u_after, v_after, a_after;
    std::vector<ForceEvaluation> one(most);
    Vector u_one = u, v_one = v, a_one = a;
    for (int k = 0; k < most; ++k) {
      VerletPasses passes(u_one, v_one, a_one, dt);
      model.evaluateInStrips(u_one, v_one, stage(k), a_one, one[k], passes, strip_nodes);
      u_after.push_back(u_one);
      v_after.push_back(v_one);
      a_after.push_back(a_one);
    }
    for (int count = 1; count <= most; ++count) {
      SCOPED_TRACE(::testing::Message() << strip_nodes << " nodes per strip, " << count << " evaluations");
      Vector u_together = u, v_together = v, a_together = a;
      std::vector<ForceEvaluation> together(most);
      VerletPasses passes(u_together, v_together, a_together, dt);
      int asked = 0;
      const int evaluated = model.evaluateSuccessiveInStrips(strip_nodes, [&](int k) -> std::optional<StripEvaluation> {
        EXPECT_EQ(k, asked++);
        if (k > 0) {
          EXPECT_TRUE((interfaceOf(a_together).array() == interfaceOf(a_after[k - 1]).array()).all());
        }
        if (k == count) return std::nullopt;
        return StripEvaluation{u_together, v_together, stage(k), a_together, together[k], passes};
      });
      EXPECT_EQ(evaluated, count);
      EXPECT_EQ(asked, count + 1);
      EXPECT_TRUE((u_together.array() == u_after[count - 1].array()).all());
      EXPECT_TRUE((v_together.array() == v_after[count - 1].array()).all());
      EXPECT_TRUE((a_together.array() == a_after[count - 1].array()).all());
      for (int k = 0; k < most; ++k) {
        if (k >= count) {
          EXPECT_EQ(together[k].normal_force.size(), 0);
          continue;
        }
        EXPECT_EQ(together[k].shear_force, one[k].shear_force);
        EXPECT_EQ(together[k].normal_load, one[k].normal_load);
        EXPECT_EQ(together[k].viscous_power, one[k].viscous_power);
        EXPECT_TRUE((together[k].normal_force.array() == one[k].normal_force.array()).all());
      }
    }
    // An evaluation past the most is refused.
    Vector u_over = u, v_over = v, a_over = a;
    ForceEvaluation over;
    VerletPasses passes(u_over, v_over, a_over, dt);
    EXPECT_THROW(model.evaluateSuccessiveInStrips(strip_nodes,
                                                  [&](int) -> std::optional<StripEvaluation> {
                                                    return StripEvaluation{u_over, v_over, stage(0),
                                                                           a_over, over,   passes};
                                                  }),
                 std::logic_error);
  }
}

TEST(LatticeStrips, SuccessiveStepsSweptTogetherGiveTheStepsOneAfterTheOther) {
  for (int variant : {0, 1}) {
    SCOPED_TRACE(variant);
    const Lattice2D lattice(latticeStripScene(variant));
    ASSERT_GE(lattice.successiveEvaluations(), 3);
    const Vector u = roughDisplacements(lattice.dofCount(), true);
    // Strips of one, two and three rows of 21 nodes, and the whole lattice as one strip.
    expectSuccessiveSweepsGiveSuccessiveEvaluations(lattice, u, {21, 2 * 21, 3 * 21, lattice.dofCount()});
  }
}

TEST(ChainStrips, TheChainEvaluatesOneStepAtATime) {
  // Its state stays in the cache: sweeping several steps together would gain nothing.
  const Chain1D chain(tiltedTorqueChainScene());
  EXPECT_EQ(chain.successiveEvaluations(), 1);
  expectSuccessiveSweepsGiveSuccessiveEvaluations(chain, roughDisplacements(chain.dofCount(), false), {4, 23});
}

}  // namespace
}  // namespace friction
