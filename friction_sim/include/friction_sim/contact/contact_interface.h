// The stick/slip rules of MODEL.md §4, written once for every friction law:
//  - stuck: the node holds (rigidly, or through the interfacial spring k_T to its anchor) as long as the
//    force needed stays within µ_s·N;
//  - unstick: at the end of a step where the force needed exceeds µ_s·N; the node then slides in the
//    direction of that force;
//  - sliding: f = −µ·N·sgn(v) with µ from the law, the direction fixed at the start of the step;
//  - re-stick: when the velocity passes through zero within a step; the node stops at the interpolated
//    zero crossing, not a step late. A node that has just unstuck cannot re-stick in the same step;
//  - loss of contact: with N = 0 the node is detached and carries no friction; it slides (or sticks, if
//    at rest) again when contact returns.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "friction_sim/contact/friction_law.h"
#include "friction_sim/model/model.h"

namespace friction {

enum class ContactState : std::uint8_t { Stuck = 0, Sliding = 1, Detached = 2 };

class ContactInterface {
 public:
  /// `tangential_stiffness` is k_T (N/m); 0 makes stuck nodes rigid.
  ContactInterface(std::unique_ptr<FrictionLaw> law, const Model& model, double tangential_stiffness);

  /// Sticks every node where it is, with no stored interfacial shear and slip measured from here. The
  /// interface must be at rest: a node sticks only with no velocity (so that a step does not move it).
  void reset(const Vector& u);

  /// Call before evaluating into `normal_forces` the normal forces that applyFriction will read. The
  /// interface reads them where the evaluation put them rather than copying them; after a state update
  /// it keeps the update's normal forces (needed by the next update) by taking their storage in exchange
  /// for spare storage of the same size. applyFriction refuses normal forces rewritten in place without
  /// this call.
  void lendNormalStorage(Vector& normal_forces);
  /// `force` holds every force but friction on the degrees of freedom (N). Records the interface
  /// entries of nodes [first_node, end_node) for the state updates, and rewrites those entries as
  /// accelerations (m/s²): (force + friction)·`inverse_mass`. The other entries are left to the caller.
  /// Nodes are independent here, so a caller may go range by range. `raw.normal_force` must stay
  /// unchanged until the next evaluation (see lendNormalStorage). A rate-dependent law's sliding
  /// friction is solved with the velocity the node ends the step with: `v` (m/s) is its velocity before
  /// the step's closing kick of `closing_kick` (s, half the step; 0 outside a step, where `v` is final).
  void applyFriction(const ForceEvaluation& raw, const Vector& u, const Vector& v, double inverse_mass, Vector& force,
                     int first_node, int end_node, double closing_kick);
  /// The same for every interface node, outside a step.
  void applyFriction(const ForceEvaluation& raw, const Vector& u, const Vector& v, double inverse_mass, Vector& force) {
    applyFriction(raw, u, v, inverse_mass, force, 0, size(), 0.0);
  }
  /// After a change of state: recomputes the friction from the recorded forces and rewrites the
  /// interface entries of `acceleration` (m/s²) as (other force + friction)·`inverse_mass`.
  void reapplyFriction(const Vector& u, const Vector& v, double inverse_mass, Vector& acceleration);
  /// s, the simulated time now: a law whose state evolves in time reads it. Set whenever the clock moves.
  void setTime(double time) { law_->setTime(time); }

  /// Remembers the interface at the start of a step.
  void beginStep(const Vector& u, const Vector& v);
  /// After the integrator's step: stops nodes whose velocity passed through zero at the interpolated
  /// crossing, accounts friction dissipation and slip. A node in the step right after it unstuck may not
  /// re-stick; if its velocity turned in that step, it slides the other way from then on. Returns true if
  /// any node's friction changed (it re-stuck or turned).
  bool finishStep(Vector& u, Vector& v, double dt);
  /// The last finishStep's slip changed sliding coefficients (a slip-dependent law): the friction of the
  /// step's end must be applied again (reapplyFriction) before the next step uses it.
  bool slipChangedCoefficients() const { return slip_changed_coefficients_; }
  /// After the last force evaluation of a step of length dt and its applyFriction at these displacements
  /// (the stuck nodes' loads are its friction forces): loss and return of
  /// contact, unsticking. A node that crossed its threshold at a fraction s of the step is given the
  /// motion it would have made sliding for the rest of the step, (1 − s)·dt, so that slip starts on time
  /// rather than up to a step late. Returns true if any node changed state (its friction must then be
  /// re-applied).
  bool updateStates(Vector& u, Vector& v, double dt, double node_mass);

