// The one run loop of the rig: the offline runner, the simulator node and the tests all drive a scene
// through a RunDriver, so that they apply commands, step, jump and sample the instruments by the same
// rule. It owns the Simulation, the command schedule, the stop rule and the sample streams; a caller
// adds what it does with the samples (files, topics) as streams' sinks, and nothing of its own that
// steps, jumps or interpolates. No ROS here.
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "friction_sim/instruments/instruments.h"
#include "friction_sim/run/command_schedule.h"
#include "friction_sim/run/simulation.h"
#include "friction_sim/scene/loading_protocol.h"

namespace friction {

/// Something that looks at the run after every advance (a step, a group of steps or a fast-forward
/// jump): an instrument sampled on its own clock of simulated time, or the slip events as they start and
/// end.
class RunStream {
 public:
  virtual ~RunStream() = default;
  /// s, the stream's next sample time: no group of steps passes it (inf: the stream has no clock).
  virtual double nextTime() const { return std::numeric_limits<double>::infinity(); }
  /// True if a jump also ends at nextTime() where jumps are cut at frames (RunOptions::cut_jumps_at_frames,
  /// and in a rest with no end).
  virtual bool cutsJumps() const { return false; }
  /// Before each advance, after the commands due were applied (`commands_applied` if any was).
  virtual void before(const Simulation& /*simulation*/, bool /*commands_applied*/) {}
  /// After each advance; `jumped` if it was a fast-forward jump.
  virtual void after(const Simulation& simulation, bool jumped) = 0;
};

/// How a stream with a clock samples.
enum class Sampling {
  /// The reading at the first step end at or after each time on its clock, at that step's time; across a
  /// jump, interpolated at each time on the clock (the rig's topics).
  AtSteps,
  /// Interpolated at each time on its clock, across steps and jumps alike (the offline runner's loading
  /// curve).
  Interpolated,
};

/// A simulated instant, for a stream that carries only its time (the rig's /clock).
struct Instant {
  double time = 0.0;  ///< s
};
inline Instant interpolate(const Instant& /*a*/, const Instant& /*b*/, double t) { return {t}; }

/// A stream's sampling rates (Hz of simulated time): while a slip event runs, and while all sticks. The
/// lab's fast acquisition runs during events only; the loading between them changes slowly.
struct SampleRates {
  double during_events;
  double idle;
  /// One rate for both.
  static SampleRates uniform(double rate) { return {rate, rate}; }
  double fastest() const { return std::max(during_events, idle); }
  bool operator==(const SampleRates& other) const { return during_events == other.during_events && idle == other.idle; }
};

/// A stream of readings (any type with a `time` in s and an `interpolate(a, b, t)`) sampled at its rates,
/// starting one idle period in: nothing is measured at t = 0. Where the rates differ, a stream sampled at
/// steps has its next sample brought within one event period by an event's first step, and its clock
/// keeps the period of the state (event or idle) at each sample; across a jump, where all sticks, the
/// idle period.
template <class Reading>
class SampledStream : public RunStream {
 public:
  using Read = std::function<Reading(const Simulation&)>;
  using Sink = std::function<void(const Reading&)>;
  /// `at_event_boundaries`: also at the end of every step where a slip event starts or ends, off the clock.
  SampledStream(SampleRates rates, Sampling sampling, Read read, Sink sink, bool at_event_boundaries = false)
      : rates_(rates),
        next_(1.0 / rates.idle),
        sampling_(sampling),
        at_event_boundaries_(at_event_boundaries),
        read_(std::move(read)),
        sink_(std::move(sink)) {}
  SampledStream(double rate, Sampling sampling, Read read, Sink sink, bool at_event_boundaries = false)
      : SampledStream(SampleRates::uniform(rate), sampling, std::move(read), std::move(sink), at_event_boundaries) {}

  double nextTime() const override { return next_; }
  /// True if the last advance produced a sample.
  bool sampledLast() const { return sampled_last_; }
  /// New rates from simulated time `now` (s): the next sample within an idle period (an event's next step
  /// brings it within an event period). The same rates again change nothing.
  void setRates(SampleRates rates, double now) {
    if (rates == rates_) return;
    rates_ = rates;
    next_ = std::min(next_, now + 1.0 / rates.idle);
  }

