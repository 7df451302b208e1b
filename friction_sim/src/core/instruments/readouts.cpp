// What Simulation's instruments read off its state, and the state's hash.
#include <cstdint>

#include "friction_sim/run/simulation.h"

namespace friction {

LoadCellReading Simulation::loadCells() const {
  LoadCellReading reading;
  reading.time = time_;
  reading.stage_position = stage_.position();
  reading.shear_force = evaluation_.shear_force;
  reading.normal_force = evaluation_.normal_load;
  reading.interface_normal_sum = evaluation_.normal_force.sum();
  reading.sliding_nodes = contact_.slidingCount();
  return reading;
}

InterfaceFrame Simulation::interfaceFrame() const {
  InterfaceFrame frame;
  frame.time = time_;
  const double area = model_->interfaceNodeArea();
  for (int node = 0; node < contact_.size(); ++node) {
    const int dof = model_->interfaceDof(node);
    frame.position.push_back(model_->interfacePosition(node));
    frame.state.push_back(static_cast<std::uint8_t>(contact_.state(node)));
    frame.slip_velocity.push_back(v_[dof]);
    frame.slip.push_back(contact_.slip(node, u_));
    frame.normal_force.push_back(contact_.normalForce(node));
    frame.friction_force.push_back(contact_.frictionForce(node));
    frame.normal_stress.push_back(contact_.normalForce(node) / area);
    frame.shear_stress.push_back(-contact_.frictionForce(node) / area);
    frame.static_coefficient.push_back(contact_.law().staticCoefficient(node));
  }
  return frame;
}

InterfaceFrame Simulation::interfaceFrameBeforeUnsticking() const {
  InterfaceFrame frame = interfaceFrame();
  const double area = model_->interfaceNodeArea();
  for (int node : contact_.unstuckLastStep()) {
    if (contact_.landedSliding(node)) continue;
    frame.state[node] = static_cast<std::uint8_t>(ContactState::Stuck);
    frame.slip_velocity[node] = 0.0;
    frame.slip[node] = contact_.slipAtUnsticking(node, u_);
    frame.friction_force[node] = contact_.thresholdFriction(node);
    frame.shear_stress[node] = -frame.friction_force[node] / area;
  }
  return frame;
}

GaugeProfile Simulation::gaugeProfile() const {
  GaugeProfile profile;
  profile.time = time_;
  profile.height = scene_.instruments.gauge_height;
  profile.position = scene_.instruments.gauge_positions;
  if (profile.position.empty()) {
    for (int node = 0; node < model_->interfaceNodeCount(); ++node) {
      profile.position.push_back(model_->interfacePosition(node));
    }
  }
  profile.stress = model_->gaugeStresses(u_, profile.height, profile.position);
  return profile;
}

LatticeSnapshot Simulation::snapshot() const {
  LatticeSnapshot snapshot;
  snapshot.time = time_;
  const auto shape = model_->gridShape();
  snapshot.nodes_x = shape[0];
  snapshot.nodes_z = shape[1];
  snapshot.spacing = model_->nodeSpacing();
  model_->nodePositions(u_, snapshot.x, snapshot.z);
  snapshot.speed = model_->nodeSpeeds(v_);
  snapshot.stress = model_->nodeStresses(u_);
  for (int node = 0; node < contact_.size(); ++node) {
    snapshot.interface_state.push_back(static_cast<std::uint8_t>(contact_.state(node)));
  }
  snapshot.stage_position = stage_.position();
  snapshot.pusher_height = model_->pushingHeight();
  snapshot.normal_force = evaluation_.normal_load;
  return snapshot;
}

EnergyBudget Simulation::energy() const {
  return ledger_.budget(*model_, contact_, u_, stage_.position(), kineticEnergy());
}

std::uint64_t Simulation::stateHash() const {
  StateHash hash;
  hash.mix(&time_, sizeof time_);
  hash.mix(u_.data(), sizeof(double) * u_.size());
  hash.mix(v_.data(), sizeof(double) * v_.size());
  for (int node = 0; node < contact_.size(); ++node) {
    const auto state = contact_.state(node);
    hash.mix(&state, sizeof state);
  }
  // A law's own state (a contact's age), for the laws that keep one.
  const std::vector<double> law_state = contact_.law().stateNumbers();
  hash.mix(law_state.data(), sizeof(double) * law_state.size());
  const std::uint64_t events = eventTally().hash.value();
  hash.mix(&events, sizeof events);
  return hash.value();
}

}  // namespace friction