  // Quasi-static creep (QuasiStaticCreep): a node slides so slowly that its friction balances its load, and
  // the slider moves through equilibria rather than by steps.
  /// The sliding `node` slid `slip` (m) while its friction went from its value now to `end_friction` (N):
  /// the law learns of the slip, and its work (by the trapezoid) is dissipated.
  void creep(int node, double slip, double end_friction);
  /// The creeping `node` stops where it is, at the end of the last advance.
  void stopCreeping(int node, const Vector& u);
  /// ±1, the direction in which the sliding `node` moves.
  int slidingDirection(int node) const { return static_cast<int>(friction_mode_[node]); }

  int size() const { return static_cast<int>(state_.size()); }
  /// The first interface degree of freedom; the others follow it contiguously.
  int firstDof() const { return first_dof_; }
  ContactState state(int node) const { return state_[node]; }
  int slidingCount() const { return sliding_count_; }
  /// True when every node is stuck (none sliding, none detached).
  bool allStuck() const { return sliding_count_ == 0 && detached_count_ == 0; }
  int detachedCount() const { return detached_count_; }
  /// Lift-offs and landings so far (a count that only grows: a lift-off and a landing in one step both count).
  long long contactChanges() const { return contact_changes_; }
  /// Whether an equilibrium found with the stuck nodes pinned keeps them stuck, each in contact and its
  /// pin's reaction, −trial.force at its dof, within µ_s·N, and keeps every detached node off the track.
  /// With `sliding_pinned`, sliding nodes were pinned too, and need only stay in contact (they creep).
  bool holdsPinned(const ForceEvaluation& trial, bool sliding_pinned = false) const;
  double frictionForce(int node) const { return friction_[latest_slot_][node]; }  ///< N, track on slider, x
  double normalForce(int node) const { return latest_normal_[node]; }             ///< N
  double slip(int node, const Vector& u) const { return u[dofs_[node]] - slip_origin_[node]; }  ///< m
  /// m, the node's x displacement at the start of the last step (before any unstick catch-up), given
  /// the displacements `u` after it.
  double stepStartPosition(int node, const Vector& u) const {
    return start_positions_kept_ || just_unstuck_[node] ? start_u_[node] : u[dofs_[node]];
  }
  /// N, the friction a node that unstuck in the last step held as it crossed its threshold: µ_s·N
  /// against the direction it now slides.
  double thresholdFriction(int node) const {
    return -friction_mode_[node] * static_coefficient_[node] * normalForce(node);
  }
  /// Of the nodes in unstuckLastStep: this one landed on the track while moving, and crossed no threshold.
  bool landedSliding(int node) const { return landed_sliding_[node] != 0; }
  /// m, the slip of a node that unstuck in the last step as it unstuck, without the catch-up it was given
  /// for the rest of the step.
  double slipAtUnsticking(int node, const Vector& u) const { return stepStartPosition(node, u) - slip_origin_[node]; }
  /// Nodes that unstuck (or slid off on returning contact) at the end of the last step.
  const std::vector<int>& unstuckLastStep() const { return unstuck_last_step_; }
  /// Nodes that re-stuck during the last step.
  const std::vector<int>& restuckLastStep() const { return restuck_last_step_; }
  /// Fraction of the last step (0..1) at which `node` crossed its threshold (unstuck) or its velocity
  /// crossed zero (re-stuck), interpolated linearly, so that event times are not quantised by dt.
  double transitionFraction(int node) const { return transition_fraction_[node]; }
  /// J, energy dissipated by friction since reset (includes energy released by k_T anchors).
  double frictionDissipation() const { return dissipation_; }
  /// J, energy stored in the k_T anchor springs.
  double anchorEnergy(const Vector& u) const;
  const FrictionLaw& law() const { return *law_; }
  /// The interface nodes' x degrees of freedom: contiguous, dofs()[node] = dofs()[0] + node.
  const std::vector<int>& dofs() const { return dofs_; }