  void before(const Simulation& simulation, bool commands_applied) override {
    // Interpolated, the reading after the last advance serves unless a command changed the state since.
    // At steps, a plain step needs no reading before it.
    const bool needed =
        sampling_ == Sampling::Interpolated ? commands_applied || !before_current_ : simulation.mayJump();
    if (needed) before_ = read_(simulation);
  }

  void after(const Simulation& simulation, bool jumped) override {
    sampled_last_ = false;
    const double idle_period = 1.0 / rates_.idle;
    const double period = simulation.inEvent() ? 1.0 / rates_.during_events : idle_period;
    if (jumped || sampling_ == Sampling::Interpolated) {
      // A jump moves a stuck interface, also where it ends at an event's first slip: the idle clock.
      const double grid = jumped ? idle_period : period;
      Reading end = read_(simulation);
      for (; next_ <= simulation.time(); next_ += grid) emit(interpolate(before_, end, next_));
      before_ = std::move(end);
      before_current_ = true;
    }
    if (sampling_ != Sampling::AtSteps) return;
    if (simulation.inEvent()) next_ = std::min(next_, simulation.time() + period);
    const bool boundary =
        at_event_boundaries_ && (simulation.eventStartedLastStep() || simulation.eventEndedLastStep());
    if (dueAt(simulation.time(), period) || boundary) emit(read_(simulation));
  }

 private:
  /// Moves the clock past `now` on its grid of `period`; true if a sample was due.
  bool dueAt(double now, double period) {
    if (now < next_) return false;
    next_ += period * (std::floor((now - next_) / period) + 1.0);
    return true;
  }
  void emit(const Reading& reading) {
    sink_(reading);
    sampled_last_ = true;
  }

  SampleRates rates_;
  double next_;  ///< s
  Sampling sampling_;
  bool at_event_boundaries_;
  Read read_;
  Sink sink_;
  Reading before_{};
  bool before_current_ = false;  ///< before_ holds the reading at the end of the last advance
  bool sampled_last_ = false;
};

/// The fast camera: a frame at every step where a node unsticks or an event starts or ends, and otherwise
/// at its rates (each frame's next counted from it). Across a jump, where all sticks, interpolated at the
/// idle rate. Jumps cut at frames end at its next one.
class CameraStream : public RunStream {
 public:
  using Sink = std::function<void(const InterfaceFrame&)>;
  CameraStream(SampleRates rates, Sink sink);
  double nextTime() const override { return next_; }
  /// New rates from simulated time `now` (s): the next frame within a period of the faster one (one frame
  /// early at most, where all sticks). The same rates again change nothing: dynamic_reconfigure's first
  /// call, with the settings as they are, adds no frame.
  void setRates(SampleRates rates, double now) {
    if (rates == rates_) return;
    rates_ = rates;
    next_ = std::min(next_, now + 1.0 / rates.fastest());
  }
  bool cutsJumps() const override { return true; }
  void before(const Simulation& simulation, bool commands_applied) override;
  void after(const Simulation& simulation, bool jumped) override;

 private:
  SampleRates rates_;
  double next_;  ///< s
  Sink sink_;
  InterfaceFrame before_;
};

/// The slip events as they start (after the step of their onset) and end (`event` is events().back()).
class EventStream : public RunStream {
 public:
  using Started = std::function<void(const Simulation&)>;
  using Ended = std::function<void(const Simulation&, const SlipEvent& event)>;
  EventStream(Started started, Ended ended) : started_(std::move(started)), ended_(std::move(ended)) {}
  void after(const Simulation& simulation, bool jumped) override;

