#include "friction_sim/run/simulation.h"

#include "run/acceleration_strips.h"
#include "run/fast_forward.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "friction_sim/scene/scene_io.h"
#include "friction_sim/solvers/static_solver.h"

namespace friction {

Simulation::~Simulation() = default;

Simulation::Simulation(const Scene& scene) : Simulation(scene, requireValidScene(scene)) {}

Simulation::Simulation(const Scene& scene, double stability_limit)
    : scene_(scene),
      model_(buildModel(scene_)),
      contact_(buildFrictionLaw(scene_.friction), *model_, scene_.friction.interfacial_stiffness),
      integrator_(buildIntegrator(scene_.integrator.scheme)),
      stage_(scene_.stage, scene_.integrator.time_step),
      detector_(*model_, scene_.instruments.front_fit_nodes, waveSpeeds(scene_).longitudinal, scene_.geometry.length,
                slipCriterion(scene_)),
      dt_(scene_.integrator.time_step),
      stability_limit_(stability_limit),
      node_mass_(model_->nodeMass()),
      inverse_mass_(1.0 / node_mass_),
      quasi_static_stage_speed_(1e-3 * std::sqrt(scene_.material.youngs_modulus / scene_.material.density)),
      fast_forward_(std::make_unique<FastForward>(*this)) {
  try {
    relaxToLoadedEquilibrium();
  } catch (const std::runtime_error& error) {
    // A valid scene whose loaded equilibrium cannot be solved is still the scene's problem, not a crash.
    throw SceneError({std::string("the loading solve failed (") + error.what() +
                      "): the stiffnesses of the scene (material, lattice, pusher, load) are too far apart to "
                      "solve in double precision"});
  }
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
  FastForward::LoadingSolve loading{nullptr, model_->blockedDofsDuringLoading(), Vector()};
  loading.solver = std::make_unique<StaticSolver>(*model_, loading.fixed_dofs, true);
  if (loading.solver->solve(*model_, u_, 0.0, body_force) > StaticSolver::kMaxIterations) {
    throw std::runtime_error("no equilibrium within " + std::to_string(StaticSolver::kMaxIterations) +
                             " modified-Newton corrections");
  }
  loading.anchor_stiffness = model_->anchorStiffness();
  if (!prestressed) model_->connectPusher(u_);
  contact_.reset(u_);
  power_ = acceleration(u_, v_, 0.0, a_);
  if (contact_.updateStates(u_, v_, 0.0, node_mass_)) reapplyFriction();
  ledger_.start(model_->elasticEnergy(u_, stage_.position()) + contact_.anchorEnergy(u_), u_);
  if (scene_.integrator.fast_forward) {
    const bool pinned = fast_forward_->pinnedSolverAfterLoading(std::move(loading)) != nullptr;
    fast_forward_->setQuasiStatic(contact_.slidingCount() == 0 && pinned);
  }
}

void Simulation::refreshAfterStaticChange() {
  power_ = acceleration(u_, v_, time_, a_);
  // Refresh every node's held force and threshold for the next step's crossing interpolation (no time
  // passes).
  if (contact_.updateStates(u_, v_, 0.0, node_mass_)) reapplyFriction();
}

bool Simulation::quasiStatic() const { return fast_forward_->quasiStatic(); }
bool Simulation::mayJump() const { return fast_forward_->mayJump(); }
long long Simulation::jumps() const { return fast_forward_->jumps(); }
long long Simulation::jumpCorrections() const { return fast_forward_->jumpCorrections(); }
double Simulation::jumpedTime() const { return fast_forward_->jumpedTime(); }
long long Simulation::staticSolverSetups() const { return fast_forward_->solverSetups(); }
long long Simulation::staticSolverReuses() const { return fast_forward_->solverReuses(); }

void Simulation::advance(double until, double group_before) {
  if (mayJump() && fast_forward_->jump(until)) return;
  if (mayStepInGroup(group_before)) {
    stepInGroup(group_before);
  } else {
    step();
  }
}

double Simulation::acceleration(const Vector& u, const Vector& v, double t, Vector& a) {
  StripHooks none;
  return accelerationInStrips(u, v, t, a, none);
}

double Simulation::accelerationInStrips(const Vector& u, const Vector& v, double t, Vector& a, StripHooks& hooks) {
  contact_.lendNormalStorage(evaluation_.normal_force);
  AccelerationStrips strips(hooks, a, inverse_mass_, contact_, evaluation_, u, v);
  model_->evaluateInStrips(u, v, stage_.positionAfter(t - time_), a, evaluation_, strips, kStripNodes);
  return evaluation_.viscous_power;
}

void Simulation::reapplyFriction() { contact_.reapplyFriction(u_, v_, inverse_mass_, a_); }

Simulation::StepStart Simulation::stepStart() const {
  return {contact_.contactChanges(), quasiStatic(), stageTooFast(), evaluation_.shear_force, stage_.position()};
}

void Simulation::advanceClock() {
  stage_.advance(dt_);
  time_ += dt_;
  contact_.setTime(time_);
  ++steps_;
}

void Simulation::accountStep(const StepStart& start, double end_shear_force, double end_stage_position,
                             double dissipated) {
  ledger_.addViscous(dissipated);
  ledger_.addPusherWork(start.shear_force, end_shear_force, start.stage_position, end_stage_position);
}

void Simulation::settleInterface() {
  if (contact_.finishStep(u_, v_, dt_)) {
    power_ = acceleration(u_, v_, time_, a_);
  } else if (contact_.slipChangedCoefficients()) {
    // The step's force was evaluated with the coefficients of the slip before it; the next step starts
    // from those of the slip after it (a whole step's lag otherwise).
    reapplyFriction();
  }
  if (contact_.updateStates(u_, v_, dt_, node_mass_)) reapplyFriction();
}

void Simulation::concludeStep(const StepStart& start) {
  const bool was_in_event = detector_.inEvent();
  event_ended_ = detector_.update(time_ - dt_, dt_, contact_, u_, v_,
                                  {start.shear_force, evaluation_.shear_force, evaluation_.normal_load});
  event_started_ = !was_in_event && (detector_.inEvent() || event_ended_);
  if (scene_.integrator.fast_forward) {
    if (event_started_ || start.stage_too_fast) fast_forward_->leavePath();
    // Back on the static path when an event ends, or when a node lifts off or lands in a step taken on
    // the path (the path goes on with the new set of nodes in contact). Not while the slider rings
    // after a fast stage move: only the end of an event brings it back then.
    const bool contact_changed =
        start.was_quasi_static && contact_.contactChanges() != start.contact_changes && !detector_.inEvent();
    // Or, where nodes may creep, once the dynamics has slowed to a creep.
    const bool creep_resume_due = fast_forward_->creepResumeDue(time_);
    if ((event_ended_ || contact_changed || creep_resume_due) && !start.stage_too_fast &&
        fast_forward_->relaxToStaticEquilibrium()) {
      fast_forward_->setQuasiStatic(true);
    }
  }
  checkStop();
}

void Simulation::step() {
  const StepStart start = stepStart();
  contact_.beginStep(u_, v_);
  const double dissipated = integrator_->step(*this, u_, v_, a_, power_, time_, dt_);
  advanceClock();
  accountStep(start, evaluation_.shear_force, stage_.position(), dissipated);
  settleInterface();
  concludeStep(start);
}

bool Simulation::finishUnfinishedEvent() {
  if (!detector_.finishUnfinished(time_, evaluation_.shear_force, u_)) return false;
  event_started_ = false;
  event_ended_ = true;
  return true;
}

void Simulation::run() {
  while (!finished()) advance(scene_.stop.time);
}

}  // namespace friction
