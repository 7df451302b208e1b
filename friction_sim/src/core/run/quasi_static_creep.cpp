#include "run/quasi_static_creep.h"

#include <algorithm>
#include <cmath>

#include "friction_sim/run/simulation.h"
#include "friction_sim/solvers/static_solver.h"
#include "solvers/cholesky_factor.h"

namespace friction {

QuasiStaticCreep::QuasiStaticCreep(const Simulation& simulation) : sim_(simulation) {
  const Scene& scene = simulation.scene();
  const bool creeps = scene.integrator.fast_forward && simulation.contact().law().rateDependent() &&
                      scene.friction.interfacial_stiffness <= 0.0 && scene.instruments.event_slip_speed > 0.0;
  exit_speed_ = creeps ? kExitShare * scene.instruments.event_slip_speed : 0.0;
  // Six decades below the exit: a node that has just unstuck starts there.
  speed_scale_ = 1e-6 * exit_speed_;
  shortest_ = kShortestSteps * scene.integrator.time_step;
  next_duration_ = shortest_;
}

void QuasiStaticCreep::linearise(const StaticSolver& solver, const ForceEvaluation& here) {
  const Simulation& s = sim_;
  const Model& model = s.model();
  const ContactInterface& contact = s.contact();
  const Vector& u = s.displacements();
  const double stage = s.stage().position();
  const int columns = static_cast<int>(nodes_.size()) + 1;
  const Vector at_rest = Vector::Zero(u.size());
  const double probe = model.probeLength();
  // A creeping node moved with every other node in contact pinned and the bulk in equilibrium, or the
  // stage moved with the whole interface pinned: each column's force with its unit motion alone, then
  // the bulk's responses to a sweep's worth of columns at once (more would only hold more memory).
  auto unitMotion = [&](int column) {
    Vector along = Vector::Zero(u.size());
    if (column < columns - 1) along[contact.dofs()[nodes_[column]]] = 1.0;
    return along;
  };
  auto stageAt = [&](int column) { return stage + (column == columns - 1 ? probe : 0.0); };
  ForceEvaluation moved;
  displacement_.resize(u.size(), columns);
  for (int first = 0; first < columns; first += CholeskyFactor::kColumnsPerSweep) {
    const int count = std::min(CholeskyFactor::kColumnsPerSweep, columns - first);
    Eigen::MatrixXd imbalance(u.size(), count);
    for (int i = 0; i < count; ++i) {
      model.evaluate(u + probe * unitMotion(first + i), at_rest, stageAt(first + i), moved);
      imbalance.col(i) = (moved.force - here.force) / probe;
    }
    displacement_.middleCols(first, count) = solver.responses(imbalance);
  }
  force_.resize(contact.size(), columns);
  normal_.resize(contact.size(), columns);
  for (int column = 0; column < columns; ++column) {
    displacement_.col(column) += unitMotion(column);
    model.evaluate(u + probe * displacement_.col(column), at_rest, stageAt(column), moved);
    for (int node = 0; node < contact.size(); ++node) {
      const int dof = contact.dofs()[node];
      force_(node, column) = (moved.force[dof] - here.force[dof]) / probe;
      normal_(node, column) = (moved.normal_force[node] - here.normal_force[node]) / probe;
    }
  }
  linearised_solver_ = &solver;
}

QuasiStaticCreep::Trial QuasiStaticCreep::solveAt(double duration) const {
  const ContactInterface& contact = sim_.contact();
  const FrictionLaw& law = contact.law();
  const int count = static_cast<int>(nodes_.size());
  Trial trial;
  trial.log_speed = start_log_speed_;
  Eigen::VectorXd& y = trial.log_speed;
  Eigen::VectorXd motion(count + 1), residual(count);
  motion[count] = sim_.stage().positionAfter(duration) - sim_.stage().position();
  std::vector<double> mu(count), mu_slope(count);
  std::vector<char> moving(count);
  auto coefficientAt = [&](int i, double log_speed) {
    return law.coefficientAfterSlip(nodes_[i], speedOf(log_speed), slipOf(i, log_speed, duration), duration);
  };
  auto evaluateAt = [&]() {
    for (int i = 0; i < count; ++i) motion[i] = directions_[i] * slipOf(i, y[i], duration);
    trial.force = start_force_ + force_ * motion;
    trial.normal = start_normal_ + normal_ * motion;
    for (int i = 0; i < count; ++i) {
      const int node = nodes_[i];
      // µ at the speed reached, with the state evolved over the step; its slope by a difference in y.
      constexpr double kDifference = 1e-7;
      mu[i] = coefficientAt(i, y[i]);
      mu_slope[i] = (coefficientAt(i, y[i] + kDifference) - mu[i]) / kDifference;
      residual[i] = directions_[i] * trial.force[node] - mu[i] * trial.normal[node];
      // A node at rest that its load does not move sticks (the rows of the others decide).
      moving[i] = y[i] > 0.0 || residual[i] > 0.0;
    }
  };
  constexpr int kMostIterations = 100;
  for (int iteration = 0; iteration < kMostIterations; ++iteration) {
    evaluateAt();
    bool balanced = true;
    for (int i = 0; i < count; ++i) {
      const double normal = trial.normal[nodes_[i]];
      if (!(normal > 0.0)) return trial;  // contact lost: not a creep
      if (moving[i] && std::abs(residual[i]) > 1e-11 * normal) balanced = false;
    }
    if (balanced) {
      trial.converged = true;
      break;
    }
    Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(count, count);
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(count);
    for (int i = 0; i < count; ++i) {
      if (!moving[i]) {
        jacobian(i, i) = 1.0;
        continue;
      }
      const int node = nodes_[i];
      for (int j = 0; j < count; ++j) {
        const double motion_per_log_speed = directions_[j] * 0.5 * speed_scale_ * std::exp(y[j]) * duration;
        jacobian(i, j) = (directions_[i] * force_(node, j) - mu[i] * normal_(node, j)) * motion_per_log_speed;
      }
      jacobian(i, i) -= trial.normal[node] * mu_slope[i];
      rhs[i] = -residual[i];
    }
    Eigen::VectorXd change = jacobian.partialPivLu().solve(rhs);
    // At most a factor e² in speed per iteration: the residual is steep in y where speeds are high.
    const double largest = change.lpNorm<Eigen::Infinity>();
    if (!std::isfinite(largest)) return trial;
    if (largest > 2.0) change *= 2.0 / largest;
    y = (y + change).cwiseMax(0.0);
    if (largest < 1e-13 * (1.0 + y.lpNorm<Eigen::Infinity>())) {
      evaluateAt();
      trial.converged = true;
      break;
    }
  }
  if (!trial.converged) return trial;
  for (int i = 0; i < count; ++i) {
    trial.fastest = std::max(trial.fastest, speedOf(y[i]));
    trial.largest_change = std::max(trial.largest_change, std::abs(y[i] - start_log_speed_[i]));
  }
  // The stuck nodes: in contact, and where the first reaches its threshold, its margin interpolated
  // linearly between the step's ends.
  for (int node = 0; node < contact.size(); ++node) {
    if (contact.state(node) != ContactState::Stuck) continue;
    if (!(trial.normal[node] > 0.0)) {
      trial.converged = false;
      return trial;
    }
    const double margin = law.staticCoefficientAfter(node, duration) * trial.normal[node] - std::abs(trial.force[node]);
    if (margin >= 0.0) continue;
    const double start_margin = law.staticCoefficient(node) * start_normal_[node] - std::abs(start_force_[node]);
    trial.crossing =
        std::min(trial.crossing, start_margin > 0.0 ? duration * start_margin / (start_margin - margin) : 0.0);
  }
  return trial;
}

bool QuasiStaticCreep::plan(const StaticSolver& solver, double span, CreepStep& step) {
  const Simulation& s = sim_;
  const ContactInterface& contact = s.contact();
  if (contact.detachedCount() > 0) return false;
  std::vector<int> nodes, directions;
  for (int node = 0; node < contact.size(); ++node) {
    if (contact.state(node) != ContactState::Sliding) continue;
    nodes.push_back(node);
    directions.push_back(contact.slidingDirection(node));
  }
  const Vector& u = s.displacements();
  ForceEvaluation start;
  s.model().evaluate(u, Vector::Zero(u.size()), s.stage().position(), start);
  if (&solver != linearised_solver_ || nodes != nodes_ || directions != directions_) {
    nodes_.swap(nodes);
    directions_.swap(directions);
    linearise(solver, start);
  }
  start_force_.resize(contact.size());
  for (int node = 0; node < contact.size(); ++node) start_force_[node] = start.force[contact.dofs()[node]];
  start_normal_ = start.normal_force;
  const int count = static_cast<int>(nodes_.size());
  start_log_speed_.resize(count);
  for (int i = 0; i < count; ++i) {
    const double speed = std::max(0.0, directions_[i] * s.velocities()[contact.dofs()[nodes_[i]]]);
    start_log_speed_[i] = std::log1p(speed / speed_scale_);
  }
  double duration = std::min(span, std::max(next_duration_, shortest_));
  constexpr int kMostTrials = 40;
  for (int attempt = 0; attempt < kMostTrials; ++attempt) {
    const Trial trial = solveAt(duration);
    const bool may_shorten = duration > shortest_;
    if (!trial.converged) {
      if (!may_shorten) return false;
      duration = std::max(0.25 * duration, shortest_);
      continue;
    }
    if (may_shorten && (trial.fastest > exit_speed_ || trial.largest_change > kMostLogSpeedChange)) {
      duration = std::max(0.5 * duration, shortest_);
      continue;
    }
    // Aimed a hair past the crossing, so that the node is over its threshold where the step ends.
    if (may_shorten && trial.crossing < (1.0 - 1e-3) * duration) {
      duration = std::max(trial.crossing * (1.0 + 1e-6), shortest_);
      continue;
    }
    step.duration = duration;
    Eigen::VectorXd motion(count + 1);
    motion[count] = s.stage().positionAfter(duration) - s.stage().position();
    step.nodes = nodes_;
    step.speed.resize(count);
    step.end_friction.resize(count);
    for (int i = 0; i < count; ++i) {
      step.speed[i] = speedOf(trial.log_speed[i]);
      motion[i] = directions_[i] * slipOf(i, trial.log_speed[i], duration);
      step.end_friction[i] = -trial.force[nodes_[i]];  // it balances the node's load
    }
    step.displacement = displacement_ * motion;
    step.fastest = trial.fastest;
    next_duration_ = duration * std::clamp(0.5 * kMostLogSpeedChange / std::max(trial.largest_change, 1e-3), 0.5, 2.0);
    return true;
  }
  return false;
}

}  // namespace friction
