// Fast-forward (MODEL.md §5): while the interface sits in static equilibrium with no node sliding and
// the stage moves slowly, the slider follows its pinned equilibrium, and a run jumps along it to the
// next change instead of stepping. Works on its Simulation's state.
#pragma once

#include <memory>
#include <vector>

#include "friction_sim/model/model.h"
#include "friction_sim/solvers/static_solver.h"
#include "run/quasi_static_creep.h"

namespace friction {

class Simulation;

class FastForward {
 public:
  explicit FastForward(Simulation& simulation);

  /// True while the slider sits in static equilibrium with no node sliding, or creeping quasi-statically.
  bool quasiStatic() const { return quasi_static_; }
  /// True if the next advance may jump.
  bool mayJump() const;
  /// The jumps of one advance towards `until` (s), or one creep step while nodes creep; false if a
  /// dynamic step is needed instead.
  bool jump(double until);
  /// With the interface pinned where it sticks or creeps and free where it has lost contact: the static
  /// equilibrium, if it holds every stuck node within its threshold and in contact and every lifted node
  /// off the track, and keeps creeping nodes in contact. Applies it (the energy of the ring-down it skips
  /// is counted as viscous dissipation) and returns true; otherwise leaves the state as it is. Nodes that
  /// slide may creep only if every one is slower than the creep's exit speed (QuasiStaticCreep).
  bool relaxToStaticEquilibrium();
  /// True, off the static path and outside events, once every interval of the slip criterion's quiet time
  /// (the next is booked then), if nodes may creep: the dynamics may then have slowed to a creep that
  /// relaxToStaticEquilibrium can take back to the path.
  bool creepResumeDue(double time);
  /// At the loaded equilibrium, or where a step may have brought the slider back to the static path.
  void setQuasiStatic(bool quasi_static) { quasi_static_ = quasi_static; }
  /// An event started or the stage moved too fast: off the static path until it is found again.
  void leavePath() { quasi_static_ = approaching_threshold_ = false; }
  /// The static solver with the interface nodes in contact pinned, those off the track free, the pusher
  /// on, set up again (factor or multigrid) only when the set of nodes off the track has changed, and not
  /// even then if it is the set before, whose solver is kept (spare_solver_). Null
  /// if that set leaves the slider free to move (every node lifted, say): then the dynamics go on.
  StaticSolver* pinnedSolver() { return pinnedSolver(nullptr); }
  /// The loading solve's solver, what it held and the model's anchor stiffness then.
  struct LoadingSolve {
    std::unique_ptr<StaticSolver> solver;
    std::vector<int> fixed_dofs;
    Vector anchor_stiffness;  ///< N/m per dof
  };
  /// pinnedSolver() at the loaded equilibrium, made from `loading` if it pins the same degrees of freedom:
  /// the two differ by the springs the pusher added (StaticSolver::withAddedSprings), and a second
  /// factorisation is spared. `loading` is spent either way.
  StaticSolver* pinnedSolverAfterLoading(LoadingSolve loading) { return pinnedSolver(&loading); }

  long long jumps() const { return jumps_; }
  long long jumpCorrections() const { return jump_corrections_; }
  /// Pinned solvers set up (factorisations, but for the one made from the loading solve), and taken back
  /// from the spare.
  long long solverSetups() const { return solver_setups_; }
  long long solverReuses() const { return solver_reuses_; }
  double jumpedTime() const { return jumped_time_; }  ///< s

