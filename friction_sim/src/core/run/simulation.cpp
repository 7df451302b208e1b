#include "friction_sim/run/simulation.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "friction_sim/scene/scene_io.h"
#include "friction_sim/solvers/static_solver.h"

namespace friction {

Simulation::Simulation(const Scene& scene) : Simulation(scene, requireValidScene(scene)) {}

Simulation::Simulation(const Scene& scene, double stability_limit)
    : scene_(scene),
      model_(buildModel(scene_)),
      contact_(buildFrictionLaw(scene_.friction), *model_, scene_.friction.interfacial_stiffness),
      integrator_(buildIntegrator(scene_.integrator.scheme)),
      stage_(scene_.stage, scene_.integrator.time_step),
      detector_(*model_, scene_.instruments.front_fit_nodes, waveSpeeds(scene_).longitudinal, scene_.geometry.length),
      dt_(scene_.integrator.time_step),
      stability_limit_(stability_limit),
      node_mass_(model_->nodeMass()),
      inverse_mass_(1.0 / node_mass_),
      quasi_static_stage_speed_(1e-3 * std::sqrt(scene_.material.youngs_modulus / scene_.material.density)) {
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
  StaticSolver(*model_, model_->blockedDofsDuringLoading(), true).solve(*model_, u_, 0.0, body_force);
  if (!prestressed) model_->connectPusher(u_);
  contact_.reset(u_);
  external_reference_u_ = u_;
  power_ = acceleration(u_, v_, 0.0, a_);
  if (contact_.updateStates(u_, v_, 0.0, node_mass_)) reapplyFriction();
  initial_elastic_ = model_->elasticEnergy(u_, stage_.position()) + contact_.anchorEnergy(u_);
  if (scene_.integrator.fast_forward) {
    quasi_static_ = contact_.slidingCount() == 0 && pinnedSolver() != nullptr;
  }
}

void Simulation::refreshAfterStaticChange() {
  power_ = acceleration(u_, v_, time_, a_);
  // Refresh every node's held force and threshold for the next step's crossing interpolation (no time
  // passes).
  if (contact_.updateStates(u_, v_, 0.0, node_mass_)) reapplyFriction();
}

StaticSolver* Simulation::pinnedSolver() {
  std::vector<int> lifted;
  for (int node = 0; node < contact_.size(); ++node) {
    if (contact_.state(node) == ContactState::Detached) lifted.push_back(node);
  }
  if (lifted != lifted_nodes_ || (lifted_nodes_.empty() && !pinned_solver_)) {
    pinned_solver_.reset();  // first: at 10⁶ nodes two solvers would not fit the memory budget
    lifted_nodes_.swap(lifted);
    std::vector<int> in_contact;
    for (int node = 0; node < contact_.size(); ++node) {
      if (contact_.state(node) != ContactState::Detached) in_contact.push_back(contact_.dofs()[node]);
    }
    try {
      pinned_solver_ = std::make_unique<StaticSolver>(*model_, in_contact, false, StaticMethod::kAuto, lifted_nodes_);
    } catch (const std::runtime_error&) {
      // Singular: too few nodes in contact hold the slider.
    }
  }
  return pinned_solver_.get();
}

bool Simulation::relaxToStaticEquilibrium() {
  if (contact_.slidingCount() > 0) return false;
  StaticSolver* solver = pinnedSolver();
  if (!solver) return false;
  Vector relaxed = u_;
  // A lifted node that wants its contact back leaves modified Newton without a converged answer.
  if (solver->solve(*model_, relaxed, stage_.position()) > StaticSolver::kMaxIterations) return false;
  ForceEvaluation check;
  model_->evaluate(relaxed, Vector::Zero(u_.size()), stage_.position(), check);
  if (!contact_.holdsPinned(check)) return false;
  // What the ring-down would have dissipated: the drop in potential energy plus the kinetic energy.
  auto potential = [&](const Vector& u) {
    return model_->elasticEnergy(u, stage_.position()) - model_->externalWork(external_reference_u_, u);
  };
  viscous_dissipation_ += potential(u_) + kineticEnergy() - potential(relaxed);
  u_ = relaxed;
  v_.setZero();
  refreshAfterStaticChange();
  approaching_threshold_ = false;
  return true;
}

bool Simulation::fastForward(double until) {
  // A jump aimed at a threshold uses the equilibrium's slope where it starts; the slope changes along
  // the way (the springs' geometry), so a long jump would land off the crossing by a part in 10⁴ of
  // the load. Approached instead in jumps that each cover a fixed share of what is left, from a slope
  // taken ever closer to the crossing, until less than a step is left: then the dynamics takes the
  // node over, and the result no longer depends on where the jumps were cut (`until`).
  bool jumped = false;
  bool toward_threshold = true;
  for (int jump = 1; toward_threshold && jumpAlongEquilibrium(until, toward_threshold); ++jump) {
    jumped = true;
    if (event_started_ || finished()) break;
    // A crossing that keeps receding (met tangentially) is left to the dynamics.
    if (jump == kMaxApproachJumps) {
      approaching_threshold_ = toward_threshold;
      approach_velocity_ = stage_.velocity();
      break;
    }
  }
  return jumped;
}

bool Simulation::jumpAlongEquilibrium(double until, bool& toward_threshold) {
  const double horizon = std::min({until, scene_.stop.time}) - time_;
  const double speed = stage_.velocity();
  // The stage's speed holds until its next change, so a travel limit falls at a known time: the jump
  // stops there, as full dynamics stops on the step that reaches it.
  const double to_travel_limit =
      speed != 0.0 ? (scene_.stop.stage_travel - stage_.travel()) / std::abs(speed) : std::numeric_limits<double>::infinity();
  const double span = std::min({horizon, stage_.timeToNextChange(), to_travel_limit});
  toward_threshold = false;
  StaticSolver* solver = pinnedSolver();
  if (!(span > dt_) || !solver) return false;
  double jump = span;
  Vector along = Vector::Zero(u_.size());  // du/dX_s along the equilibrium
  Vector path_velocity = Vector::Zero(u_.size());  // m/s, every free node moves with the stage
  bool stops_at_threshold = false;
  if (speed != 0.0) {
    // The pusher's force per unit stage travel, and the free nodes' response to it.
    ForceEvaluation here, moved;
    const Vector at_rest = Vector::Zero(u_.size());
    model_->evaluate(u_, at_rest, stage_.position(), here);
    model_->evaluate(u_, at_rest, stage_.position() + 1.0, moved);
    along = solver->response(moved.force - here.force);
    // Friction needed and normal force of every stuck node are affine in the stage position. Along the
    // path every free node moves at speed·along, and the pair damping's force on the stuck nodes
    // counts towards their thresholds, as it does once the dynamics takes over.
    path_velocity = speed * along;
    const double probe = 1e-6 * model_->nodeSpacing();
    model_->evaluate(u_, path_velocity, stage_.position(), here);
    const Vector probed = u_ + probe * along;
    model_->evaluate(probed, path_velocity, stage_.position() + probe, moved);
    Vector lift, lift_moved;  // signed normal forces of the lifted nodes, which land where they reach 0
    if (contact_.detachedCount() > 0) {
      lift = model_->signedNormalForces(u_, here);
      lift_moved = model_->signedNormalForces(probed, moved);
    }
    for (int node = 0; node < contact_.size(); ++node) {
      if (contact_.state(node) == ContactState::Detached) {
        const double lift_rate = (lift_moved[node] - lift[node]) / probe * speed;
        if (lift_rate > 0.0 && -lift[node] / lift_rate < jump) {
          jump = -lift[node] / lift_rate;
          stops_at_threshold = true;
        }
        continue;
      }
      const int dof = contact_.dofs()[node];
      const double mu = contact_.law().staticCoefficient(node);
      const double force = here.force[dof], force_rate = (moved.force[dof] - force) / probe * speed;
      const double normal = here.normal_force[node];
      const double normal_rate = (moved.normal_force[node] - normal) / probe * speed;
      // Times t > 0 where ±F(t) = µ_s·N(t) or N(t) = 0.
      for (double sign : {1.0, -1.0}) {
        const double slope = sign * force_rate - mu * normal_rate;
        if (slope > 0.0) {
          const double crossing = (mu * normal - sign * force) / slope;
          if (crossing < jump) {
            jump = crossing;
            stops_at_threshold = true;
          }
        }
      }
      if (normal_rate < 0.0 && -normal / normal_rate < jump) {
        jump = -normal / normal_rate;
        stops_at_threshold = true;
      }
    }
  }
  if (!(jump > dt_)) {
    approaching_threshold_ = stops_at_threshold;
    approach_velocity_ = speed;
    return false;
  }
  // With nothing due, no end and no threshold ahead (a stage at rest) the jump has no end: nothing
  // would change along it, and a jump to t = inf would leave NaN behind; the caller steps or bounds it.
  if (!std::isfinite(jump)) return false;
  if (stops_at_threshold) jump *= kApproachShare;
  toward_threshold = stops_at_threshold;
  const double shear_start = evaluation_.shear_force;
  const double stage_start = stage_.position();
  const double stage_end = stage_.positionAfter(jump);
  u_ += (stage_end - stage_start) * along;
  stage_.advance(jump);
  // A jump to the caller's time ends on it exactly: time_ + (until − time_) can fall an ulp short, and a
  // command due then would wait a step (the rig compares due times with the clock exactly).
  time_ = !stops_at_threshold && jump == horizon ? std::min(until, scene_.stop.time) : time_ + jump;
  const double kinetic_before = kineticEnergy();
  solver->solve(*model_, u_, stage_end);
  v_.swap(path_velocity);
  // Along the path every node moves with the stage: the stage supplies that kinetic energy, as in the
  // dynamics, where it accelerates the slider (otherwise the next relaxation would count it as
  // dissipated); kinetic energy lost when the stage stops rings down in the dynamics.
  const double kinetic_change = kineticEnergy() - kinetic_before;
  if (kinetic_change > 0.0) {
    pusher_work_ += kinetic_change;
  } else {
    viscous_dissipation_ -= kinetic_change;
  }
  // The jump is a step of its own for the slip of an event that starts at its end (a lifted node moved).
  contact_.beginStep(u_, v_);
  refreshAfterStaticChange();
  // Round-off may land a node just past its threshold: then its slip starts here.
  detector_.update(time_, 0.0, contact_, u_, {evaluation_.shear_force, evaluation_.shear_force, evaluation_.normal_load});
  pusher_work_ += 0.5 * (shear_start + evaluation_.shear_force) * (stage_end - stage_start);
  ++jumps_;
  // Any approach before this jump is over: the crossing, if it comes, is found again from here.
  approaching_threshold_ = false;
  jumped_time_ += jump;
  event_started_ = detector_.inEvent();
  event_ended_ = false;
  if (event_started_) quasi_static_ = approaching_threshold_ = false;
  checkStop();
  return true;
}

void Simulation::advance(double until, double group_before) {
  if (mayJump() && fastForward(until)) return;
  if (mayStepInGroup(group_before)) {
    stepInGroup(group_before);
  } else {
    step();
  }
}

namespace {
/// About 4·10³ nodes: the strip's displacements, velocities and accelerations (≈ 200 kB) stay in the
/// L2 cache between the force evaluation and the integrator's passes.
constexpr int kStripNodes = 4096;
/// About 2·10³ nodes while a group of steps is swept at once: each sweep keeps one or two strips behind
/// the one ahead of it in the cache. At 10⁶ nodes with two steps per sweep, 1024 and 2048 gave 4.8–5.1 ns
/// per node-step, 4096 4.9–5.7 and 8192 5.5–6.0 (by hand, 2026-11-24).
constexpr int kGroupStripNodes = 2048;

/// Turns each finished strip's forces into accelerations before passing it on: the interface's entries
/// with their friction, which needs nothing beyond the strip's own nodes.
class AccelerationStrips : public StripHooks {
 public:
  AccelerationStrips(StripHooks& caller, Vector& a, double inverse_mass, ContactInterface& contact,
                     const ForceEvaluation& evaluation, const Vector& u)
      : caller_(caller), a_(a), inverse_mass_(inverse_mass), contact_(contact), evaluation_(evaluation), u_(u),
        interface_begin_(contact.firstDof()), interface_end_(interface_begin_ + contact.size()) {}
  void prepare(int first, int end) override { caller_.prepare(first, end); }
  void finish(int first, int end) override {
    scaleOutsideInterface(first, std::min(end, interface_begin_));
    const int first_node = std::max(first, interface_begin_) - interface_begin_;
    const int end_node = std::min(end, interface_end_) - interface_begin_;
    if (first_node < end_node) contact_.applyFriction(evaluation_, u_, inverse_mass_, a_, first_node, end_node);
    scaleOutsideInterface(std::max(first, interface_end_), end);
    caller_.finish(first, end);
  }

