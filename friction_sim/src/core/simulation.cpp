#include "friction_sim/simulation.h"

#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>
#include <stdexcept>

#include "friction_sim/scene_io.h"

namespace friction {

double EnergyBudget::relativeResidual() const {
  const double scale = std::max({std::abs(work_in), std::abs(elastic - initial_elastic), kinetic,
                                 friction_dissipation, viscous_dissipation, 1e-300});
  return residual() / scale;
}

namespace {
const Scene& validated(const Scene& scene) {
  requireValidScene(scene);
  return scene;
}
}  // namespace

Simulation::Simulation(const Scene& scene)
    : scene_(validated(scene)),
      model_(buildModel(scene_)),
      contact_(buildFrictionLaw(scene_.friction), *model_, scene_.friction.interfacial_stiffness),
      integrator_(buildIntegrator(scene_.integrator.scheme)),
      stage_(scene_.stage),
      detector_(*model_, scene_.instruments.front_fit_nodes),
      dt_(scene_.integrator.time_step),
      stability_limit_(sceneStabilityLimit(scene_)) {
  relaxToLoadedEquilibrium();
}

void Simulation::relaxToLoadedEquilibrium() {
  const int n = model_->dofCount();
  u_ = Vector::Zero(n);
  v_ = Vector::Zero(n);
  const Vector body_force = model_->initialBodyForce();
  const bool prestressed = body_force.size() > 0;
  // A prestressed start is an equilibrium that the pusher holds; otherwise F_Z is applied with the
  // pusher off and the pusher connects unstretched afterwards.
  if (prestressed) {
    model_->connectPusher(u_);
  } else {
    model_->disconnectPusher();
  }
  std::vector<char> blocked(n, 0);
  for (int dof : model_->blockedDofsDuringLoading()) blocked[dof] = 1;
  std::vector<int> free_dofs;
  for (int dof = 0; dof < n; ++dof) {
    if (!blocked[dof]) free_dofs.push_back(dof);
  }
  if (!free_dofs.empty()) {
    std::vector<int> position_in_free(n, -1);
    for (std::size_t i = 0; i < free_dofs.size(); ++i) position_in_free[free_dofs[i]] = static_cast<int>(i);
    const SparseMatrix stiffness = model_->stiffnessMatrix();
    std::vector<Eigen::Triplet<double>> entries;
    for (int column = 0; column < stiffness.outerSize(); ++column) {
      for (SparseMatrix::InnerIterator it(stiffness, column); it; ++it) {
        const int row = position_in_free[it.row()], col = position_in_free[it.col()];
        if (row >= 0 && col >= 0) entries.emplace_back(row, col, it.value());
      }
    }
    SparseMatrix reduced(free_dofs.size(), free_dofs.size());
    reduced.setFromTriplets(entries.begin(), entries.end());
    Eigen::SimplicialLDLT<SparseMatrix> solver(reduced);
    if (solver.info() != Eigen::Success) throw std::runtime_error("static solve: stiffness matrix is singular");
    // Modified Newton: the rest-state stiffness corrects the residual of the full (geometric,
    // one-sided) forces until they balance.
    ForceEvaluation evaluation;
    Vector residual(free_dofs.size());
    const double tolerance = 1e-14 * scene_.geometry.length;
    for (int iteration = 0; iteration < 500; ++iteration) {
      model_->evaluate(u_, v_, 0.0, evaluation);
      for (std::size_t i = 0; i < free_dofs.size(); ++i) {
        residual[i] = evaluation.force[free_dofs[i]] + (prestressed ? body_force[free_dofs[i]] : 0.0);
      }
      const Vector correction = solver.solve(residual);
      for (std::size_t i = 0; i < free_dofs.size(); ++i) u_[free_dofs[i]] += correction[i];
      const bool load_changed = model_->rebalanceLoad(u_);
      if (!load_changed && correction.lpNorm<Eigen::Infinity>() < tolerance) break;
    }
  }
  if (!prestressed) model_->connectPusher(u_);
  contact_.reset(u_);
  external_reference_u_ = u_;
  power_ = acceleration(u_, v_, 0.0, a_);
  if (contact_.updateStates(evaluation_, u_, v_, 0.0, model_->nodeMass())) reapplyFriction();
  initial_elastic_ = model_->elasticEnergy(u_, stage_.position()) + contact_.anchorEnergy(u_);
}

double Simulation::acceleration(const Vector& u, const Vector& v, double t, Vector& a) {
  model_->evaluate(u, v, stage_.positionAfter(t - time_), evaluation_);
  a = evaluation_.force;
  contact_.applyFriction(evaluation_, u, a);
  a /= model_->nodeMass();
  return evaluation_.viscous_power;
}

void Simulation::reapplyFriction() {
  a_ = evaluation_.force;
  contact_.applyFriction(evaluation_, u_, a_);
  a_ /= model_->nodeMass();
}

void Simulation::step() {
  contact_.beginStep(u_, v_);
  const double shear_start = evaluation_.shear_force;
  const double stage_start = stage_.position();
  viscous_dissipation_ += integrator_->step(*this, u_, v_, a_, power_, time_, dt_);
  stage_.advance(dt_);
  time_ += dt_;
  ++steps_;
  pusher_work_ += 0.5 * (shear_start + evaluation_.shear_force) * (stage_.position() - stage_start);
  if (contact_.finishStep(u_, v_, dt_)) power_ = acceleration(u_, v_, time_, a_);
  if (contact_.updateStates(evaluation_, u_, v_, dt_, model_->nodeMass())) reapplyFriction();
  const bool was_in_event = detector_.inEvent();
  event_ended_ = detector_.update(time_ - dt_, dt_, contact_, u_,
                                 {shear_start, evaluation_.shear_force, evaluation_.normal_load});
  event_started_ = !was_in_event && (detector_.inEvent() || event_ended_);
  checkStop();
}

void Simulation::run() {
  while (!finished()) step();
}

void Simulation::checkStop() {
  std::ostringstream reason;
  if (scene_.stop.global_events > 0 && detector_.globalEventCount() >= scene_.stop.global_events) {
    reason << "reached " << detector_.globalEventCount() << " global slip event(s)";
  } else if (time_ >= scene_.stop.time) {
    reason << "reached the time limit of " << scene_.stop.time << " s";
  } else if (stage_.travel() >= scene_.stop.stage_travel) {
    reason << "reached the stage travel limit of " << scene_.stop.stage_travel << " m";
  }
  stop_reason_ = reason.str();
}

std::string Simulation::setNormalLoad(double normal_force) {
  if (!std::isfinite(normal_force) || normal_force <= 0.0) {
    std::ostringstream reason;
    reason << "normal load " << normal_force << " N must be finite and > 0";
    return reason.str();
  }
  external_work_closed_ += model_->externalWork(external_reference_u_, u_);
  external_reference_u_ = u_;
  model_->setNormalLoad(normal_force);
  power_ = acceleration(u_, v_, time_, a_);
  return {};
}

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
  snapshot.pusher_height = scene_.pusher.height;
  snapshot.normal_force = evaluation_.normal_load;
  return snapshot;
}