 private:
  /// pinnedSolver(), made from `loading` (if not null) when it is set up.
  StaticSolver* pinnedSolver(LoadingSolve* loading);
  /// Where the pinned solver is to be replaced for the nodes `lifted` off the track: the spare if it was
  /// made for them (null otherwise); the current solver becomes the spare if it may be kept, and what is
  /// not kept is freed.
  std::unique_ptr<StaticSolver> exchangeWithSpare(const std::vector<int>& lifted);
  /// Where a jump along the equilibrium goes and how far.
  struct Path {
    Vector along;         ///< du/dX_s along the equilibrium
    Vector velocity;      ///< m/s, every free node moves with the stage
    double length = 0.0;  ///< s, to the caller's time, the stage's next change, a stop limit or the first threshold
    bool stops_at_threshold = false;
    std::vector<double> crossings;  ///< s, each interface node's estimated first crossing (inf: none)
  };
  /// The jumps of one fast-forward towards a threshold crossing, as far as the last one went.
  struct Approach {
    bool toward_threshold = true;       ///< the last jump stopped short of a crossing (true before the first)
    double length = 0.0;                ///< s, that jump's (0: none yet)
    std::vector<double> expected_left;  ///< s, each node's way to its crossing that the jump estimated it would leave
  };
  /// One jump along the pinned equilibrium towards `until` or, if sooner, the next node's threshold
  /// (then `approach.toward_threshold`, and the jump covers approachShare of the way). Returns false,
  /// jumping nowhere, if less than a step is left.
  bool jumpAlongEquilibrium(double until, Approach& approach);
  /// Share of the way along `path` to its first crossing that the next jump of `approach` covers: the
  /// first kApproachShare, each later one leaving kApproachSafety times the error that the last jump's
  /// misses predict for it, within [kApproachShare, kLongestApproachShare].
  static double approachShare(const Approach& approach, const Path& path);
  /// The path from here with the stage at its speed, and the first threshold crossing, lift-off or
  /// landing along it.
  Path pathAhead(double span);
  /// Shortens `path` to the first time a node reaches its threshold or loses contact, or a lifted node lands.
  /// `here` and `moved` are the forces at the start and at `probed`, `probe` (m) of stage travel along it.
  void findFirstCrossing(Path& path, const ForceEvaluation& here, const ForceEvaluation& moved, const Vector& probed,
                         double probe);
  /// s, for a law that ages: when the stuck `node`'s load sign·(force + force_rate·t) first reaches its
  /// rising strength µ_s(t)·(normal + normal_rate·t), searched from `earliest` (the crossing with µ_s
  /// as it is now, before which it cannot come); inf if the load never reaches it.
  double agedCrossing(int node, double sign, double force, double force_rate, double normal, double normal_rate,
                      double earliest) const;
  /// Moves the slider and the stage along `path` by its length, the clock to `end_time` (s), and takes
  /// the jump's secant as the path's slope if it went from one equilibrium to another.
  void takeJump(StaticSolver& solver, Path& path, double end_time);
  /// m, how far the slider moves along the path in a jump of `stage_move` (m of the stage's travel) whose
  /// middle is at `middle` (m of the stage's position): by the path's slope, and by its curvature where
  /// the branch has given one.
  Vector predictedMove(double middle, double stage_move) const;
  /// The last jump's secant, `slope` (m/m) over its middle at `middle` (m of the stage's position), becomes
  /// the path's slope, and with the secant before it on the same branch gives its curvature.
  void takeSecant(const Vector& slope, double middle);
  /// The slider left the branch of equilibria it was following (a creep step, another contact set):
  /// slopes taken before do not give the curvature of the next. An event and the relaxation after it
  /// do not: the curvature, which comes mostly from the springs around the pushed node, changes little
  /// across them (at 225 × 121 kept: 163 corrections to the first global event; reset: 185), though
  /// the slope jumps, so that the secants on either side of an event give no curvature.
  void leaveBranch();
  /// s, how far an advance towards `until` (s) may go: to `until`, the stop time, the stage's next change
  /// or its travel limit.
  double spanAhead(double until) const;
  /// s, the clock after an advance of `length` (s) towards `until` (s) (spanAhead).
  double endTime(double until, double length) const;
  /// One creep step towards `until` (s); false, leaving the path, if the dynamics must take over.
  bool creepStep(double until);
  /// Where an advance along the path began, for concludeAdvance.
  struct AdvanceStart {
    double shear_force;     ///< N, F_X
    double stage_position;  ///< m
    double stage_end;       ///< m, the stage's position where the advance ends
    double time;            ///< s
    double kinetic_energy;  ///< J
  };
  /// Starts an advance along the path: moves the stage by `length` (s) of its motion and the clock to
  /// `end_time` (s), and returns where it began. The caller then moves the slider.
  AdvanceStart beginAdvance(double length, double end_time);
  /// What every advance along the path ends with: the kinetic energy it changed, the pusher's work, slip
  /// events over [`event_start`, + `event_length`] (s), the jump count and the stop condition.
  void concludeAdvance(const AdvanceStart& start, double event_start, double event_length);
  /// Share of the way to an estimated threshold crossing that a jump covers at least.
  static constexpr double kApproachShare = 0.9;
  /// ... and at most: what is left is never less than a hundredth of the estimate.
  static constexpr double kLongestApproachShare = 0.99;
  /// A jump's secant becomes the path's slope if the solve's tolerance is at most this share of the
  /// largest displacement the jump made: a shorter jump's secant would carry the solve's error.
  static constexpr double kSecantPrecision = 1e-6;
  /// The margin left before a crossing, in the error predicted for the jump.
  static constexpr double kApproachSafety = 10.0;
  /// The nodes whose misses count: those estimated to cross within this many times the way to the first.
  static constexpr double kApproachNeighbourhood = 10.0;
  /// Jumps of one fast-forward after which the dynamics takes over (an approach takes about three).
  static constexpr int kMaxApproachJumps = 50;
  /// The dynamics takes a threshold's approach over while the stage keeps the velocity that brings the
  /// crossing; another motion (a hold, a reversal: a command or a segment of the program) may never
  /// bring it, and jumps again.
  bool approachingThreshold() const;

