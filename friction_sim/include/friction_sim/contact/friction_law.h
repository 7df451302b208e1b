// Friction laws (MODEL.md §4). Every law shares the stuck/sliding states and the rules for leaving
// them (ContactInterface); a law only says how strong static and sliding friction are, and may keep
// per-node internal state that it updates as the node slips and as time passes. Adding a law is adding
// one class.
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

  // Laws whose state evolves with time, also at rest, and whose sliding µ depends on the slip speed.
  /// True if µ_s changes with time while a node is stuck: the interface then reads it afresh before it
  /// decides, and the fast-forward asks staticCoefficientAfter.
  virtual bool ages() const { return false; }
  /// True if the sliding µ depends on the slip speed: the interface solves it with the step's velocity.
  virtual bool rateDependent() const { return false; }
  /// s, the simulated time now. Set before every state update.
  virtual void setTime(double /*time*/) {}
  /// µ of `node` sliding at `speed` (m/s, ≥ 0), with its state now.
  virtual double coefficientAt(int node, double /*speed*/) const { return slidingCoefficient(node); }
  /// The speed y (m/s) at which `node` ends a step's closing kick, from y + resistance·µ(y) = reach: `reach`
  /// (m/s) is the speed it would reach without friction, `resistance` (m/s) the kick's speed per unit of
  /// µ (half the step times N over the node's mass). Negative if friction at rest, µ(0), stops it within
  /// the kick: reach − resistance·µ(0). `start_speed` (m/s, along the slip), the node's speed before the
  /// kick, is a first guess: it changes the answer within round-off only.
  virtual double endSpeed(int node, double reach, double resistance, double /*start_speed*/) const {
    return reach - resistance * coefficientAt(node, 0.0);
  }
  /// µ_s of `node` if it stays stuck for `elapsed` (s) more.
  virtual double staticCoefficientAfter(int node, double /*elapsed*/) const { return staticCoefficient(node); }
  /// µ of the sliding `node` at `speed` (m/s, ≥ 0) after it slid |`slip`| (m) more over `elapsed` (s), its
  /// state evolved over that slide as onSlip would evolve it.
  virtual double coefficientAfterSlip(int node, double speed, double /*slip*/, double /*elapsed*/) const {
    return coefficientAt(node, speed);
  }
  /// `node` touched the track again after a loss of contact: a new contact.
  virtual void onLanding(int /*node*/) {}
  /// The per-node state as numbers, for the run's state hash (empty: none).
  virtual std::vector<double> stateNumbers() const { return {}; }
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

/// Rate-and-state friction with the ageing law (RateStateSpec, MODEL.md §4). Each node keeps its contact
/// age φ as of a time; with no slip reported since, φ has grown by the time elapsed (dφ/dt = 1 at rest),
/// so that a stuck node, or every node across a fast-forward jump, ages exactly without being visited.
/// A step's slip s over Δt ages it by the ageing law's exact solution at the step's mean speed s/Δt.
class RateAndState : public FrictionLaw {
 public:
  explicit RateAndState(const RateStateSpec& spec) : spec_(spec) {}
  void resize(int node_count) override;
  double staticCoefficient(int node) const override { return spec_.staticCoefficient(age(node)); }
  /// µ at rest with the node's age: where a node that has just unstuck starts.
  double slidingCoefficient(int node) const override { return staticCoefficient(node); }
  void onUnstick(int node) override { settle(node); }
  void onSlip(int node, double slip) override;
  bool ages() const override { return true; }
  bool rateDependent() const override { return true; }
  void setTime(double time) override { now_ = time; }
  double coefficientAt(int node, double speed) const override { return spec_.coefficient(speed, age(node)); }
  double endSpeed(int node, double reach, double resistance, double start_speed) const override;
  double staticCoefficientAfter(int node, double elapsed) const override {
    return spec_.staticCoefficient(age(node) + elapsed);
  }
  double coefficientAfterSlip(int node, double speed, double slip, double elapsed) const override {
    return spec_.coefficient(speed, spec_.ageAfterSlip(age(node), slip, elapsed));
  }
  void onLanding(int node) override;
  std::vector<double> stateNumbers() const override;
  /// s, φ of `node` now.
  double age(int node) const { return age_[node] + (now_ - since_[node]); }

 private:
  /// Makes `node`'s age as of now its recorded one.
  void settle(int node);

  RateStateSpec spec_;
  double now_ = 0.0;           ///< s
  std::vector<double> age_;    ///< s, φ per node as of since_
  std::vector<double> since_;  ///< s, when age_ was recorded
};

std::unique_ptr<FrictionLaw> buildFrictionLaw(const FrictionSpec& spec);

}  // namespace friction
