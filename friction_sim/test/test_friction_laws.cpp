// MODEL.md §4, branch by branch: stick, stick→slip, sliding in both directions, re-stick at the zero
// crossing, weakening over ξ_µ, loss and return of contact, the elastic anchor k_T.
#include <gtest/gtest.h>

#include "friction_sim/contact/contact_interface.h"
#include "friction_sim/model/chain_1d.h"
#include "one_node.h"

namespace friction {
namespace {

constexpr double kMuS = 0.4, kMuK = 0.17;

/// One Amontons–Coulomb node, unless a test gives another law.
class OneNode : public testing::OneInterfaceNode {
 protected:
  OneNode() : OneNode(std::make_unique<AmontonsCoulomb>(kMuS, kMuK)) {}
  explicit OneNode(std::unique_ptr<FrictionLaw> law) : OneInterfaceNode(std::move(law)) {}
  /// Unsticks the node forwards and ends one step of length `dt` with it sliding, so that it is no longer
  /// "just unstuck" and may re-stick in the next step.
  void slideThroughOneStep(double dt) {
    update(4.1, 10.0);
    net(4.1, 10.0);
    contact_.beginStep(u_, v_);
    contact_.finishStep(u_, v_, dt);
  }
};

TEST_F(OneNode, StuckNodeCarriesWhateverHoldsItUpToStaticFriction) {
  EXPECT_DOUBLE_EQ(net(3.9, 10.0), 0.0);
  EXPECT_DOUBLE_EQ(contact_.frictionForce(0), -3.9);
  EXPECT_FALSE(update(3.9, 10.0));
  EXPECT_FALSE(update(-4.0, 10.0));  // exactly µ_s·N still holds
  EXPECT_EQ(contact_.state(0), ContactState::Stuck);
}

TEST_F(OneNode, ReadingsAfterStateUpdatesAreThoseOfTheLastFrictionPass) {
  // Each update keeps its loads for the next one's crossing interpolation; the readings must not lag.
  update(3.0, 10.0);
  EXPECT_FALSE(update(2.0, 8.0));
  EXPECT_DOUBLE_EQ(contact_.frictionForce(0), -2.0);
  EXPECT_DOUBLE_EQ(contact_.normalForce(0), 8.0);
  EXPECT_FALSE(update(1.0, 6.0));
  EXPECT_DOUBLE_EQ(contact_.frictionForce(0), -1.0);
  EXPECT_DOUBLE_EQ(contact_.normalForce(0), 6.0);
}

TEST_F(OneNode, FrictionReappliedAfterUnstickingUsesTheLastNormalForce) {
  update(3.0, 8.0);  // an earlier update at another normal force
  EXPECT_TRUE(update(4.1, 10.0));
  Vector acceleration = Vector::Zero(1);
  contact_.reapplyFriction(u_, v_, 1.0, acceleration);
  EXPECT_DOUBLE_EQ(acceleration[0], 4.1 - kMuK * 10.0);
  EXPECT_DOUBLE_EQ(contact_.frictionForce(0), -kMuK * 10.0);
  EXPECT_DOUBLE_EQ(contact_.normalForce(0), 10.0);
}

TEST_F(OneNode, UnsticksBeyondStaticFrictionAndSlidesAgainstKineticFriction) {
  EXPECT_TRUE(update(4.1, 10.0));
  EXPECT_EQ(contact_.state(0), ContactState::Sliding);
  EXPECT_DOUBLE_EQ(net(4.1, 10.0), 4.1 - kMuK * 10.0);
  EXPECT_DOUBLE_EQ(contact_.frictionForce(0), -kMuK * 10.0);
}

TEST_F(OneNode, SlidesBackwardsWithFrictionReversed) {
  EXPECT_TRUE(update(-4.1, 10.0));
  EXPECT_DOUBLE_EQ(net(-4.1, 10.0), -4.1 + kMuK * 10.0);
  // The friction force follows the current normal force while sliding.
  EXPECT_DOUBLE_EQ(net(-1.0, 20.0), -1.0 + kMuK * 20.0);
}

TEST_F(OneNode, ReSticksAtTheInterpolatedZeroCrossingOfTheVelocity) {
  // A step that is not the one right after unsticking: the velocity goes from +2 to −1 m/s.
  const double dt = 1e-3;
  slideThroughOneStep(dt);
  v_[0] = 2.0;
  u_[0] = 0.5;
  contact_.beginStep(u_, v_);
  u_[0] = 0.5 + 0.5 * dt;
  v_[0] = -1.0;
  EXPECT_TRUE(contact_.finishStep(u_, v_, dt));
  EXPECT_EQ(contact_.state(0), ContactState::Stuck);
  EXPECT_DOUBLE_EQ(contact_.transitionFraction(0), 2.0 / 3.0);
  // Velocity linear over the step: it stops after 2/3 dt, having moved ½·2·(2/3)dt.
  EXPECT_DOUBLE_EQ(u_[0], 0.5 + 2.0 / 3.0 * dt);
  EXPECT_DOUBLE_EQ(v_[0], 0.0);
}

TEST_F(OneNode, CannotReStickInTheStepRightAfterUnstickingButTurnsWithItsVelocity) {
  update(4.1, 10.0);  // unsticks towards +x
  contact_.beginStep(u_, v_);
  v_[0] = -1e-3;
  EXPECT_TRUE(contact_.finishStep(u_, v_, 1e-3));  // its friction changed
  EXPECT_EQ(contact_.state(0), ContactState::Sliding);
  // Sliding towards −x now: kinetic friction along +x.
  EXPECT_DOUBLE_EQ(net(1.0, 10.0), 1.0 + kMuK * 10.0);
  EXPECT_DOUBLE_EQ(contact_.frictionForce(0), kMuK * 10.0);
}

TEST_F(OneNode, NodeThatTurnedAfterUnstickingReSticksWhenItsVelocityPassesThroughZeroAgain) {
  const double dt = 1e-3;
  update(4.1, 10.0);
  contact_.beginStep(u_, v_);
  v_[0] = -1e-3;
  u_[0] = -0.5e-3 * dt;
  ASSERT_TRUE(contact_.finishStep(u_, v_, dt));
  // Its friction changed, so the forces are evaluated again; a constant +2 N pulls it back: net 2 + 1.7 N
  // on 1 kg, from −1 mm/s through zero within the next step (after 1e-3 / 3.7 s = 0.27 dt).
  const double acceleration = net(2.0, 10.0);
  const double start_u = u_[0];
  const double dissipated_before = contact_.frictionDissipation();
  contact_.beginStep(u_, v_);
  EXPECT_DOUBLE_EQ(acceleration, 2.0 + kMuK * 10.0);
  v_[0] += acceleration * dt;
  u_[0] += (-1e-3 + 0.5 * acceleration * dt) * dt;
  EXPECT_TRUE(contact_.finishStep(u_, v_, dt));
  EXPECT_EQ(contact_.state(0), ContactState::Stuck);
  const double fraction = 1e-3 / (acceleration * dt);
  EXPECT_NEAR(contact_.transitionFraction(0), fraction, 1e-12);
  EXPECT_NEAR(u_[0], start_u - 0.5e-3 * fraction * dt, 1e-15);
  // Friction opposed the motion: it dissipated µ_k·N times the distance slid.
  EXPECT_NEAR(contact_.frictionDissipation() - dissipated_before, kMuK * 10.0 * 0.5e-3 * fraction * dt, 1e-15);
}

TEST_F(OneNode, LosesContactAtZeroNormalForceAndRecovers) {
  EXPECT_TRUE(update(1.0, 0.0));
  EXPECT_EQ(contact_.state(0), ContactState::Detached);
  EXPECT_DOUBLE_EQ(net(1.0, 0.0), 1.0);  // no friction without contact
  v_[0] = -0.2;
  EXPECT_TRUE(update(1.0, 10.0));
  EXPECT_EQ(contact_.state(0), ContactState::Sliding);
  EXPECT_DOUBLE_EQ(contact_.frictionForce(0), 0.0);
  EXPECT_DOUBLE_EQ(net(1.0, 10.0), 1.0 + kMuK * 10.0);  // sliding towards −x: friction along +x
  update(1.0, 0.0);
  v_[0] = 0.0;
  EXPECT_TRUE(update(1.0, 10.0));
  EXPECT_EQ(contact_.state(0), ContactState::Stuck);  // returns at rest: sticks
}

TEST_F(OneNode, NodeSlidingOffOnLandingUnsticksAtTheEndOfTheStep) {
  update(3.0, 10.0);
  net(5.0, 10.0);
  ASSERT_TRUE(contact_.updateStates(u_, v_, 1e-3, 2.0));
  ASSERT_DOUBLE_EQ(contact_.transitionFraction(0), 0.5);  // unstuck halfway through a step
  ASSERT_TRUE(update(1.0, 0.0));                          // lifts off, still moving
  ASSERT_EQ(contact_.state(0), ContactState::Detached);
  ASSERT_TRUE(update(1.0, 10.0));  // lands moving: slides on, and counts as unsticking at this update
  EXPECT_EQ(contact_.state(0), ContactState::Sliding);
  ASSERT_EQ(contact_.unstuckLastStep(), std::vector<int>{0});
  EXPECT_DOUBLE_EQ(contact_.transitionFraction(0), 1.0);
}

TEST_F(OneNode, UnstickingMidStepCatchesUpTheSlipItMissed) {
  update(3.0, 10.0);  // load ratio 0.75
  net(5.0, 10.0);     // load ratio 1.25: crossed µ_s·N halfway through the step
  const double dt = 1e-3, mass = 2.0;
  ASSERT_TRUE(contact_.updateStates(u_, v_, dt, mass));
  EXPECT_DOUBLE_EQ(contact_.transitionFraction(0), 0.5);
  const double acceleration = (5.0 - kMuK * 10.0) / mass;
  EXPECT_DOUBLE_EQ(v_[0], acceleration * 0.5 * dt);
  EXPECT_DOUBLE_EQ(u_[0], 0.5 * acceleration * 0.25 * dt * dt);
}

/// The same node under linear slip weakening over ξ_µ = 0.1 µm.
class OneWeakeningNode : public OneNode {
 public:
  static constexpr double kWeakeningLength = 1e-7;