 private:
  Started started_;
  Ended ended_;
};

struct RunOptions {
  /// s, how long before its time a command is due: 0 for commands at the times they were given, half a
  /// nanosecond for times recorded rounded to whole nanoseconds (CommandSchedule).
  double command_early = 0.0;
  /// End when the scene's stop condition holds; without, only a run end set by setRunEnd ends the run.
  bool stop_at_scene_end = true;
  /// Jumps also end at the next time of every stream that cutsJumps() (a paced run: a watcher sees the
  /// slider move, and a command sent "now" acts within a frame). Its events may then differ from an uncut
  /// run's by fast-forward's own error: each jump solves the equilibrium afresh.
  bool cut_jumps_at_frames = false;
  /// Threads for the force evaluations (Simulation::setThreads): the same results for any count.
  int threads = 1;
};

/// The stage state now.
StageStateReading stageState(const Simulation& simulation);

class RunDriver {
 public:
  /// For a scene already validated: `stability_limit` (s) is the limit its validation computed.
  RunDriver(const Scene& scene, double stability_limit, RunOptions options = {});

  Simulation& simulation() { return simulation_; }
  const Simulation& simulation() const { return simulation_; }

  /// Adds a stream; streams are sampled in the order they were added. Returns it, for its sampledLast().
  template <class Stream>
  Stream& add(std::unique_ptr<Stream> stream) {
    Stream& added = *stream;
    streams_.push_back(std::move(stream));
    return added;
  }
  /// Called for every command when it comes due: applied (refusal empty) or refused by the simulation.
  void onCommandDue(CommandSchedule::Report report) { command_due_ = std::move(report); }

  /// Why `command` would never be applied (empty if it may be): stamped past a known end of the run, the
  /// scene's time limit where it ends the run, or the one set by setRunEnd.
  std::string checkCommandTime(const TimedCommand& command) const;
  /// Why `command` must be refused (empty if it may be scheduled): Simulation::checkCommand, then
  /// checkCommandTime.
  std::string checkCommand(const TimedCommand& command) const;
  /// Schedules a command at its time (check it first with checkCommand):
  /// what the simulation refuses it for when it is due is reported then.
  void schedule(const TimedCommand& command) { schedule_.add(command); }
  /// Schedules every command of a command table (rig_report's stage_commands.csv) read from `path`, each
  /// checked against the simulation first: throws ConfigError listing every problem. Returns how many.
  std::size_t scheduleCommandTable(const std::string& path);
  /// Schedules a loading protocol's commands as the stage controller sends them from t = 0, each step
  /// checked first (ConfigError names `path`). Its end is the caller's: it is part of the scene run.
  std::size_t scheduleProtocol(const LoadingProtocol& protocol, const std::string& path);
  /// Replaces the scene's stop condition (Simulation::setStopCondition) and ends the run when it holds,
  /// whatever stop_at_scene_end. Returns the refusal, or empty.
  std::string setRunEnd(const StopSpec& stop);

  /// One advance: the commands due by now, then a step, a group of steps or a jump that ends where the
  /// next command is due (and, cut at frames, at the next frame), then every stream.
  void advance();
  /// True once the run's end holds.
  bool finished() const { return (options_.stop_at_scene_end || run_end_set_) && simulation_.finished(); }
  /// Paced runs cut their jumps at frames (RunOptions::cut_jumps_at_frames), from the next advance on.
  void setCutJumpsAtFrames(bool cut) { options_.cut_jumps_at_frames = cut; }
  /// Advances until finished().
  void run() {
    while (!finished()) advance();
  }
  /// Where a caller stops the run: ends a slip event under way, flagged unfinished, and lets every stream
  /// see it end (the event stream reports it).
  void finishRun() {
    if (!simulation_.finishUnfinishedEvent()) return;
    for (const auto& stream : streams_) stream->after(simulation_, false);
  }

 private:
  /// s, where the next advance must end at the latest.
  double jumpEnd() const;
  /// Schedules `commands`; returns how many.
  std::size_t scheduleAll(const std::vector<TimedCommand>& commands);
  /// The simulation's refusal of a command, for the loaders' checks.
  CommandCheck commandCheck() const;

  Simulation simulation_;
  RunOptions options_;
  CommandSchedule schedule_;
  CommandSchedule::Report command_due_ = [](const TimedCommand&, const std::string&) {};
  std::vector<std::unique_ptr<RunStream>> streams_;
  bool run_end_set_ = false;
};

}  // namespace friction