  Simulation& sim_;
  QuasiStaticCreep creep_;
  double next_creep_resume_ = 0.0;               ///< s, creepResumeDue's next time
  std::unique_ptr<StaticSolver> pinned_solver_;  ///< see pinnedSolver(); null when its stiffness is singular
  std::vector<int> lifted_nodes_;                ///< the interface nodes off the track it was set up for
  bool set_up_ = false;                          ///< a setup was tried for lifted_nodes_ (null if it failed)
  /// The solver before, kept for when its contact set comes back: a corner that lifts and lands again
  /// toggles between two sets (449 × 241: 15 factorisations of 4 s to the first global event, all but two
  /// of them repeats). Kept up to kLargestSpareFactor bytes; never a multigrid solver.
  std::unique_ptr<StaticSolver> spare_solver_;
  std::vector<int> spare_lifted_nodes_;
  static constexpr std::size_t kLargestSpareFactor = std::size_t(1) << 29;  // 512 MiB
  long long solver_setups_ = 0;
  long long solver_reuses_ = 0;
  /// du/dX_s (m/m), the slope of the path: first the free nodes' linear response to the stage, solved once
  /// per solver (the models' pushers are linear springs, whose force is affine in the stage's position);
  /// then the secant of each jump between equilibria long enough (kSecantPrecision): the springs' geometry
  /// turns the path away from the loaded state's slope as the slider deforms.
  Vector stage_response_;
  /// m of the stage's position where stage_response_ is the path's slope: the middle of the jump whose
  /// secant it is.
  double slope_position_ = 0.0;
  /// d²u/dX_s² (1/m), from the last two secants taken on one branch; empty until there are two. A jump
  /// predicted by the slope alone lands off the path by the curvature times the jump and the way back to
  /// the slope's middle: corrections after it start at 10⁻⁸–10⁻⁹ m at 113 × 61, and each gains only a
  /// factor of about 80 (modified Newton on the unloaded stiffness, mostly at the pushed node).
  Vector slope_change_;
  /// What stage_response_ is on the branch followed now: no secant of it, a secant taken before the last
  /// event's relaxation, or one taken on the path since.
  enum class LastSecant { kNone, kBeforeEvent, kOnPath };
  LastSecant last_secant_ = LastSecant::kNone;
  /// The state is a converged pinned equilibrium (the loaded one, a relaxation's or a jump's), as long as
  /// no step has been taken since `equilibrium_steps_`.
  bool at_equilibrium_ = true;
  long long equilibrium_steps_ = 0;
  void markEquilibrium(bool at_equilibrium);
  bool atEquilibrium() const;
  bool quasi_static_ = false;
  bool approaching_threshold_ = false;  ///< the last jump stopped short of a threshold: step dynamically
  double approach_velocity_ = 0.0;      ///< m/s, the stage's velocity then: the crossing is that motion's
  long long jumps_ = 0;
  long long jump_corrections_ = 0;
  double jumped_time_ = 0.0;  ///< s
};

}  // namespace friction
