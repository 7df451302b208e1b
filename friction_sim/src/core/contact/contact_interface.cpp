#include "friction_sim/contact/contact_interface.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>

namespace friction {

namespace {
/// The friction mode of a stuck node (see ContactInterface::friction_mode_).
constexpr double kStuckMode = 2.0;
}  // namespace

ContactInterface::ContactInterface(std::unique_ptr<FrictionLaw> law, const Model& model, double tangential_stiffness)
    : law_(std::move(law)),
      uniform_law_(law_->uniform()),
      ageing_law_(law_->ages()),
      rate_dependent_law_(law_->rateDependent()),
      k_t_(tangential_stiffness) {
  const int n = model.interfaceNodeCount();
  for (int node = 0; node < n; ++node) dofs_.push_back(model.interfaceDof(node));
  first_dof_ = n > 0 ? dofs_[0] : 0;
  for (int node = 0; node < n; ++node) {
    if (dofs_[node] != first_dof_ + node) throw std::logic_error("interface degrees of freedom must be contiguous");
  }
  law_->resize(n);
  state_.assign(n, ContactState::Stuck);
  friction_mode_.assign(n, kStuckMode);
  static_coefficient_.assign(n, 0.0);
  sliding_coefficient_.assign(n, 0.0);
  anchor_.assign(n, 0.0);
  for (auto& slot : friction_) slot.assign(n, 0.0);
  update_normal_ = Vector::Zero(n);
  latest_normal_ = update_normal_.data();
  other_force_.assign(n, 0.0);
  slip_origin_.assign(n, 0.0);
  just_unstuck_.assign(n, 0);
  landed_sliding_.assign(n, 0);
  transition_fraction_.assign(n, 1.0);
  start_u_.assign(n, 0.0);
  start_v_.assign(n, 0.0);
  start_friction_.assign(n, 0.0);
  for (int node = 0; node < n; ++node) refreshCoefficients(node);
}

void ContactInterface::setState(int node, ContactState state) {
  sliding_count_ += (state == ContactState::Sliding) - (state_[node] == ContactState::Sliding);
  const int lifts = (state == ContactState::Detached) - (state_[node] == ContactState::Detached);
  detached_count_ += lifts;
  contact_changes_ += lifts != 0;
  state_[node] = state;
  friction_mode_[node] = state == ContactState::Stuck ? kStuckMode : 0.0;  // startSliding sets the direction
}

void ContactInterface::refreshCoefficients(int node) {
  static_coefficient_[node] = law_->staticCoefficient(node);
  sliding_coefficient_[node] = law_->slidingCoefficient(node);
}

void ContactInterface::reset(const Vector& u) {
  law_->resize(size());
  for (int node = 0; node < size(); ++node) {
    setState(node, ContactState::Stuck);
    anchor_[node] = u[dofs_[node]];
    slip_origin_[node] = u[dofs_[node]];
    just_unstuck_[node] = 0;
    landed_sliding_[node] = 0;
    clearLoad(node);
    refreshCoefficients(node);
  }
  unstuck_last_step_.clear();
  restuck_last_step_.clear();
  dissipation_ = 0.0;
  start_positions_kept_ = false;  // every node is stuck where it is
}

namespace {
/// The friction rules in branch-free form, so that the loops over the nodes vectorise: a stuck node
/// carries what holds it (weight 1), a sliding one −µ·N·sgn(v) (sign ±1); a detached node has both
/// weights zero. The weights are decoded from the node's friction mode.
inline double stuckWeight(double mode) { return mode == kStuckMode ? 1.0 : 0.0; }
inline double slidingSign(double mode) { return mode == kStuckMode ? 0.0 : mode; }
inline double frictionOf(double stuck_weight, double holding, double sliding_coefficient, double normal,
                         double sliding_sign) {
  return stuck_weight * holding - sliding_coefficient * normal * sliding_sign;
}
/// Turns every node's other force into its acceleration: records the force in `other` and the friction
/// in `friction`, and overwrites `force_to_acceleration` with (other force + friction)·inverse_mass.
/// The force that holds a stuck node is its anchor spring's or, with rigid sticking (k_T = 0), the
/// reaction to every other force; then anchors and displacements are not read. With kUniform, every
/// node has the first node's µ_s and sliding µ (FrictionLaw::uniform). Returns how many nodes
/// need one of the state rules: a stuck node in contact whose holding force exceeds its threshold µ_s·N,
/// a node losing contact or a detached node regaining it. Branch-free and in one pass. A function of its
/// own because GCC honours restrict only on parameters; without it the loop needs more run-time alias
/// checks than GCC allows and is left scalar.
template <bool kRigid, bool kUniform>
std::int64_t frictionPass(int n, double k_t, double inverse_mass, const double* __restrict x,
                          const double* __restrict anchor, const double* __restrict normal,
                          const double* __restrict static_mu, const double* __restrict mu,
                          const double* __restrict mode, double* __restrict other, double* __restrict friction,
                          double* __restrict force_to_acceleration) {
  // Counted in 64 bits, the width of every other lane of the loop: a mix of widths costs conversions.
  std::int64_t attention = 0;
  if (n <= 0) return attention;
  const double uniform_static_mu = static_mu[0], uniform_mu = mu[0];
  for (int node = 0; node < n; ++node) {
    const double node_static_mu = kUniform ? uniform_static_mu : static_mu[node];
    const double node_mu = kUniform ? uniform_mu : mu[node];
    const double stuck = stuckWeight(mode[node]), sign = slidingSign(mode[node]);
    const double force = force_to_acceleration[node];
    other[node] = force;
    // 0 − force rather than −force: a node with no force carries +0, not −0 (as a written result).
    const double holding = kRigid ? 0.0 - force : k_t * (anchor[node] - x[node]);
    friction[node] = frictionOf(stuck, holding, node_mu, normal[node], sign);
    force_to_acceleration[node] = (force + friction[node]) * inverse_mass;
    // The flags are integers, combined with & and | rather than && and ||: GCC may not compute a
    // floating-point comparison or product that a branch would skip (it could trap), so with && the
    // loop vectorises only with AVX-512's masks and stays scalar with AVX2.
    const std::int64_t in_contact = normal[node] > 0.0;
    const std::int64_t attached = mode[node] != 0.0;  // stuck or sliding
    const std::int64_t over_threshold = std::abs(friction[node]) > node_static_mu * normal[node];
    attention += ((stuck > 0.0) & in_contact & over_threshold) | (in_contact ^ attached);
  }
  return attention;
}
}  // namespace

void ContactInterface::lendNormalStorage(Vector& normal_forces) {
  if (!normals_to_take_) return;
  normals_to_take_ = false;
  if (normal_forces.data() == latest_normal_) {
    update_normal_.swap(normal_forces);
  } else if (latest_normal_ != update_normal_.data()) {
    update_normal_ = Eigen::Map<const Vector>(latest_normal_, size());
  }
  latest_normal_ = update_normal_.data();
}

void ContactInterface::accelerateWithFriction(const double* u, const double* normal, double inverse_mass,
                                              double* force_to_acceleration, int first_node, int end_node) {
  const int offset = first_dof_ + first_node;
  // The ranges of one evaluation come in order from node 0.
  if (first_node == 0) attention_ = 0;
  latest_slot_ = current_slot_;
  latest_normal_ = normal;
  auto* pass = k_t_ <= 0.0 ? (uniform_law_ ? frictionPass<true, true> : frictionPass<true, false>)
                           : (uniform_law_ ? frictionPass<false, true> : frictionPass<false, false>);
  attention_ +=
      pass(end_node - first_node, k_t_, inverse_mass, u + offset, anchor_.data() + first_node, normal + first_node,
           static_coefficient_.data() + first_node, sliding_coefficient_.data() + first_node,
           friction_mode_.data() + first_node, other_force_.data() + first_node,
           friction_[current_slot_].data() + first_node, force_to_acceleration + offset);
}

void ContactInterface::applyFriction(const ForceEvaluation& raw, const Vector& u, const Vector& v, double inverse_mass,
                                     Vector& force, int first_node, int end_node, double closing_kick) {
  if (normals_to_take_ && raw.normal_force.data() == latest_normal_) {
    throw std::logic_error(
        "ContactInterface::applyFriction: normal forces evaluated over those of the last state update, which "
        "the next update needs; call lendNormalStorage before the evaluation");
  }
  accelerateWithFriction(u.data(), raw.normal_force.data(), inverse_mass, force.data(), first_node, end_node);
  if (rate_dependent_law_ && sliding_count_ > 0) {
    solveSlidingFriction(v.data(), closing_kick, inverse_mass, force.data(), first_node, end_node);
  }
}

void ContactInterface::reapplyFriction(const Vector& u, const Vector& v, double inverse_mass, Vector& acceleration) {
  std::copy_n(other_force_.data(), size(), acceleration.data() + first_dof_);
  accelerateWithFriction(u.data(), latest_normal_, inverse_mass, acceleration.data(), 0, size());
  if (rate_dependent_law_ && sliding_count_ > 0) {
    solveSlidingFriction(v.data(), 0.0, inverse_mass, acceleration.data(), 0, size());
  }
}

void ContactInterface::solveSlidingFriction(const double* v, double closing_kick, double inverse_mass,
                                            double* force_to_acceleration, int first_node, int end_node) {
  // An explicit µ(v) at the kick's start would act as a damper of a·N/v* on the node: unstable at any
  // usable step. The node's speed at the kick's end and its friction are solved together instead.
  const double kick_per_force = closing_kick * inverse_mass;  // m/s per N
  for (int node = first_node; node < end_node; ++node) {
    if (state_[node] != ContactState::Sliding) continue;
    const int dof = first_dof_ + node;
    const double direction = friction_mode_[node];
    const double normal = latest_normal_[node];
    const double reach = direction * (v[dof] + kick_per_force * other_force_[node]);
    const double speed =
        closing_kick > 0.0 ? law_->endSpeed(node, reach, kick_per_force * normal, direction * v[dof]) : reach;
    const double mu = law_->coefficientAt(node, std::max(speed, 0.0));
    sliding_coefficient_[node] = mu;
    friction_[current_slot_][node] = -mu * normal * direction;
    force_to_acceleration[dof] = (other_force_[node] + friction_[current_slot_][node]) * inverse_mass;
  }
}

void ContactInterface::refreshStaticCoefficients() {
  for (int node = 0; node < size(); ++node) {
    if (state_[node] == ContactState::Stuck) static_coefficient_[node] = law_->staticCoefficient(node);
  }
}

void ContactInterface::beginStep(const Vector& u, const Vector& v) {
  restuck_last_step_.clear();
  const int n = size();
  start_positions_kept_ = k_t_ > 0.0 || !allStuck();
  if (start_positions_kept_) std::copy_n(u.data() + first_dof_, n, start_u_.data());
  // Only finishStep() reads the rest, and only after a step that began with a node sliding. No state
  // changes between the two, so the states it reads are still those of the step's start.
  if (sliding_count_ == 0) return;
  std::copy_n(v.data() + first_dof_, n, start_v_.data());
  start_friction_ = friction_[latest_slot_];
}

bool ContactInterface::finishStep(Vector& u, Vector& v, double dt) {
  bool changed = false;
  slip_changed_coefficients_ = false;
  if (sliding_count_ > 0) {
    for (int node = 0; node < size(); ++node) {
      // Re-sticking below changes only this node, so state_ still holds the step's start here.
      if (state_[node] != ContactState::Sliding) continue;
      changed = finishSlidingNode(node, u, v, dt) || changed;
    }
  }
  for (int node : unstuck_last_step_) just_unstuck_[node] = 0;  // the only nodes flagged
  return changed;
}

bool ContactInterface::finishSlidingNode(int node, Vector& u, Vector& v, double dt) {
  bool changed = false;
  const int dof = dofs_[node];
  const double direction = friction_mode_[node];  // ±1: it slides
  const double v_start = start_v_[node] * direction;
  const double v_end = v[dof] * direction;
  if (just_unstuck_[node]) {
    // It may not re-stick in this step, but friction must oppose its velocity (f = −µ·N·sgn v): had it
    // kept its direction while moving the other way, its velocity would never pass through zero in
    // that direction again, and friction would drive it on.
    if (v_end < 0.0) {
      friction_mode_[node] = -direction;
      changed = true;
    }
  } else if (v_start >= 0.0 && v_end <= 0.0) {
    // Velocity is close to linear in time over one step: stop where it crosses zero.
    restick(node, u, v, v_start > 0.0 ? v_start / (v_start - v_end) : 0.0, dt);
    changed = true;
  }
  countSlipOfStep(node, u);
  return changed;
}

void ContactInterface::restick(int node, Vector& u, Vector& v, double fraction, double dt) {
  const int dof = dofs_[node];
  u[dof] = start_u_[node] + 0.5 * start_v_[node] * fraction * dt;
  v[dof] = 0.0;
  setState(node, ContactState::Stuck);
  transition_fraction_[node] = fraction;
  clearLoad(node);
  restuck_last_step_.push_back(node);
  if (k_t_ > 0.0) {
    // Place the anchor so that the friction force is continuous; that spring energy has to come
    // from somewhere in the bookkeeping, and friction is where the model puts it.
    anchor_[node] = u[dof] + start_friction_[node] / k_t_;
    dissipation_ -= 0.5 * start_friction_[node] * start_friction_[node] / k_t_;
  } else {
    anchor_[node] = u[dof];
  }
}

void ContactInterface::countSlipOfStep(int node, const Vector& u) {
  // The work of the friction the step applied, by the trapezoid as velocity Verlet applies it: its
  // value at the step's start and at its end, where it slid on (slip weakening lowers it within the
  // step, to first order in dt). One that stopped within the step had the start's friction up to the
  // stop.
  const double end_friction =
      state_[node] == ContactState::Sliding ? friction_[latest_slot_][node] : start_friction_[node];
  const double slip = u[dofs_[node]] - start_u_[node];
  dissipation_ -= 0.5 * (start_friction_[node] + end_friction) * slip;
  const double sliding_before = sliding_coefficient_[node];
  addSlip(node, slip);
  // Fully weakened (or under a law without slip) the coefficient stays: nothing to apply again.
  slip_changed_coefficients_ = slip_changed_coefficients_ || sliding_coefficient_[node] != sliding_before;
}

void ContactInterface::stick(int node, const Vector& u) {
  setState(node, ContactState::Stuck);
  anchor_[node] = u[dofs_[node]];
  clearLoad(node);
}

void ContactInterface::addSlip(int node, double slip) {
  law_->onSlip(node, slip);
  refreshCoefficients(node);
}

void ContactInterface::clearLoad(int node) {
  // Both buffers: a node that sticks again before the state update (finishStep) has its load at the
  // update's previous slot; one that sticks during it, at the slot that becomes the previous one.
  friction_[0][node] = friction_[1][node] = 0.0;
}

void ContactInterface::startSliding(int node, int direction) {
  setState(node, ContactState::Sliding);
  friction_mode_[node] = direction;
  just_unstuck_[node] = 1;
  law_->onUnstick(node);
  refreshCoefficients(node);
  unstuck_last_step_.push_back(node);
}

void ContactInterface::rotateLoads() {
  current_slot_ ^= 1;  // the slot written last stays the one read (latest_slot_) until the next pass
  normals_to_take_ = true;
}

bool ContactInterface::updateStates(Vector& u, Vector& v, double dt, double node_mass) {
  // Also when no step came between updates.
  for (int node : unstuck_last_step_) just_unstuck_[node] = landed_sliding_[node] = 0;
  unstuck_last_step_.clear();
  // The last friction pass recorded every node's load and whether any node needs one of the rules
  // below. Usually none does, and the step ends here.
  if (attention_ == 0) {
    rotateLoads();
    return false;
  }
  if (ageing_law_) refreshStaticCoefficients();
  bool changed = false;
  for (int node = 0; node < size(); ++node) {
    const double normal = latest_normal_[node];
    if (normal <= 0.0) {
      changed = loseContact(node, u) || changed;
    } else if (state_[node] == ContactState::Detached) {
      regainContact(node, u, v);
      changed = true;
    } else if (state_[node] == ContactState::Stuck && overThreshold(node, normal)) {
      unstick(node, u, v, dt, node_mass);
      changed = true;
    }
  }
  rotateLoads();
  return changed;
}

bool ContactInterface::overThreshold(int node, double normal) const {
  return !(std::abs(friction_[current_slot_][node]) <= static_coefficient_[node] * normal);
}

bool ContactInterface::loseContact(int node, const Vector& u) {
  if (state_[node] == ContactState::Detached) return false;
  if (state_[node] == ContactState::Stuck) dissipation_ += 0.5 * k_t_ * std::pow(anchor_[node] - u[dofs_[node]], 2);
  setState(node, ContactState::Detached);
  return true;
}

void ContactInterface::regainContact(int node, const Vector& u, const Vector& v) {
  // Contact returns as this update sees it, at the step's end; the fraction of its last transition is
  // stale.
  transition_fraction_[node] = 1.0;
  law_->onLanding(node);
  refreshCoefficients(node);
  const double velocity = v[dofs_[node]];
  if (velocity != 0.0) {
    startSliding(node, velocity > 0.0 ? 1 : -1);
    landed_sliding_[node] = 1;
  } else {
    stick(node, u);
  }
}

void ContactInterface::unstick(int node, Vector& u, Vector& v, double dt, double node_mass) {
  const int dof = dofs_[node];
  const double normal = latest_normal_[node];
  const double held = std::abs(friction_[current_slot_][node]);
  const double ratio = held / (static_coefficient_[node] * normal);
  // Its load at the last update. A node stuck since then had contact there; a node that has just stuck
  // had its load cleared (0), but perhaps no contact there.
  const int previous_slot = current_slot_ ^ 1;
  const double previous_threshold = static_coefficient_[node] * update_normal_[node];
  const double previous_ratio =
      previous_threshold > 0.0 ? std::abs(friction_[previous_slot][node]) / previous_threshold : 0.0;
  transition_fraction_[node] =
      previous_ratio < 1.0 ? std::clamp((1.0 - previous_ratio) / (ratio - previous_ratio), 0.0, 1.0) : 0.0;
  // The spring energy of an elastic anchor is released into the slip.
  dissipation_ += 0.5 * k_t_ * std::pow(anchor_[node] - u[dof], 2);
  // It slides opposite to the friction that held it.
  startSliding(node, friction_[current_slot_][node] > 0.0 ? -1 : 1);
  const double late = (1.0 - transition_fraction_[node]) * dt;
  // At the coefficient of the moment it unstuck: weakening within the catch-up itself (a fraction of
  // one step's slip) is left out, in the motion and in the dissipation alike.
  const double sliding_friction = -sliding_coefficient_[node] * normal * friction_mode_[node];
  const double acceleration = (other_force_[node] + sliding_friction) / node_mass;
  const double catch_up = 0.5 * acceleration * late * late;
  if (!start_positions_kept_) start_u_[node] = u[dof];
  u[dof] += catch_up;
  v[dof] += acceleration * late;
  dissipation_ -= sliding_friction * catch_up;
  // Slip weakening counts the catch-up too: it is slip since unsticking that no step will measure.
  addSlip(node, catch_up);
}

bool ContactInterface::holdsPinned(const ForceEvaluation& trial, bool sliding_pinned) const {
  for (int node = 0; node < size(); ++node) {
    const double normal = trial.normal_force[node];
    if (state_[node] == ContactState::Detached) {
      if (normal > 0.0) return false;
    } else if (normal <= 0.0) {
      return false;
    } else if (!(sliding_pinned && state_[node] == ContactState::Sliding) &&
               std::abs(trial.force[dofs_[node]]) > law_->staticCoefficient(node) * normal) {
      return false;
    }
  }
  return true;
}

void ContactInterface::creep(int node, double slip, double end_friction) {
  dissipation_ -= 0.5 * (friction_[latest_slot_][node] + end_friction) * slip;
  addSlip(node, slip);
}

void ContactInterface::stopCreeping(int node, const Vector& u) {
  stick(node, u);
  transition_fraction_[node] = 1.0;
  restuck_last_step_.push_back(node);
}

double ContactInterface::anchorEnergy(const Vector& u) const {
  if (k_t_ <= 0.0) return 0.0;
  double energy = 0.0;
  for (int node = 0; node < size(); ++node) {
    if (state_[node] == ContactState::Stuck) energy += 0.5 * k_t_ * std::pow(anchor_[node] - u[dofs_[node]], 2);
  }
  return energy;
}

}  // namespace friction
