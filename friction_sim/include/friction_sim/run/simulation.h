// A whole run of the rig: builds the model, the contact interface and the integrator from a scene,
// applies the loading protocol (F_Z relaxed to static equilibrium with the interface blocked, pusher
// connected unstretched), then advances in steps of dt while the stage moves, detecting slip events
// and keeping the energy budget. No ROS here: the offline runner and the ROS node both drive this.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "friction_sim/contact/contact_interface.h"
#include "friction_sim/instruments/instruments.h"
#include "friction_sim/instruments/slip_events.h"
#include "friction_sim/model/model.h"
#include "friction_sim/run/energy_ledger.h"
#include "friction_sim/scene/loading_protocol.h"
#include "friction_sim/scene/scene.h"
#include "friction_sim/solvers/integrator.h"
#include "friction_sim/stage/stage.h"

namespace friction {

class FastForward;

class Simulation : public Dynamics {
 public:
  /// Throws SceneError if the scene is invalid.
  explicit Simulation(const Scene& scene);
  ~Simulation() override;
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;
  /// For a scene already validated: `stability_limit` (s) is the limit its validation computed.
  Simulation(const Scene& scene, double stability_limit);

  /// Advances by one time step.
  void step();
  /// Advances by one time step or, with fast-forward on while the interface sits in static equilibrium
  /// with no node sliding and the stage moves slowly, jumps along the equilibrium to the earliest of
  /// `until` (s), the stage's next change and just before the next node reaches its threshold, loses
  /// contact or, lifted, lands (MODEL.md §5). While nodes creep quasi-statically (a rate-dependent law),
  /// takes one creep step instead, which counts as a jump. Where the next two steps end before `group_before` (s), may
  /// take several plain steps instead, each ending before `group_before`, for as long as each changes
  /// nothing at the interface (no node slides, none starts to, no slip event is under way): the same
  /// results as single steps, with the state swept once for all of them
  /// (Model::evaluateSuccessiveInStrips). Velocity Verlet, and a model that sweeps several evaluations at
  /// once (the 2D lattice), only. For callers that need the state after every step only around events
  /// and at their own sample times.
  void advance(double until, double group_before = 0.0);
  /// Advances until the scene's stop condition holds.
  void run();
  /// Threads the force evaluations may use (Model::setThreads): the same results for any count. With
  /// threads, the 2D lattice takes its steps one at a time.
  void setThreads(int threads) { model_->setThreads(threads); }
  /// True while the slider sits in static equilibrium with no node sliding, or creeping quasi-statically
  /// (fast-forward can jump).
  bool quasiStatic() const;
  /// True if the next `advance` may be a fast-forward jump.
  bool mayJump() const;
  /// Fast-forward jumps taken, and simulated time (s) they covered.
  long long jumps() const;
  double jumpedTime() const;
  /// The corrections (sparse solves) that brought fast-forward's jumps along the equilibrium to it (creep
  /// steps, one correction each, are not counted; a solve that gave up counts its kMaxIterations).
  long long jumpCorrections() const;
  /// Fast-forward's static solvers set up after the loading (factorisations of a new contact set), and
  /// taken back for a contact set that returned.
  long long staticSolverSetups() const;
  long long staticSolverReuses() const;
  /// True once the stop condition holds; `stopReason()` says which.
  bool finished() const { return !stop_reason_.empty(); }
  const std::string& stopReason() const { return stop_reason_; }

  double time() const { return time_; }  ///< s, simulated time since the stage started
  long long steps() const { return steps_; }
  double timeStep() const { return dt_; }                     ///< s
  double stabilityLimit() const { return stability_limit_; }  ///< s

  LoadCellReading loadCells() const;
  InterfaceFrame interfaceFrame() const;
  /// The interface frame with the nodes that unstuck in the last step as they were at their threshold
  /// crossing, stuck with friction µ_s·N_i and without the slip they were given for the rest of the step:
  /// at an event's onset, the loaded state that gave way (the plain frame shows them already sliding, at
  /// µ_k·N_i under Amontons–Coulomb). A node that landed on the track moving crossed no threshold and is
  /// shown as it is.
  InterfaceFrame interfaceFrameBeforeUnsticking() const;
  GaugeProfile gaugeProfile() const;
  LatticeSnapshot snapshot() const;
  EnergyBudget energy() const;
  /// The latest slip events (SlipEventDetector::events); all of them are counted in eventTally().
  const std::vector<SlipEvent>& events() const { return detector_.events(); }
  const EventTally& eventTally() const { return detector_.tally(); }
  /// True if the last step ended a slip event (events().back()).
  bool eventEndedLastStep() const { return event_ended_; }
  /// True if a slip event started in the last step.
  bool eventStartedLastStep() const { return event_started_; }
  /// A node began slipping, an event's quiet spell began (SlipCriterion), or an event started or ended,
  /// in the last step: the steps the interface camera must show, so that a detector reading only its
  /// frames sees every slip and every end.
  bool interfaceChangedLastStep() const { return event_started_ || event_ended_ || detector_.slipChangedLastUpdate(); }
  /// True while a slip event is under way.
  bool inEvent() const { return detector_.inEvent(); }
  /// Ends the slip event under way, if any, where the run is now, flagged unfinished: for a caller that
  /// stops the run here. Returns true if it ended one (eventEndedLastStep() then says so too).
  bool finishUnfinishedEvent();
  int globalEventCount() const { return detector_.tally().global_events; }