 private:
  /// The only place a node's state changes: keeps the per-node weights of applyFriction in step.
  void setState(int node, ContactState state);
  void stick(int node, const Vector& u);
  void startSliding(int node, int direction);
  // The rules of finishStep for a node that slid through the step: its direction or re-sticking, then
  // the work and slip of its friction.
  bool finishSlidingNode(int node, Vector& u, Vector& v, double dt);
  /// Sticks `node` where its velocity crossed zero, at `fraction` of the step.
  void restick(int node, Vector& u, Vector& v, double fraction, double dt);
  void countSlipOfStep(int node, const Vector& u);
  // The rules of updateStates: contact lost, contact regained, a stuck node over its threshold (which
  // then slides for the rest of the step from its crossing).
  bool loseContact(int node, const Vector& u);
  /// True if a stuck node's load exceeds µ_s·`normal` (N).
  bool overThreshold(int node, double normal) const;
  void regainContact(int node, const Vector& u, const Vector& v);
  void unstick(int node, Vector& u, Vector& v, double dt, double node_mass);
  /// The law's coefficients for `node` after its state or slip changed.
  void refreshCoefficients(int node);
  /// `node` slid by `slip` (m): the law learns of it and its coefficients follow.
  void addSlip(int node, double slip);
  /// Forgets a node's load history (it has just stuck).
  void clearLoad(int node);
  /// At the end of a state update: its loads become the next update's previous ones.
  void rotateLoads();
  /// Records the interface entries of nodes [first_node, end_node) of `force_to_acceleration` (N, every
  /// force but friction) as the other forces and `normal` (N, indexed by node, all nodes) as the latest
  /// normal forces; computes the friction in the current slot from them, and overwrites those entries
  /// with accelerations (m/s²), (other force + friction)·`inverse_mass`.
  void accelerateWithFriction(const double* u, const double* normal, double inverse_mass, double* force_to_acceleration,
                              int first_node, int end_node);
  /// For a rate-dependent law: the friction of the sliding nodes among [first_node, end_node), solved
  /// with the velocity each ends the closing kick with (applyFriction), and their accelerations.
  void solveSlidingFriction(const double* v, double closing_kick, double inverse_mass, double* force_to_acceleration,
                            int first_node, int end_node);
  /// For a law that ages: every stuck node's µ_s as of now.
  void refreshStaticCoefficients();

  std::unique_ptr<FrictionLaw> law_;
  bool uniform_law_;  ///< law_->uniform(), asked once
  // law_->ages() and law_->rateDependent(), asked once. With an ageing law µ_s grows while a node is
  // stuck: the friction pass compares loads with µ_s as last read (never above its value now), and the
  // state update reads it afresh before it decides.
  bool ageing_law_, rate_dependent_law_;
  bool slip_changed_coefficients_ = false;
  std::vector<int> dofs_;
  int first_dof_;
  double k_t_;
  std::vector<ContactState> state_;
  int sliding_count_ = 0, detached_count_ = 0;
  long long contact_changes_ = 0;
  // Per node, in the form the friction loop needs: its mode, 2 if stuck, the sliding direction
  // ±1 if sliding, 0 if detached (one array rather than a stuck weight and a sign: the loop is bound by
  // memory traffic); the law's µ_s and current sliding µ.
  std::vector<double> friction_mode_, static_coefficient_, sliding_coefficient_;
  std::vector<double> anchor_;  ///< m, where a stuck node is held
  // Friction (N) of every node in two slots: the friction passes write the current one; the other keeps
  // it as it was at the last state update, when the next update needs it to interpolate a threshold
  // crossing. A stuck node's load is its friction against µ_s·N.
  std::array<std::vector<double>, 2> friction_;
  int current_slot_ = 0;
  int latest_slot_ = 0;  ///< the slot the last friction pass wrote (the readings come from it)
  /// N, every node's normal force as the last friction pass read it, in the caller's evaluation.
  const double* latest_normal_;
  /// N, the normal forces of the last state update, once lendNormalStorage has taken them over; before
  /// that, spare storage. Zero before the first update.
  Vector update_normal_;
  /// Whether a state update happened since the last lendNormalStorage: the update's normal forces are
  /// then still in the evaluation's storage, and the next one must not overwrite them in place.
  bool normals_to_take_ = false;
  std::vector<double> other_force_;   ///< N, tangential force on the node from everything but friction
  std::vector<double> slip_origin_;   ///< m
  std::vector<char> just_unstuck_;    ///< 1 for the nodes in unstuck_last_step_, else 0
  std::vector<char> landed_sliding_;  ///< 1 for those of them that landed moving, else 0
  std::vector<int> unstuck_last_step_, restuck_last_step_;
  std::vector<double> transition_fraction_;
  std::int64_t attention_ = 0;  ///< nodes that needed a state rule at the last friction pass
  // Start-of-step copies for re-stick interpolation and dissipation.
  std::vector<double> start_u_, start_v_, start_friction_;
  // Whether the last step kept every node's start position. A rigidly stuck node does not move in a
  // step (it has no velocity and an acceleration of exactly 0), so while every node sticks rigidly the
  // copy is skipped: a node's start position is where it still is, or, for one that unsticks at the
  // step's end, where it was before its catch-up.
  bool start_positions_kept_ = true;
  double dissipation_ = 0.0;
};

}  // namespace friction