 protected:
  OneWeakeningNode() : OneNode(std::make_unique<LinearSlipWeakening>(kMuS, kMuK, kWeakeningLength)) {}
};

TEST_F(OneWeakeningNode, TheCatchUpSlipWeakensFriction) {
  update(3.0, 10.0);
  net(5.0, 10.0);  // crosses µ_s·N halfway through the step
  const double dt = 1e-3, mass = 2.0;
  ASSERT_TRUE(contact_.updateStates(u_, v_, dt, mass));
  // Unweakened at the crossing, µ = µ_s: it catches up ½·a·(dt/2)² = 62.5 nm, 0.625 ξ_µ.
  const double catch_up = 0.5 * ((5.0 - kMuS * 10.0) / mass) * 0.25 * dt * dt;
  ASSERT_DOUBLE_EQ(u_[0], catch_up);
  // µ = 0.4 − 0.23 · 0.625 = 0.25625
  EXPECT_DOUBLE_EQ(net(5.0, 10.0), 5.0 - (kMuS - (kMuS - kMuK) * catch_up / kWeakeningLength) * 10.0);
  // The next step measures its slip from after the catch-up: δ is the sum, each counted once.
  contact_.beginStep(u_, v_);
  const double step_slip = 20e-9;
  u_[0] += step_slip;
  v_[0] += 1e-6;  // still sliding forwards
  contact_.finishStep(u_, v_, dt);
  EXPECT_DOUBLE_EQ(net(5.0, 10.0), 5.0 - (kMuS - (kMuS - kMuK) * (catch_up + step_slip) / kWeakeningLength) * 10.0);
}

/// µ(δ) = µ_s − (µ_s − µ_k)·min(δ/ξ_µ, 1) (MODEL.md §4).
double weakened(double slip) { return kMuS - (kMuS - kMuK) * std::min(slip / OneWeakeningNode::kWeakeningLength, 1.0); }

class OneWeakeningNodeBothWays : public OneWeakeningNode, public ::testing::WithParamInterface<double> {
 protected:
  /// Moves the sliding node by `slip` (m) over one step, its velocity keeping the sign of `slip`.
  void slide(double slip) {
    contact_.beginStep(u_, v_);
    u_[0] += slip;
    v_[0] = slip > 0.0 ? 1e-3 : -1e-3;
    contact_.finishStep(u_, v_, 1e-3);
  }
};

TEST_P(OneWeakeningNodeBothWays, StaysStuckUpToStaticFrictionThenWeakensOverTheSlipFromMuSToMuK) {
  const double sign = GetParam(), xi = kWeakeningLength;
  EXPECT_FALSE(update(sign * 4.0, 10.0));  // µ_s·N holds
  EXPECT_DOUBLE_EQ(contact_.frictionForce(0), -sign * 4.0);
  EXPECT_TRUE(update(sign * 4.1, 10.0));  // beyond it: slides, unweakened at first
  EXPECT_DOUBLE_EQ(net(sign * 4.1, 10.0), sign * (4.1 - kMuS * 10.0));
  slide(sign * 0.25 * xi);  // the step right after unsticking: weakens, cannot re-stick
  EXPECT_DOUBLE_EQ(net(sign * 4.1, 10.0), sign * (4.1 - weakened(0.25 * xi) * 10.0));
  slide(sign * 0.5 * xi);  // δ is the slip summed, 0.75 ξ_µ
  EXPECT_NEAR(net(sign * 4.1, 10.0), sign * (4.1 - weakened(0.75 * xi) * 10.0), 1e-12);
  EXPECT_NEAR(contact_.frictionForce(0), -sign * weakened(0.75 * xi) * 10.0, 1e-12);
  slide(sign * xi);  // beyond ξ_µ: µ_k, and no lower
  EXPECT_DOUBLE_EQ(net(sign * 4.1, 10.0), sign * (4.1 - kMuK * 10.0));
}

TEST_P(OneWeakeningNodeBothWays, ReStickingRestoresStaticFriction) {
  const double sign = GetParam();
  update(sign * 4.1, 10.0);
  slide(sign * 2.0 * kWeakeningLength);
  ASSERT_DOUBLE_EQ(net(sign * 4.1, 10.0), sign * (4.1 - kMuK * 10.0));
  // Its velocity passes through zero within a step: it re-sticks, and δ starts again from 0.
  contact_.beginStep(u_, v_);
  v_[0] = -sign * 1e-3;
  ASSERT_TRUE(contact_.finishStep(u_, v_, 1e-3));
  ASSERT_EQ(contact_.state(0), ContactState::Stuck);
  EXPECT_FALSE(update(sign * 4.0, 10.0));  // held again up to µ_s·N
  EXPECT_TRUE(update(sign * 4.1, 10.0));
  EXPECT_DOUBLE_EQ(net(sign * 4.1, 10.0), sign * (4.1 - kMuS * 10.0));
}

TEST_P(OneWeakeningNodeBothWays, HasNoFrictionWithoutContactAndLandsSlidingOnAFreshContact) {
  const double sign = GetParam();
  update(sign * 4.1, 10.0);
  slide(sign * 2.0 * kWeakeningLength);
  ASSERT_TRUE(update(sign * 1.0, 0.0));  // lifts off while weakened
  EXPECT_EQ(contact_.state(0), ContactState::Detached);
  EXPECT_DOUBLE_EQ(net(sign * 1.0, 0.0), sign * 1.0);
  // It lands moving: a new contact, unstuck at this update (δ = 0), so µ_s opposes the motion.
  ASSERT_TRUE(update(sign * 1.0, 10.0));
  EXPECT_EQ(contact_.state(0), ContactState::Sliding);
  EXPECT_DOUBLE_EQ(net(sign * 1.0, 10.0), sign * (1.0 - kMuS * 10.0));
}

INSTANTIATE_TEST_SUITE_P(ForwardsAndBackwards, OneWeakeningNodeBothWays, ::testing::Values(1.0, -1.0));

TEST_F(OneNode, CrossingIsInterpolatedFromTheLoadAtTheLastUpdateUnderItsOwnNormalForce) {
  update(3.0, 8.0);  // load ratio 3/(µ_s·8)
  net(4.1, 10.0);    // load ratio 4.1/(µ_s·10), in the evaluation's storage of the 8 N
  ASSERT_TRUE(contact_.updateStates(u_, v_, 1e-3, 1.0));
  const double before = 3.0 / (kMuS * 8.0), after = 4.1 / (kMuS * 10.0);
  EXPECT_DOUBLE_EQ(contact_.transitionFraction(0), (1.0 - before) / (after - before));
}

TEST_F(OneNode, KeepsTheLastUpdatesNormalForceWhenTheNextEvaluationUsesOtherStorage) {
  update(3.0, 8.0);
  ForceEvaluation other;  // not the storage the interface read the 8 N from: it copies them
  other.force = Vector::Constant(1, 4.1);
  contact_.lendNormalStorage(other.normal_force);
  other.normal_force = Vector::Constant(1, 10.0);
  Vector force = other.force;
  contact_.applyFriction(other, u_, v_, 1.0, force);
  ASSERT_TRUE(contact_.updateStates(u_, v_, 1e-3, 1.0));
  const double before = 3.0 / (kMuS * 8.0), after = 4.1 / (kMuS * 10.0);
  EXPECT_DOUBLE_EQ(contact_.transitionFraction(0), (1.0 - before) / (after - before));
}

TEST_F(OneNode, RefusesNormalForcesRewrittenOverThoseOfTheLastUpdate) {
  update(3.0, 8.0);
  raw_.normal_force[0] = 10.0;  // in place: the 8 N the next update needs are lost
  Vector force = raw_.force;
  EXPECT_THROW(contact_.applyFriction(raw_, u_, v_, 1.0, force), std::logic_error);
}

TEST_F(OneNode, NodeUnstuckAtTheEndOfAnAllStuckStepStartedWhereItWasBeforeItsCatchUp) {
  // With every node stuck rigidly, beginStep keeps no copy of the positions: none moves in the step.
  u_[0] = 0.25;
  contact_.reset(u_);
  update(3.0, 10.0);
  contact_.beginStep(u_, v_);
  EXPECT_EQ(contact_.stepStartPosition(0, u_), 0.25);
  net(4.1, 10.0);
  EXPECT_TRUE(contact_.updateStates(u_, v_, 1e-3, 1.0));
  EXPECT_GT(u_[0], 0.25);  // the slip it missed since crossing, 1/11 of the step before its end
  EXPECT_EQ(contact_.stepStartPosition(0, u_), 0.25);
}

// A node that has just stuck starts from a cleared load: if it crosses µ_s·N in the next update, the
// crossing is interpolated from zero load, at (1 − 0)/(1.25 − 0) = 0.8 of the step for a load ratio of
// 1.25, whether it stuck again in the step's finishStep or in the state update before.
TEST_F(OneNode, ReStuckNodeCrossingInTheSameStepCountsFromAClearedLoad) {
  const double dt = 1e-3;
  slideThroughOneStep(dt);
  contact_.updateStates(u_, v_, dt, 1.0);  // sliding: its load ratio here is µ_k/µ_s, not zero
  v_[0] = 2.0;
  contact_.beginStep(u_, v_);
  v_[0] = -1.0;
  ASSERT_TRUE(contact_.finishStep(u_, v_, dt));
  ASSERT_EQ(contact_.state(0), ContactState::Stuck);
  net(5.0, 10.0);
  ASSERT_TRUE(contact_.updateStates(u_, v_, dt, 1.0));
  EXPECT_EQ(contact_.state(0), ContactState::Sliding);
  EXPECT_DOUBLE_EQ(contact_.transitionFraction(0), 0.8);
}

TEST_F(OneNode, NodeStuckOnRegainingContactCrossingInTheNextStepCountsFromAClearedLoad) {
  update(1.0, 0.0);
  ASSERT_TRUE(update(1.0, 10.0));  // returns at rest: sticks
  ASSERT_EQ(contact_.state(0), ContactState::Stuck);
  net(5.0, 10.0);
  ASSERT_TRUE(contact_.updateStates(u_, v_, 1e-3, 1.0));
  EXPECT_EQ(contact_.state(0), ContactState::Sliding);
  EXPECT_DOUBLE_EQ(contact_.transitionFraction(0), 0.8);
}

TEST(LinearSlipWeakening, WeakensLinearlyOverTheWeakeningLength) {
  LinearSlipWeakening law(kMuS, kMuK, 1e-5);
  law.resize(2);
  law.onUnstick(0);
  EXPECT_DOUBLE_EQ(law.staticCoefficient(0), kMuS);
  EXPECT_DOUBLE_EQ(law.slidingCoefficient(0), kMuS);
  law.onSlip(0, 2.5e-6);
  law.onSlip(0, -2.5e-6);  // slip counts in either direction
  EXPECT_DOUBLE_EQ(law.slidingCoefficient(0), kMuS - 0.5 * (kMuS - kMuK));
  law.onSlip(0, 1e-5);
  EXPECT_DOUBLE_EQ(law.slidingCoefficient(0), kMuK);
  EXPECT_DOUBLE_EQ(law.slidingCoefficient(1), kMuS);  // per node
  law.onUnstick(0);
  EXPECT_DOUBLE_EQ(law.slidingCoefficient(0), kMuS);
}

TEST(LinearSlipWeakening, ZeroLengthIsAmontonsCoulomb) {
  LinearSlipWeakening law(kMuS, kMuK, 0.0);
  law.resize(1);
  law.onUnstick(0);
  EXPECT_DOUBLE_EQ(law.slidingCoefficient(0), kMuK);
}

TEST(ElasticAnchor, StuckNodeIsHeldByTheInterfacialSpringAndReSticksWithContinuousForce) {
  Scene scene;
  scene.model = ModelKind::Chain1D;
  scene.chain.blocks = 1;
  const Chain1D block(scene);
  const double k_t = 1000.0;
  ContactInterface contact(std::make_unique<AmontonsCoulomb>(kMuS, kMuK), block, k_t);
  Vector u = Vector::Zero(1), v = Vector::Zero(1), force(1);
  contact.reset(u);
  ForceEvaluation raw;
  // An evaluation with 2 N of other force and 10 N of normal force, then friction on a block of mass
  // 1/inverse_mass.
  auto applyFriction = [&](double inverse_mass) {
    raw.force = Vector::Constant(1, 2.0);
    contact.lendNormalStorage(raw.normal_force);
    raw.normal_force = Vector::Constant(1, 10.0);
    force = raw.force;
    contact.applyFriction(raw, u, v, inverse_mass, force);
  };
  u[0] = 3e-3;         // anchor spring force −3 N, within µ_s·N = 4 N
  applyFriction(0.5);  // a 2 kg block
  EXPECT_DOUBLE_EQ(contact.frictionForce(0), -3.0);
  EXPECT_DOUBLE_EQ(force[0], (2.0 - 3.0) * 0.5);  // the block's acceleration, m/s²
  EXPECT_FALSE(contact.updateStates(u, v, 0.0, 2.0));
  EXPECT_DOUBLE_EQ(contact.anchorEnergy(u), 0.5 * k_t * 9e-6);
  u[0] = 5e-3;  // −5 N needed: unsticks
  applyFriction(1.0);
  EXPECT_TRUE(contact.updateStates(u, v, 0.0, 1.0));
  applyFriction(1.0);
  EXPECT_DOUBLE_EQ(contact.frictionForce(0), -kMuK * 10.0);
  contact.beginStep(u, v);
  contact.finishStep(u, v, 1e-3);
  v[0] = 1.0;
  contact.beginStep(u, v);
  v[0] = -1.0;
  ASSERT_TRUE(contact.finishStep(u, v, 1e-3));
  applyFriction(1.0);
  EXPECT_NEAR(contact.frictionForce(0), -kMuK * 10.0, 1e-12);
}

}  // namespace
}  // namespace friction
