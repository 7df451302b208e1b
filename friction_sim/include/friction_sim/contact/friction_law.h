// Friction laws (MODEL.md §4). Every law shares the stuck/sliding states and the rules for leaving
// them (ContactInterface); a law only says how strong static and sliding friction are, and may keep
// per-node internal state that it updates as the node slips. Adding a law is adding one class.
#pragma once

#include <memory>
#include <vector>

#include "friction_sim/scene/scene.h"

namespace friction {

class FrictionLaw {
 public:
  virtual ~FrictionLaw() = default;

  /// Sizes the per-node state for `node_count` interface nodes.
  virtual void resize(int node_count) = 0;
  /// µ_s of `node`: it unsticks when the force needed to hold it exceeds µ_s·N.
  virtual double staticCoefficient(int node) const = 0;
  /// µ while `node` slides: friction is −µ·N·sgn(v).
  virtual double slidingCoefficient(int node) const = 0;
  /// `node` has just unstuck.
  virtual void onUnstick(int node) = 0;
  /// `node` slid by |slip| (m): during the last step, or in the catch-up of a node that unstuck within it.
  virtual void onSlip(int node, double slip) = 0;
  /// True if every node has the same µ_s and the same sliding µ at all times: the friction loop then
  /// reads two numbers rather than two per-node arrays.
  virtual bool uniform() const { return false; }
};

/// Amontons–Coulomb: µ_s to start, constant µ_k while sliding.
class AmontonsCoulomb : public FrictionLaw {
 public:
  AmontonsCoulomb(double static_coefficient, double kinetic_coefficient);
  void resize(int) override {}
  double staticCoefficient(int) const override { return static_; }
  double slidingCoefficient(int) const override { return kinetic_; }
  void onUnstick(int) override {}
  void onSlip(int, double) override {}
  bool uniform() const override { return true; }

 private:
  double static_, kinetic_;
};

/// Linear slip weakening: µ(δ) = µ_s − (µ_s − µ_k)·min(δ/ξ_µ, 1), δ = slip since the node last unstuck.
/// Landing sliding after a loss of contact counts as unsticking: the new contact starts unweakened.
class LinearSlipWeakening : public FrictionLaw {
 public:
  LinearSlipWeakening(double static_coefficient, double kinetic_coefficient, double weakening_length);
  void resize(int node_count) override { slip_since_unstick_.assign(node_count, 0.0); }
  double staticCoefficient(int) const override { return static_; }
  double slidingCoefficient(int node) const override;
  void onUnstick(int node) override { slip_since_unstick_[node] = 0.0; }
  void onSlip(int node, double slip) override;

 private:
  double static_, kinetic_, weakening_length_;
  std::vector<double> slip_since_unstick_;  ///< m, δ per node
};

std::unique_ptr<FrictionLaw> buildFrictionLaw(const FrictionSpec& spec);

}  // namespace friction
