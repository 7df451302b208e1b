// Quasi-static creep (MODEL.md §5). Under a rate-dependent law a node that has unstuck can slide for
// seconds far slower than any event: the trailing edge of pmma_2d_rate_state creeps at 10⁻⁵–10⁻⁴ m/s
// from F_X/F_Z ≈ 0.12 on, so its interface is never all stuck and fast-forward could not jump. While
// every sliding node creeps that slowly, inertia is negligible and the slider passes through equilibria
// in which each creeping node's friction µ(v, φ)·N balances its load. A creep step solves the equilibrium
// at its end implicitly (the trapezoid in the creeping nodes' positions, the law's state evolved over
// the step at its mean speed), in steps that follow the creep's own time scale rather than the waves'.
#pragma once

#include <Eigen/Dense>
#include <limits>
#include <vector>

#include "friction_sim/model/model.h"

namespace friction {

class Simulation;
class StaticSolver;

/// A creep step planned by QuasiStaticCreep::plan, for FastForward to take.
struct CreepStep {
  double duration = 0.0;             ///< s
  Vector displacement;               ///< m, per degree of freedom, linearised (the equilibrium is corrected after)
  std::vector<int> nodes;            ///< the nodes that crept, as the step began
  std::vector<double> speed;         ///< m/s, ≥ 0, each one's at the end (0: it stops there)
  std::vector<double> end_friction;  ///< N, each one's at the end
  double fastest = 0.0;              ///< m/s, the largest of `speed`
};

class QuasiStaticCreep {
 public:
  explicit QuasiStaticCreep(const Simulation& simulation);

  /// True if the scene's nodes may creep quasi-statically: fast-forward on, a rate-dependent law, rigid
  /// sticking, and an event slip speed, below which sliding is not an event.
  bool enabled() const { return exit_speed_ > 0.0; }
  /// m/s, the creep speed above which the dynamics takes over: kExitShare of the event slip speed.
  double exitSpeed() const { return exit_speed_; }
  /// Plans a step of at most `span` (s) with the interface pinned in `solver` where it sticks: as long as
  /// the creeping nodes' speeds change by at most a factor e, none passes exitSpeed() unless the step is
  /// already the shortest, and it ends where the first stuck node reaches its threshold. False if no step
  /// of at least the shortest one converges with every node in contact: then the dynamics takes over.
  bool plan(const StaticSolver& solver, double span, CreepStep& step);
  /// The linearisation is stale (a new solver, or the state changed by other means).
  void forget() { linearised_solver_ = nullptr; }

 private:
  /// The equilibrium at the end of a trial step.
  struct Trial {
    bool converged = false;
    Eigen::VectorXd log_speed;    ///< ln(1 + v/speed_scale_) of each creeping node
    Vector force, normal;         ///< N, every interface node's tangential (friction excluded) and normal force
    double fastest = 0.0;         ///< m/s
    double largest_change = 0.0;  ///< the largest change of a log_speed over the step
    /// s, the estimated time of the first stuck node's threshold crossing within the step (inf: none)
    double crossing = std::numeric_limits<double>::infinity();
  };
  /// The creeping nodes' response to their own motion and to the stage's, at the state now, whose forces
  /// (at rest) are `here`.
  void linearise(const StaticSolver& solver, const ForceEvaluation& here);
  Trial solveAt(double duration) const;
  /// m/s, the speed of log-speed y.
  double speedOf(double log_speed) const { return speed_scale_ * std::expm1(log_speed); }
  /// m, ≥ 0, the slip of creeping node `i` over a step of `duration` (s) that it ends at `log_speed`: by
  /// the trapezoid, at the mean of its speeds at the step's ends.
  double slipOf(int i, double log_speed, double duration) const {
    return 0.5 * (speedOf(start_log_speed_[i]) + speedOf(log_speed)) * duration;
  }

  /// Share of the event slip speed where the dynamics takes a creeping node over.
  static constexpr double kExitShare = 0.5;
  /// The shortest creep step, in dynamic steps: shorter ones the dynamics takes as cheaply.
  static constexpr double kShortestSteps = 10.0;
  /// The largest change of a creeping node's ln(1 + v/speed_scale_) in one step.
  static constexpr double kMostLogSpeedChange = 0.3;

  const Simulation& sim_;
  double exit_speed_ = 0.0;     ///< m/s; 0 if nodes may not creep
  double speed_scale_ = 0.0;    ///< m/s, where log-speeds turn from linear to logarithmic
  double shortest_ = 0.0;       ///< s
  double next_duration_ = 0.0;  ///< s, the next step's length, from the last step's speed changes
  // The linearisation: for the creeping nodes (`nodes_`, moving in `directions_`) and, in the last
  // column, the stage, per unit of motion: every degree of freedom's displacement and every interface
  // node's tangential and normal force.
  const StaticSolver* linearised_solver_ = nullptr;
  std::vector<int> nodes_;
  std::vector<int> directions_;
  Eigen::MatrixXd displacement_, force_, normal_;
  /// The interface's forces at the step's start (friction excluded), and each creeping node's log-speed.
  Vector start_force_, start_normal_;
  Eigen::VectorXd start_log_speed_;
};

}  // namespace friction
