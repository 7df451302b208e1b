#include "friction_sim/contact_interface.h"

#include <algorithm>
#include <cmath>

namespace friction {

ContactInterface::ContactInterface(std::unique_ptr<FrictionLaw> law, const Model& model,
                                   double tangential_stiffness)
    : law_(std::move(law)), k_t_(tangential_stiffness) {
  const int n = model.interfaceNodeCount();
  for (int node = 0; node < n; ++node) dofs_.push_back(model.interfaceDof(node));
  law_->resize(n);
  state_.assign(n, ContactState::Stuck);
  direction_.assign(n, 1);
  anchor_.assign(n, 0.0);
  friction_.assign(n, 0.0);
  normal_.assign(n, 0.0);
  other_force_.assign(n, 0.0);
  slip_origin_.assign(n, 0.0);
  just_unstuck_.assign(n, 0);
  transition_fraction_.assign(n, 1.0);
  load_ratio_.assign(n, 0.0);
  start_u_.assign(n, 0.0);
  start_v_.assign(n, 0.0);
  start_friction_.assign(n, 0.0);
  start_state_.assign(n, ContactState::Stuck);
}

void ContactInterface::reset(const Vector& u) {
  for (int node = 0; node < size(); ++node) {
    state_[node] = ContactState::Stuck;
    anchor_[node] = u[dofs_[node]];
    slip_origin_[node] = u[dofs_[node]];
    just_unstuck_[node] = 0;
    load_ratio_[node] = 0.0;
  }
  law_->resize(size());
  unstuck_last_step_.clear();
  restuck_last_step_.clear();
  dissipation_ = 0.0;
}

void ContactInterface::applyFriction(const ForceEvaluation& raw, const Vector& u, Vector& force) {
  for (int node = 0; node < size(); ++node) {
    const int dof = dofs_[node];
    other_force_[node] = raw.force[dof];
    normal_[node] = raw.normal_force[node];
    double f = 0.0;
    switch (state_[node]) {
      case ContactState::Stuck:
        f = k_t_ > 0.0 ? k_t_ * (anchor_[node] - u[dof]) : -other_force_[node];
        break;
      case ContactState::Sliding:
        f = -law_->slidingCoefficient(node) * normal_[node] * direction_[node];
        break;
      case ContactState::Detached:
        break;
    }
    friction_[node] = f;
    force[dof] += f;
  }
}

void ContactInterface::beginStep(const Vector& u, const Vector& v) {
  restuck_last_step_.clear();
  for (int node = 0; node < size(); ++node) {
    start_u_[node] = u[dofs_[node]];
    start_v_[node] = v[dofs_[node]];
    start_friction_[node] = friction_[node];
    start_state_[node] = state_[node];
  }
}

bool ContactInterface::finishStep(Vector& u, Vector& v, double dt) {
  bool restuck = false;
  for (int node = 0; node < size(); ++node) {
    if (start_state_[node] != ContactState::Sliding) continue;
    const int dof = dofs_[node];
    const double v_start = start_v_[node] * direction_[node];
    const double v_end = v[dof] * direction_[node];
    if (!just_unstuck_[node] && v_start > 0.0 && v_end <= 0.0) {
      // Velocity is close to linear in time over one step: stop where it crosses zero.
      const double fraction = v_start / (v_start - v_end);
      u[dof] = start_u_[node] + 0.5 * start_v_[node] * fraction * dt;
      v[dof] = 0.0;
      state_[node] = ContactState::Stuck;
      transition_fraction_[node] = fraction;
      load_ratio_[node] = 0.0;
      restuck_last_step_.push_back(node);
      if (k_t_ > 0.0) {
        // Place the anchor so that the friction force is continuous; that spring energy has to come
        // from somewhere in the bookkeeping, and friction is where the model puts it.
        anchor_[node] = u[dof] + start_friction_[node] / k_t_;
        dissipation_ -= 0.5 * start_friction_[node] * start_friction_[node] / k_t_;
      } else {
        anchor_[node] = u[dof];
      }
      restuck = true;
    }
    const double slip = u[dof] - start_u_[node];
    dissipation_ -= start_friction_[node] * slip;
    law_->onSlip(node, slip);
  }
  std::fill(just_unstuck_.begin(), just_unstuck_.end(), 0);
  return restuck;
}

void ContactInterface::stick(int node, const Vector& u) {
  state_[node] = ContactState::Stuck;
  anchor_[node] = u[dofs_[node]];
  load_ratio_[node] = 0.0;
}

void ContactInterface::startSliding(int node, int direction) {
  state_[node] = ContactState::Sliding;
  direction_[node] = direction;
  just_unstuck_[node] = 1;
  law_->onUnstick(node);
  unstuck_last_step_.push_back(node);
}

bool ContactInterface::updateStates(const ForceEvaluation& raw, Vector& u, Vector& v, double dt,
                                    double node_mass) {
  unstuck_last_step_.clear();
  bool changed = false;
  for (int node = 0; node < size(); ++node) {
    const int dof = dofs_[node];
    const double normal = raw.normal_force[node];
    if (normal <= 0.0) {
      if (state_[node] != ContactState::Detached) {
        if (state_[node] == ContactState::Stuck) dissipation_ += 0.5 * k_t_ * std::pow(anchor_[node] - u[dof], 2);
        state_[node] = ContactState::Detached;
        changed = true;
      }
      continue;
    }
    if (state_[node] == ContactState::Detached) {
      if (v[dof] != 0.0) {
        startSliding(node, v[dof] > 0.0 ? 1 : -1);
      } else {
        stick(node, u);
      }
      changed = true;
      continue;
    }
    if (state_[node] != ContactState::Stuck) continue;
    const double needed = k_t_ > 0.0 ? k_t_ * (anchor_[node] - u[dof]) : -raw.force[dof];
    const double ratio = std::abs(needed) / (law_->staticCoefficient(node) * normal);
    const double previous_ratio = load_ratio_[node];
    load_ratio_[node] = ratio;
    if (ratio > 1.0) {
      transition_fraction_[node] =
          previous_ratio < 1.0 ? std::clamp((1.0 - previous_ratio) / (ratio - previous_ratio), 0.0, 1.0) : 0.0;
      // The spring energy of an elastic anchor is released into the slip.
      dissipation_ += 0.5 * k_t_ * std::pow(anchor_[node] - u[dof], 2);
      startSliding(node, needed > 0.0 ? -1 : 1);
      const double late = (1.0 - transition_fraction_[node]) * dt;
      const double sliding_friction = -law_->slidingCoefficient(node) * normal * direction_[node];
      const double acceleration = (raw.force[dof] + sliding_friction) / node_mass;
      const double catch_up = 0.5 * acceleration * late * late;
      u[dof] += catch_up;
      v[dof] += acceleration * late;
      dissipation_ -= sliding_friction * catch_up;
      changed = true;
    }
  }
  return changed;
}

int ContactInterface::slidingCount() const {
  return static_cast<int>(std::count(state_.begin(), state_.end(), ContactState::Sliding));
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
