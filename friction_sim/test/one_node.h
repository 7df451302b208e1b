// One interface node (a single block) whose forces a test sets by hand: the friction laws' tests.
#pragma once

#include <gtest/gtest.h>

#include <memory>

#include "friction_sim/contact/contact_interface.h"
#include "friction_sim/model/chain_1d.h"

namespace friction::testing {

class OneInterfaceNode : public ::testing::Test {
 protected:
  explicit OneInterfaceNode(std::unique_ptr<FrictionLaw> law)
      : block_(blockScene()), contact_(std::move(law), block_, 0.0) {
    u_ = Vector::Zero(1);
    v_ = Vector::Zero(1);
    contact_.reset(u_);
  }
  static Scene blockScene() {
    Scene scene;
    scene.model = ModelKind::Chain1D;
    scene.chain.blocks = 1;
    return scene;
  }
  /// Friction for a tangential force `other` (N) and normal force `normal` (N), with a closing kick of
  /// `closing_kick` (s; 0 outside a step); returns the net force (the acceleration of a 1 kg block).
  double net(double other, double normal, double closing_kick = 0.0) {
    raw_.force = Vector::Constant(1, other);
    contact_.lendNormalStorage(raw_.normal_force);
    raw_.normal_force = Vector::Constant(1, normal);
    Vector force = raw_.force;
    contact_.applyFriction(raw_, u_, v_, 1.0, force, 0, contact_.size(), closing_kick);
    return force[0];
  }
  /// The state update after a force evaluation giving `other` and `normal` (N).
  bool update(double other, double normal) {
    net(other, normal);
    return contact_.updateStates(u_, v_, 0.0, 1.0);
  }

  Chain1D block_;
  ContactInterface contact_;
  ForceEvaluation raw_;
  Vector u_, v_;
};

}  // namespace friction::testing