  /// Stage commands from a controller replace the scene's stage program.
  Stage& stage() { return stage_; }
  const Stage& stage() const { return stage_; }
  /// N, changes F_Z during the run; returns the refusal reason (checkNormalLoad) or empty.
  std::string setNormalLoad(double normal_force);
  /// Why F_Z = `normal_force` (N) cannot be set now (empty if it can): it must be finite, > 0 and at most
  /// largestNormalForce(scene), and the spring mattress's plate is placed once, when F_Z is first applied.
  std::string checkNormalLoad(double normal_force) const;
  /// Why `command` would be refused now (empty if acceptable): the stage's checks, or checkNormalLoad.
  std::string checkCommand(const TimedCommand& command) const;
  /// Applies `command` now, whatever its time (the caller applies each when it is due); returns the
  /// refusal reason, or empty.
  std::string apply(const TimedCommand& command);
  /// Replaces the scene's stop condition for the rest of the run (a controller's end of its protocol);
  /// finished() is then that condition's. Returns the refusal reason, its problems separated by " | ", or
  /// empty: global_events ≥ 0, time and stage_travel > 0 (∞ allowed).
  std::string setStopCondition(const StopSpec& stop);

  const Scene& scene() const { return scene_; }
  const Model& model() const { return *model_; }
  const ContactInterface& contact() const { return contact_; }
  const Vector& displacements() const { return u_; }
  const Vector& velocities() const { return v_; }

  /// FNV-1a hash of the state (time, displacements, velocities, contact states) and the event table.
  std::uint64_t stateHash() const;

  double acceleration(const Vector& u, const Vector& v, double t, Vector& a) override;
  /// The forces in strips of about 4096 nodes (their state stays in the L2 cache), each turned into
  /// accelerations before the caller's finish; the interface is finished last, once its friction is known.
  double accelerationInStrips(const Vector& u, const Vector& v, double t, Vector& a, StripHooks& hooks) override;

 private:
  friend class FastForward;
  void relaxToLoadedEquilibrium();
  /// What a step keeps from its start for its end.
  struct StepStart {
    long long contact_changes;  ///< the contact's lift-offs and landings so far
    bool was_quasi_static;
    bool stage_too_fast;
    double shear_force;     ///< N, F_X
    double stage_position;  ///< m
  };
  StepStart stepStart() const;
  /// The clock and the stage a step on.
  void advanceClock();
  /// The energy of a step that dissipated `dissipated` (J) in the pair damping, and the pusher's work up
  /// to F_X = `end_shear_force` (N) with the stage at `end_stage_position` (m).
  void accountStep(const StepStart& start, double end_shear_force, double end_stage_position, double dissipated);
  /// The interface's re-sticking and its other state rules at the step's end.
  void settleInterface();
  /// Slip events, fast-forward's return to the static path and the stop condition after a step.
  void concludeStep(const StepStart& start);
  /// Whether advance(until, group_before) may take several steps in one sweep now.
  bool mayStepInGroup(double group_before) const;
  /// Steps of velocity Verlet in one sweep (Model::evaluateSuccessiveInStrips), each ending before
  /// `group_before` (s), until one changes anything at the interface or ends the run.
  void stepInGroup(double group_before);
  /// The most steps stepInGroup takes in one sweep, whatever the model's successiveEvaluations(): the
  /// 2D lattice's.
  static constexpr int kMaxGroupSteps = 3;
  /// Step k's force evaluation in stepInGroup.
  ForceEvaluation& groupEvaluation(int k) { return k == 0 ? evaluation_ : later_evaluations_[k - 1]; }
  /// True while the stage moves too fast for the slider to follow it through static equilibria.
  bool stageTooFast() const { return std::abs(stage_.velocity()) > quasi_static_stage_speed_; }
  void refreshAfterStaticChange();
  void reapplyFriction();
  /// J, of the slider at its current velocities.
  double kineticEnergy() const { return 0.5 * node_mass_ * v_.squaredNorm(); }
  /// Sets the stop reason once a stop condition holds. Called every step.
  void checkStop();
  /// Composes the stop reason; kept out of checkStop, whose every-step test it would otherwise slow
  /// with a string stream's set-up.
  void recordStopReason();

  Scene scene_;
  std::unique_ptr<Model> model_;
  ContactInterface contact_;
  std::unique_ptr<Integrator> integrator_;
  Stage stage_;
  SlipEventDetector detector_;
  double dt_;
  double stability_limit_;
  double time_ = 0.0;
  long long steps_ = 0;
  double node_mass_;     ///< kg, of every node
  double inverse_mass_;  ///< 1/kg
  Vector u_, v_, a_;
  double power_ = 0.0;  ///< W, viscous power at the current state
  /// The last force evaluation (friction excluded); its `force` stays empty, the forces go to a_.
  ForceEvaluation evaluation_;
  /// The evaluations of a group's later steps while stepInGroup sweeps them; the last one is then
  /// swapped into evaluation_.
  std::array<ForceEvaluation, kMaxGroupSteps - 1> later_evaluations_;
  bool event_ended_ = false;
  bool event_started_ = false;
  std::string stop_reason_;
  EnergyLedger ledger_;
  /// m/s, 10⁻³ of the bar-wave speed √(E/ρ): MODEL.md §5's fast-forward rests on a stage far slower than
  /// the waves (the lab's is 10⁻⁸ of it). A stage step that moves faster leaves the static path.
  double quasi_static_stage_speed_;
  std::unique_ptr<FastForward> fast_forward_;
};

}  // namespace friction