EnergyBudget Simulation::energy() const {
  EnergyBudget budget;
  budget.work_in = pusher_work_ + external_work_closed_ + model_->externalWork(external_reference_u_, u_);
  budget.elastic = model_->elasticEnergy(u_, stage_.position()) + contact_.anchorEnergy(u_);
  budget.initial_elastic = initial_elastic_;
  budget.kinetic = 0.5 * model_->nodeMass() * v_.squaredNorm();
  budget.friction_dissipation = contact_.frictionDissipation();
  budget.viscous_dissipation = viscous_dissipation_;
  return budget;
}

std::uint64_t Simulation::stateHash() const {
  std::uint64_t hash = 1469598103934665603ULL;
  auto mix = [&hash](const void* data, std::size_t bytes) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < bytes; ++i) {
      hash ^= p[i];
      hash *= 1099511628211ULL;
    }
  };
  mix(&time_, sizeof time_);
  mix(u_.data(), sizeof(double) * u_.size());
  mix(v_.data(), sizeof(double) * v_.size());
  for (int node = 0; node < contact_.size(); ++node) {
    const auto state = contact_.state(node);
    mix(&state, sizeof state);
  }
  for (const SlipEvent& event : events()) {
    const double numbers[] = {event.onset_time, event.end_time, event.onset_shear_force,
                              event.rupture_length, event.nucleation_position};
    mix(numbers, sizeof numbers);
    mix(event.node_slip.data(), sizeof(double) * event.node_slip.size());
  }
  return hash;
}

}  // namespace friction