 private:
  void scaleOutsideInterface(int first, int end) {
    if (first < end) a_.segment(first, end - first) *= inverse_mass_;
  }

  StripHooks& caller_;
  Vector& a_;
  double inverse_mass_;
  ContactInterface& contact_;
  const ForceEvaluation& evaluation_;
  const Vector& u_;
  int interface_begin_, interface_end_;
};
}  // namespace

double Simulation::acceleration(const Vector& u, const Vector& v, double t, Vector& a) {
  StripHooks none;
  return accelerationInStrips(u, v, t, a, none);
}

double Simulation::accelerationInStrips(const Vector& u, const Vector& v, double t, Vector& a, StripHooks& hooks) {
  contact_.lendNormalStorage(evaluation_.normal_force);
  AccelerationStrips strips(hooks, a, inverse_mass_, contact_, evaluation_, u);
  model_->evaluateInStrips(u, v, stage_.positionAfter(t - time_), a, evaluation_, strips, kStripNodes);
  return evaluation_.viscous_power;
}

void Simulation::reapplyFriction() { contact_.reapplyFriction(u_, inverse_mass_, a_); }

Simulation::StepStart Simulation::stepStart() const {
  return {contact_.contactChanges(), quasi_static_, stageTooFast(), evaluation_.shear_force, stage_.position()};
}

void Simulation::advanceClock() {
  stage_.advance(dt_);
  time_ += dt_;
  ++steps_;
}

void Simulation::accountStep(const StepStart& start, double end_shear_force, double end_stage_position,
                             double dissipated) {
  viscous_dissipation_ += dissipated;
  pusher_work_ += 0.5 * (start.shear_force + end_shear_force) * (end_stage_position - start.stage_position);
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
  event_ended_ = detector_.update(time_ - dt_, dt_, contact_, u_,
                                 {start.shear_force, evaluation_.shear_force, evaluation_.normal_load});
  event_started_ = !was_in_event && (detector_.inEvent() || event_ended_);
  if (scene_.integrator.fast_forward) {
    if (event_started_ || start.stage_too_fast) quasi_static_ = approaching_threshold_ = false;
    // Back on the static path when an event ends, or when a node lifts off or lands in a step taken on
    // the path (the path goes on with the new set of nodes in contact). Not while the slider rings
    // after a fast stage move: only the end of an event brings it back then.
    const bool contact_changed = start.was_quasi_static && contact_.contactChanges() != start.contact_changes &&
                                 !detector_.inEvent();
    if ((event_ended_ || contact_changed) && !start.stage_too_fast && relaxToStaticEquilibrium()) quasi_static_ = true;
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

bool Simulation::mayStepInGroup(double group_before) const {
  // Without fast-forward's next try: mayJump() stays false through steps with no event.
  return scene_.integrator.scheme == IntegratorKind::VelocityVerlet && model_->successiveEvaluations() > 1 &&
         !mayJump() && contact_.slidingCount() == 0 && !detector_.inEvent() && (time_ + dt_) + dt_ < group_before;
}

void Simulation::stepInGroup(double group_before) {
  // What the steps' sweeps share, and what each step keeps for its end. Captured by reference, with
  // `this`: two pointers, which std::function keeps without allocating.
  struct Group {
    int most;
    double before;  ///< s
    VerletPasses passes;
    std::array<StepStart, kMaxGroupSteps> starts;
    std::array<std::optional<AccelerationStrips>, kMaxGroupSteps> strips;
    bool last_concluded = true;
  } group{std::min(model_->successiveEvaluations(), kMaxGroupSteps), group_before, VerletPasses(u_, v_, a_, dt_), {},
          {}};
  group.starts[0] = stepStart();
  contact_.beginStep(u_, v_);
  const int steps = model_->evaluateSuccessiveInStrips(
      kGroupStripNodes, [this, &group](int k) -> std::optional<StripEvaluation> {
        if (k > 0) {
          // Step k − 1's interface is final. With no node sliding, finishStep has nothing to re-stick: the
          // interface's end of the step is its state update alone (settleInterface).
          advanceClock();
          if (contact_.updateStates(u_, v_, dt_, node_mass_)) {
            reapplyFriction();
            group.last_concluded = false;  // once its sums are known, below
            return std::nullopt;
          }
          // Nothing changed at the interface, so no slip event starts or ends, nothing returns to the static
          // path (which would evaluate forces while the sweeps are under way in the model's work space),
          // and the step's conclusion needs none of the sums its sweep is still adding up (F_X, the
          // viscous power).
          concludeStep(group.starts[k - 1]);
          if (k == group.most || finished() || !(time_ + dt_ < group.before)) return std::nullopt;
          group.starts[k] = stepStart();
          contact_.beginStep(u_, v_);
        }
        ForceEvaluation& evaluation = groupEvaluation(k);
        contact_.lendNormalStorage(evaluation.normal_force);
        group.strips[k].emplace(group.passes, a_, inverse_mass_, contact_, evaluation, u_);
        return StripEvaluation{u_, v_, stage_.positionAfter((time_ + dt_) - time_), a_, evaluation,
                               *group.strips[k]};
      });
  // The steps' energy, in order, now that their sums are known; the clock stands at the last one's end.
  for (int k = 0; k < steps; ++k) {
    const ForceEvaluation& evaluation = groupEvaluation(k);
    StepStart& start = group.starts[k];
    if (k > 0) start.shear_force = groupEvaluation(k - 1).shear_force;
    const double end_stage_position = k + 1 < steps ? group.starts[k + 1].stage_position : stage_.position();
    // Velocity Verlet's dissipation, as VelocityVerlet::step counts it.
    accountStep(start, evaluation.shear_force, end_stage_position, evaluation.viscous_power * dt_);
  }
  power_ = groupEvaluation(steps - 1).viscous_power;
  if (steps > 1) std::swap(evaluation_, later_evaluations_[steps - 2]);
  if (!group.last_concluded) concludeStep(group.starts[steps - 1]);
}

void Simulation::run() {
  while (!finished()) advance(scene_.stop.time);
}

void Simulation::checkStop() {
  if (finished()) return;  // the first reason stands while a caller steps on past it
  const bool enough_events = scene_.stop.global_events > 0 && detector_.globalEventCount() >= scene_.stop.global_events;
  if (enough_events || !(time_ < scene_.stop.time) || !(stage_.travel() < scene_.stop.stage_travel)) {
    recordStopReason(enough_events);
  }
}

[[gnu::cold]] void Simulation::recordStopReason(bool enough_events) {
  std::ostringstream reason;
  if (enough_events) {
    reason << "reached " << detector_.globalEventCount() << " global slip event(s)";
  } else if (time_ >= scene_.stop.time) {
    reason << "reached the time limit of " << scene_.stop.time << " s";
  } else {
    reason << "reached the stage travel limit of " << scene_.stop.stage_travel << " m";
  }
  stop_reason_ = reason.str();
}

std::string Simulation::setStopCondition(const StopSpec& stop) {
  // Every problem, separated by " | " (a problem's own text holds "; "), so that one refusal says all that
  // must change.
  std::ostringstream reason;
  auto problem = [&reason]() -> std::ostream& { return reason << (reason.tellp() > 0 ? " | " : ""); };
  if (stop.global_events < 0) {
    problem() << "global_events " << stop.global_events << " is not allowed; allowed: >= 0 (0: not this condition)";
  }
  // A condition already met would end the run on the next step: refused, as a caller who means "now"
  // calls stop.
  if (stop.global_events > 0 && detector_.globalEventCount() >= stop.global_events) {
    problem() << "global_events " << stop.global_events << " is already reached (" << detector_.globalEventCount()
              << " so far); allowed: > " << detector_.globalEventCount() << " (0: not this condition)";
  }
  if (!(stop.time > time_)) {
    problem() << "time " << stop.time << " s is not allowed; allowed: > " << time_
              << " s, the time now (inf: not this condition)";
  }
  if (!(stop.stage_travel > stage_.travel())) {
    problem() << "stage_travel " << stop.stage_travel << " m is not allowed; allowed: > "
              << stage_.travel() << " m, the travel now (inf: not this condition)";
  }
  if (!endsTheRun(stop)) problem() << kNoEndProblem;
  if (!reason.str().empty()) return reason.str();
  scene_.stop = stop;
  stop_reason_.clear();
  checkStop();
  return {};
}

std::string Simulation::checkNormalLoad(double normal_force) const {
  std::ostringstream reason;
  if (!std::isfinite(normal_force) || normal_force <= 0.0 || normal_force > largestNormalForce(scene_)) {
    reason << "normal load " << normal_force << " N is not allowed; allowed: a finite F_Z > 0 N, at most "
           << largestNormalForce(scene_) << " N (a mean normal stress of 5 % of E: a small strain)";
  } else if (!model_->takesNormalLoadChanges()) {
    reason << "normal load " << normal_force
           << " N refused: F_Z cannot change during a run with load.top spring_mattress (its plate is placed "
              "once, when F_Z is applied); use load.top uniform";
  }
  return reason.str();
}

std::string Simulation::setNormalLoad(double normal_force) {
  std::string reason = checkNormalLoad(normal_force);
  if (!reason.empty()) return reason;
  external_work_closed_ += model_->externalWork(external_reference_u_, u_);
  external_reference_u_ = u_;
  model_->setNormalLoad(normal_force);
  power_ = acceleration(u_, v_, time_, a_);
  if (scene_.integrator.fast_forward) {
    quasi_static_ = !detector_.inEvent() && !stageTooFast() && relaxToStaticEquilibrium();
  }
  return {};
}

std::string Simulation::checkCommand(const TimedCommand& command) const {
  return command.kind == TimedCommand::Kind::NormalLoad ? checkNormalLoad(command.normal_force)
                                                        : stage_.checkCommand(command.stage);
}

std::string Simulation::apply(const TimedCommand& command) {
  return command.kind == TimedCommand::Kind::NormalLoad ? setNormalLoad(command.normal_force)
                                                        : stage_.command(command.stage);
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
  EnergyBudget budget;
  budget.work_in = pusher_work_ + external_work_closed_ + model_->externalWork(external_reference_u_, u_);
  budget.elastic = model_->elasticEnergy(u_, stage_.position()) + contact_.anchorEnergy(u_);
  budget.initial_elastic = initial_elastic_;
  budget.kinetic = kineticEnergy();
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
                              event.mean_shear_force, event.rupture_length, event.nucleation_position};
    mix(numbers, sizeof numbers);
    mix(event.node_slip.data(), sizeof(double) * event.node_slip.size());
  }
  return hash;
}

}  // namespace friction
