#include "run/fast_forward.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "friction_sim/run/simulation.h"

namespace friction {

FastForward::FastForward(Simulation& simulation) : sim_(simulation), creep_(simulation) {}

bool FastForward::approachingThreshold() const {
  return approaching_threshold_ && sim_.stage_.velocity() == approach_velocity_;
}

bool FastForward::mayJump() const {
  // Where nodes may creep, a threshold's approach ends in a creep step rather than in the dynamics.
  return quasi_static_ && (!approachingThreshold() || creep_.enabled()) && !sim_.stageTooFast();
}

StaticSolver* FastForward::pinnedSolver(LoadingSolve* loading) {
  const ContactInterface& contact = sim_.contact_;
  std::vector<int> lifted;
  for (int node = 0; node < contact.size(); ++node) {
    if (contact.state(node) == ContactState::Detached) lifted.push_back(node);
  }
  // A set whose setup failed is not tried again until the set changes: a failed factorisation or
  // multigrid setup would otherwise be repeated at every advance.
  if (!set_up_ || lifted != lifted_nodes_) {
    creep_.forget();  // it knows its solver by address, which a solver taken back from the spare reuses
    std::unique_ptr<StaticSolver> solver = exchangeWithSpare(lifted);
    lifted_nodes_.swap(lifted);
    set_up_ = true;
    std::vector<int> in_contact;
    for (int node = 0; node < contact.size(); ++node) {
      if (contact.state(node) != ContactState::Detached) in_contact.push_back(contact.dofs()[node]);
    }
    try {
      if (!solver && loading && loading->solver && lifted_nodes_.empty() && in_contact == loading->fixed_dofs) {
        solver = StaticSolver::withAddedSprings(std::move(loading->solver),
                                                sim_.model_->anchorStiffness() - loading->anchor_stiffness);
      }
      if (loading) loading->solver.reset();  // freed before a factorisation, as the spare's leftovers
      if (!solver) {
        solver = std::make_unique<StaticSolver>(*sim_.model_, in_contact, false, StaticMethod::kAuto, lifted_nodes_);
        ++solver_setups_;
      }
      // The pusher's force is affine in the stage's position: one solve gives the response to it, the
      // path's slope until a jump's secant takes its place.
      ForceEvaluation here, moved;
      const Vector at_rest = Vector::Zero(sim_.u_.size());
      sim_.model_->evaluate(sim_.u_, at_rest, sim_.stage_.position(), here);
      sim_.model_->evaluate(sim_.u_, at_rest, sim_.stage_.position() + 1.0, moved);
      stage_response_ = solver->response(moved.force - here.force);
      leaveBranch();
      pinned_solver_ = std::move(solver);
    } catch (const std::runtime_error&) {
      // Singular (too few nodes in contact hold the slider), or a multigrid solve that did not converge.
    }
  }
  return pinned_solver_.get();
}

std::unique_ptr<StaticSolver> FastForward::exchangeWithSpare(const std::vector<int>& lifted) {
  std::unique_ptr<StaticSolver> returning;
  if (spare_solver_ && spare_lifted_nodes_ == lifted) {
    returning = std::move(spare_solver_);
    ++solver_reuses_;
  }
  // Free what is not kept before a factorisation. Multigrid solvers (10⁶ nodes) are never kept: two
  // would not fit the memory budget.
  spare_solver_.reset();
  const std::size_t factor_bytes = pinned_solver_ ? pinned_solver_->directFactorBytes() : 0;
  if (factor_bytes > 0 && factor_bytes <= kLargestSpareFactor) {
    spare_solver_ = std::move(pinned_solver_);
    spare_lifted_nodes_ = lifted_nodes_;
  }
  pinned_solver_.reset();
  return returning;
}

bool FastForward::relaxToStaticEquilibrium() {
  Simulation& s = sim_;
  const ContactInterface& contact = s.contact_;
  const bool creeping = contact.slidingCount() > 0;
  if (creeping) {
    if (!creep_.enabled()) return false;
    for (int node = 0; node < contact.size(); ++node) {
      const bool sliding = contact.state(node) == ContactState::Sliding;
      if (sliding && std::abs(s.v_[contact.dofs()[node]]) > creep_.exitSpeed()) return false;
    }
  }
  StaticSolver* solver = pinnedSolver();
  if (!solver) return false;
  Vector relaxed = s.u_;
  // A lifted node that wants its contact back leaves modified Newton without a converged answer.
  if (solver->solve(*s.model_, relaxed, s.stage_.position()) > StaticSolver::kMaxIterations) return false;
  ForceEvaluation check;
  s.model_->evaluate(relaxed, Vector::Zero(s.u_.size()), s.stage_.position(), check);
  if (!s.contact_.holdsPinned(check, creeping)) return false;
  // What the ring-down would have dissipated: the drop in potential energy plus the kinetic energy.
  const double stage = s.stage_.position();
  s.ledger_.addViscous(s.ledger_.potential(*s.model_, s.u_, stage) + s.kineticEnergy() -
                       s.ledger_.potential(*s.model_, relaxed, stage));
  s.u_ = relaxed;
  s.v_.setZero();
  markEquilibrium(true);
  if (last_secant_ == LastSecant::kOnPath) last_secant_ = LastSecant::kBeforeEvent;
  s.refreshAfterStaticChange();
  approaching_threshold_ = false;
  return true;
}

bool FastForward::creepResumeDue(double time) {
  if (!creep_.enabled() || quasi_static_ || sim_.detector_.inEvent() || time < next_creep_resume_) return false;
  next_creep_resume_ = time + sim_.detector_.criterion().quiet_time;
  return true;
}

bool FastForward::jump(double until) {
  if (creep_.enabled() && (sim_.contact_.slidingCount() > 0 || approaching_threshold_)) return creepStep(until);
  // A jump aimed at a threshold follows the path's slope as the last jump's secant gave it; the slope
  // changes along the way (the springs' geometry), so a long jump would land off the crossing by a part
  // in 10⁴ of the load. Approached instead in jumps that each cover a share of what is left (approachShare), from
  // a slope taken ever closer to the crossing, until less than a step is left: then the dynamics takes
  // the node over, and the result no longer depends on where the jumps were cut (`until`).
  bool jumped = false;
  Approach approach;
  for (int jump = 1; approach.toward_threshold && jumpAlongEquilibrium(until, approach); ++jump) {
    jumped = true;
    if (sim_.event_started_ || sim_.finished()) break;
    // A crossing that keeps receding (met tangentially) is left to the dynamics.
    if (jump == kMaxApproachJumps) {
      approaching_threshold_ = approach.toward_threshold;
      approach_velocity_ = sim_.stage_.velocity();
      break;
    }
  }
  return jumped;
}

double FastForward::spanAhead(double until) const {
  const Simulation& s = sim_;
  const StopSpec& stop = s.scene_.stop;
  const double speed = s.stage_.velocity();
  // The stage's speed holds until its next change, so a travel limit falls at a known time: the advance
  // stops there, as full dynamics stops on the step that reaches it.
  const double to_travel_limit = speed != 0.0 ? (stop.stage_travel - s.stage_.travel()) / std::abs(speed)
                                              : std::numeric_limits<double>::infinity();
  return std::min({until - s.time_, stop.time - s.time_, s.stage_.timeToNextChange(), to_travel_limit});
}

double FastForward::endTime(double until, double length) const {
  // An advance to the caller's time ends on it exactly: time + (until − time) can fall an ulp short, and a
  // command due then would wait a step (the rig compares due times with the clock exactly).
  const double end = std::min(until, sim_.scene_.stop.time);
  return length == end - sim_.time_ ? end : sim_.time_ + length;
}

double FastForward::approachShare(const Approach& approach, const Path& path) {
  if (!(approach.length > 0.0)) return kApproachShare;
  // An estimate misses by a share of the way jumped: the last jump measured that share for every node
  // that may cross soon, not only the first (a node's crossing may come sooner than estimated).
  double miss = 0.0;
  for (std::size_t node = 0; node < path.crossings.size(); ++node) {
    if (path.crossings[node] < kApproachNeighbourhood * path.length) {
      miss = std::max(miss, std::abs(path.crossings[node] - approach.expected_left[node]) / approach.length);
    }
  }
  return std::clamp(1.0 - kApproachSafety * miss, kApproachShare, kLongestApproachShare);
}

bool FastForward::jumpAlongEquilibrium(double until, Approach& approach) {
  const Simulation& s = sim_;
  const double span = spanAhead(until);
  approach.toward_threshold = false;
  StaticSolver* solver = pinnedSolver();
  if (!(span > s.dt_) || !solver) return false;
  Path path = pathAhead(span);
  if (!(path.length > s.dt_)) {
    approaching_threshold_ = path.stops_at_threshold;
    approach_velocity_ = s.stage_.velocity();
    return false;
  }
  // With nothing due, no end and no threshold ahead (a stage at rest) the jump has no end: nothing
  // would change along it, and a jump to t = inf would leave NaN behind; the caller steps or bounds it.
  if (!std::isfinite(path.length)) return false;
  if (path.stops_at_threshold) {
    path.length *= approachShare(approach, path);
    approach.toward_threshold = true;
    approach.length = path.length;
    approach.expected_left = path.crossings;
    for (double& left : approach.expected_left) left -= path.length;
  }
  takeJump(*solver, path, path.stops_at_threshold ? s.time_ + path.length : endTime(until, path.length));
  return true;
}

FastForward::Path FastForward::pathAhead(double span) {
  const Simulation& s = sim_;
  const Model& model = *s.model_;
  Path path;
  path.length = span;
  path.along = Vector::Zero(s.u_.size());
  path.velocity = Vector::Zero(s.u_.size());
  const double speed = s.stage_.velocity();
  if (speed == 0.0) return path;
  path.along = stage_response_;
  // Friction needed and normal force of every stuck node are affine in the stage position. Along the
  // path every free node moves at speed·along, and the pair damping's force on the stuck nodes
  // counts towards their thresholds, as it does once the dynamics takes over.
  path.velocity = speed * path.along;
  const double probe = model.probeLength();
  ForceEvaluation here, moved;
  model.evaluate(s.u_, path.velocity, s.stage_.position(), here);
  const Vector probed = s.u_ + probe * path.along;
  model.evaluate(probed, path.velocity, s.stage_.position() + probe, moved);
  findFirstCrossing(path, here, moved, probed, probe);
  return path;
}

void FastForward::findFirstCrossing(Path& path, const ForceEvaluation& here, const ForceEvaluation& moved,
                                    const Vector& probed, double probe) {
  const Simulation& s = sim_;
  const ContactInterface& contact = s.contact_;
  const double speed = s.stage_.velocity();
  path.crossings.assign(contact.size(), std::numeric_limits<double>::infinity());
  auto stop_at = [&path](int node, double time) {
    path.crossings[node] = std::min(path.crossings[node], time);
    if (time < path.length) {
      path.length = time;
      path.stops_at_threshold = true;
    }
  };
  Vector lift, lift_moved;  // signed normal forces of the lifted nodes, which land where they reach 0
  if (contact.detachedCount() > 0) {
    lift = s.model_->signedNormalForces(s.u_, here);
    lift_moved = s.model_->signedNormalForces(probed, moved);
  }
  const bool ageing = contact.law().ages();
  for (int node = 0; node < contact.size(); ++node) {
    if (contact.state(node) == ContactState::Detached) {
      const double lift_rate = (lift_moved[node] - lift[node]) / probe * speed;
      if (lift_rate > 0.0) stop_at(node, -lift[node] / lift_rate);
      continue;
    }
    const int dof = contact.dofs()[node];
    const double mu = contact.law().staticCoefficient(node);
    const double force = here.force[dof], force_rate = (moved.force[dof] - force) / probe * speed;
    const double normal = here.normal_force[node];
    const double normal_rate = (moved.normal_force[node] - normal) / probe * speed;
    // Times t > 0 where ±F(t) = µ_s·N(t) or N(t) = 0.
    for (double sign : {1.0, -1.0}) {
      const double slope = sign * force_rate - mu * normal_rate;
      if (!(slope > 0.0)) continue;
      const double crossing = (mu * normal - sign * force) / slope;
      stop_at(node, ageing ? agedCrossing(node, sign, force, force_rate, normal, normal_rate, crossing) : crossing);
    }
    if (normal_rate < 0.0) stop_at(node, -normal / normal_rate);
  }
}

double FastForward::agedCrossing(int node, double sign, double force, double force_rate, double normal,
                                 double normal_rate, double earliest) const {
  const FrictionLaw& law = sim_.contact_.law();
  auto margin = [&](double t) {
    return law.staticCoefficientAfter(node, t) * (normal + normal_rate * t) - sign * (force + force_rate * t);
  };
  // The strength rises as the logarithm of the age, the load linearly: the margin falls through zero once,
  // after `earliest`. Bracketed in steps that double from a scale of `earliest`, then halved down to
  // round-off. Not on a scale of the jump: a crossing must not depend on where a caller ends its jump (a
  // live run ends its jumps where commands are due, an offline run where it stops).
  constexpr double kShortestScale = 1e-9;  // s, for a node at its threshold now (earliest = 0)
  constexpr int kMostDoublings = 200;
  double low = std::max(earliest, 0.0);
  double step = std::max(low, kShortestScale) / 64;
  for (int doubling = 0; doubling < kMostDoublings; ++doubling, step *= 2) {
    double high = low + step;
    if (margin(high) >= 0.0) {
      low = high;
      continue;
    }
    while (high - low > 1e-15 * high) {
      const double middle = 0.5 * (low + high);
      if (middle <= low || middle >= high) break;
      (margin(middle) >= 0.0 ? low : high) = middle;
    }
    return low;
  }
  return std::numeric_limits<double>::infinity();
}

void FastForward::takeJump(StaticSolver& solver, Path& path, double end_time) {
  Simulation& s = sim_;
  const bool from_equilibrium = atEquilibrium();
  const AdvanceStart start = beginAdvance(path.length, end_time);
  const double stage_move = start.stage_end - start.stage_position;
  const double middle = start.stage_position + 0.5 * stage_move;  // m, of the stage
  const Vector u_start = s.u_;
  s.u_ += from_equilibrium ? predictedMove(middle, stage_move) : stage_move * path.along;
  const int corrections = solver.solve(*s.model_, s.u_, start.stage_end);
  jump_corrections_ += std::min(corrections, StaticSolver::kMaxIterations);
  const bool converged = corrections <= StaticSolver::kMaxIterations;
  const Vector secant = s.u_ - u_start;
  // From one equilibrium to the next along the path, and long enough that the solves' error is lost in it.
  if (converged && from_equilibrium && stage_move != 0.0 &&
      solver.tolerance() <= kSecantPrecision * secant.lpNorm<Eigen::Infinity>()) {
    takeSecant(secant / stage_move, middle);
  }
  markEquilibrium(converged);
  s.v_.swap(path.velocity);
  jumped_time_ += path.length;
  concludeAdvance(start, s.time_, 0.0);
}

Vector FastForward::predictedMove(double middle, double stage_move) const {
  if (slope_change_.size() == 0) return stage_move * stage_response_;
  const Vector turn = (middle - slope_position_) * slope_change_;
  // Extrapolated far (across an event) or from a noisy difference, the turn could outgrow the slope
  // itself: the slope alone is then the safer start.
  if (!(turn.lpNorm<Eigen::Infinity>() <= stage_response_.lpNorm<Eigen::Infinity>())) {
    return stage_move * stage_response_;
  }
  return stage_move * (stage_response_ + turn);
}

void FastForward::takeSecant(const Vector& slope, double middle) {
  // Across an event the slope jumped, and the curvature from before it is the better estimate.
  if (last_secant_ == LastSecant::kOnPath && middle != slope_position_) {
    slope_change_ = (slope - stage_response_) / (middle - slope_position_);
  }
  stage_response_ = slope;
  slope_position_ = middle;
  last_secant_ = LastSecant::kOnPath;
}

void FastForward::leaveBranch() {
  slope_change_.resize(0);
  last_secant_ = LastSecant::kNone;
}

void FastForward::markEquilibrium(bool at_equilibrium) {
  at_equilibrium_ = at_equilibrium;
  equilibrium_steps_ = sim_.steps();
}

bool FastForward::atEquilibrium() const { return at_equilibrium_ && sim_.steps() == equilibrium_steps_; }

bool FastForward::creepStep(double until) {
  Simulation& s = sim_;
  const double span = spanAhead(until);
  StaticSolver* solver = pinnedSolver();
  CreepStep step;
  if (!solver || !(span > s.dt_) || !creep_.plan(*solver, span, step)) {
    leavePath();
    return false;
  }
  const Vector u_start = s.u_;
  markEquilibrium(false);  // one correction: near, not at, the creep's equilibrium
  leaveBranch();
  const AdvanceStart start = beginAdvance(step.duration, endTime(until, step.duration));
  s.u_ += step.displacement;
  // The step's linearised motion is within a part in 10⁴ of equilibrium: one correction leaves a part in
  // 10⁶ or less, and the next step corrects what is left.
  solver->correct(*s.model_, s.u_, start.stage_end);
  // The bulk at its mean velocity over the step, each creeping node at its speed at the end: the next
  // step, or the dynamics, starts from it.
  s.v_ = (s.u_ - u_start) / step.duration;
  for (std::size_t i = 0; i < step.nodes.size(); ++i) {
    const int node = step.nodes[i];
    const int dof = s.contact_.dofs()[node];
    s.v_[dof] = s.contact_.slidingDirection(node) * step.speed[i];
    if (step.speed[i] > 0.0) {
      s.contact_.creep(node, s.u_[dof] - u_start[dof], step.end_friction[i]);
    } else {
      s.contact_.stopCreeping(node, s.u_);
    }
  }
  jumped_time_ += step.duration;
  concludeAdvance(start, start.time, step.duration);
  if (step.fastest > creep_.exitSpeed()) leavePath();
  return true;
}

FastForward::AdvanceStart FastForward::beginAdvance(double length, double end_time) {
  Simulation& s = sim_;
  const AdvanceStart start{s.evaluation_.shear_force, s.stage_.position(), s.stage_.positionAfter(length), s.time_,
                           s.kineticEnergy()};
  s.stage_.advance(length);
  s.time_ = end_time;
  s.contact_.setTime(end_time);
  return start;
}

void FastForward::concludeAdvance(const AdvanceStart& start, double event_start, double event_length) {
  Simulation& s = sim_;
  // Along the path every node moves with the stage: the stage supplies that kinetic energy, as in the
  // dynamics, where it accelerates the slider (otherwise the next relaxation would count it as
  // dissipated); kinetic energy lost when the stage stops rings down in the dynamics.
  const double kinetic_change = s.kineticEnergy() - start.kinetic_energy;
  if (kinetic_change > 0.0) {
    s.ledger_.addPusherWork(kinetic_change);
  } else {
    s.ledger_.addViscous(-kinetic_change);
  }
  // The advance is a step of its own for the slip of an event that starts at its end (a lifted node moved).
  s.contact_.beginStep(s.u_, s.v_);
  s.refreshAfterStaticChange();
  // Round-off may land a node just past its threshold: then its slip starts here.
  const ForceEvaluation& end = s.evaluation_;
  s.detector_.update(event_start, event_length, s.contact_, s.u_, s.v_,
                     {start.shear_force, end.shear_force, end.normal_load});
  s.ledger_.addPusherWork(start.shear_force, end.shear_force, start.stage_position, start.stage_end);
  ++jumps_;
  // Any approach before this advance is over: the crossing, if it comes, is found again from here.
  approaching_threshold_ = false;
  s.event_started_ = s.detector_.inEvent();
  s.event_ended_ = false;
  if (s.event_started_) leavePath();
  s.checkStop();
}

}  // namespace friction
