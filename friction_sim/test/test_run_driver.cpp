// The run driver: the one loop of the offline runner, the simulator node and the tests. Its streams
// sample on their own clocks and never change the run; its commands and run end act as the rig's.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "friction_sim/instruments/results_io.h"
#include "friction_sim/run/run_driver.h"
#include "test_helpers.h"

namespace friction::testing {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// The single block pushed at V = 0.4 mm/s through K = 4 MN/m under F_Z = 1920 N, µ_s = 0.4: stuck, F_X =
/// K·V·t until K·V·t = µ_s·F_Z at t = 0.48 s (MODEL.md §7.1).
Scene blockScene(bool fast_forward, double stop_time) {
  Scene scene = loadScene(scenePath("single_block"));
  scene.integrator.fast_forward = fast_forward;
  scene.stop.time = stop_time;
  return scene;
}
constexpr double kStageStiffness = 4.0e6, kStageSpeed = 4.0e-4, kFirstSlip = 0.4 * 1920.0 / (4.0e6 * 4.0e-4);

/// Every stream the simulator node registers, at its default rates, each counting what it receives.
struct Counts {
  int clock = 0, cells = 0, gauges = 0, frames = 0, started = 0, ended = 0, stage = 0, lattice = 0;
};
void addEveryStream(RunDriver& driver, Counts& counts) {
  driver.add(std::make_unique<SampledStream<Instant>>(
      1e4, Sampling::AtSteps, [](const Simulation& s) { return Instant{s.time()}; },
      [&counts](const Instant&) { ++counts.clock; }));
  driver.add(std::make_unique<SampledStream<LoadCellReading>>(
      1e4, Sampling::AtSteps, [](const Simulation& s) { return s.loadCells(); },
      [&counts](const LoadCellReading&) { ++counts.cells; }, true));
  driver.add(std::make_unique<SampledStream<GaugeProfile>>(
      SampleRates{1e5, 1e3}, Sampling::AtSteps, [](const Simulation& s) { return s.gaugeProfile(); },
      [&counts](const GaugeProfile&) { ++counts.gauges; }));
  driver.add(
      std::make_unique<CameraStream>(SampleRates{1e5, 100.0}, [&counts](const InterfaceFrame&) { ++counts.frames; }));
  driver.add(std::make_unique<EventStream>([&counts](const Simulation&) { ++counts.started; },
                                           [&counts](const Simulation&, const SlipEvent&) { ++counts.ended; }));
  driver.add(std::make_unique<SampledStream<StageStateReading>>(
      1e3, Sampling::AtSteps, stageState, [&counts](const StageStateReading&) { ++counts.stage; }));
  driver.add(std::make_unique<SampledStream<LatticeSnapshot>>(
      SampleRates{1e4, 50.0}, Sampling::AtSteps, [](const Simulation& s) { return s.snapshot(); },
      [&counts](const LatticeSnapshot&) { ++counts.lattice; }));
}

TEST(RunDriver, StreamsNeverChangeTheRun) {
  // The simulator node's streams against none, on a 2D slider with fast-forward to its first global
  // event: the same state to the last bit, and the same events.
  const Scene scene = coarseSliderScene(true);
  const double limit = requireValidScene(scene);
  RunDriver bare(scene, limit), watched(scene, limit);
  Counts counts;
  addEveryStream(watched, counts);
  bare.run();
  watched.run();
  EXPECT_GT(watched.simulation().jumps(), 0);
  EXPECT_EQ(watched.simulation().stateHash(), bare.simulation().stateHash());
  ASSERT_EQ(watched.simulation().events().size(), bare.simulation().events().size());
  const double t = watched.simulation().time();
  // Each clock's samples: one per period up to the end, none at t = 0.
  EXPECT_EQ(counts.clock, static_cast<int>(std::floor(t * 1e4 + 1e-9)));
  EXPECT_EQ(counts.stage, static_cast<int>(std::floor(t * 1e3 + 1e-9)));
  // Those with an event rate: at least their idle clock's samples.
  EXPECT_GE(counts.lattice, static_cast<int>(std::floor(t * 50.0 + 1e-9)));
  EXPECT_GE(counts.gauges, static_cast<int>(std::floor(t * 1e3 + 1e-9)));
  // The load cells also at each event's first and last step.
  const int events = static_cast<int>(watched.simulation().events().size());
  EXPECT_GE(counts.cells, counts.clock + events);
  EXPECT_LE(counts.cells, counts.clock + 2 * events);
  EXPECT_EQ(counts.started, events);
  EXPECT_EQ(counts.ended, events);
  EXPECT_GE(counts.frames, static_cast<int>(std::floor(t * 100.0 + 1e-9)));
}

TEST(RunDriver, InterpolatedSamplesLieOnTheirClockAndOnTheLoadingLine) {
  // Fast-forward jumps from t = 0 to just before the first slip: the samples across them lie on
  // F_X = K·V·t, at k milliseconds.
  RunDriver driver(blockScene(true, 0.4005), requireValidScene(blockScene(true, 0.4005)));
  std::vector<LoadCellReading> samples;
  driver.add(std::make_unique<SampledStream<LoadCellReading>>(
      1e3, Sampling::Interpolated, [](const Simulation& s) { return s.loadCells(); },
      [&samples](const LoadCellReading& reading) { samples.push_back(reading); }));
  driver.run();
  EXPECT_GT(driver.simulation().jumps(), 0);
  ASSERT_EQ(samples.size(), 400U);
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const double t = (k + 1) * 1e-3;
    EXPECT_NEAR(samples[k].time, t, 1e-12);
    EXPECT_NEAR(samples[k].shear_force, kStageStiffness * kStageSpeed * samples[k].time, 1e-9 * 640.0) << t;
  }
}

TEST(RunDriver, SamplesAtStepsComeAtTheFirstStepEndOnOrAfterTheirTime) {
  const Scene scene = blockScene(false, 0.01);
  RunDriver driver(scene, requireValidScene(scene));
  std::vector<double> times;
  driver.add(std::make_unique<SampledStream<Instant>>(
      1e3, Sampling::AtSteps, [](const Simulation& s) { return Instant{s.time()}; },
      [&times](const Instant& instant) { times.push_back(instant.time); }));
  driver.run();
  ASSERT_EQ(times.size(), 10U);
  for (std::size_t k = 0; k < times.size(); ++k) {
    const double due = (k + 1) * 1e-3;
    EXPECT_GE(times[k], due - 1e-12);
    EXPECT_LT(times[k], due + scene.integrator.time_step);
  }
}

/// A reading that remembers whether a slip event ran when it was taken, or that it was interpolated
/// across a jump.
struct EventFlag {
  double time = 0.0;
  bool in_event = false;
  bool interpolated = false;
};
EventFlag interpolate(const EventFlag& /*a*/, const EventFlag& /*b*/, double t) { return {t, false, true}; }

/// Runs `scene` with a stream at the gauges' default rates, 1e5 Hz while an event runs and 1e3 Hz while
/// all sticks, and checks its clock: within 10 µs (give or take a step) after each sample taken in an
/// event, a millisecond between samples of the loading and across jumps, and no faster than the idle
/// rate between events. With `events_stepped` (no jump inside an event), each event also gets a sample
/// every 10 µs of its length.
void expectEventAndIdleRates(const Scene& scene, bool events_stepped) {
  RunDriver driver(scene, requireValidScene(scene));
  std::vector<EventFlag> samples;
  driver.add(std::make_unique<SampledStream<EventFlag>>(
      SampleRates{1e5, 1e3}, Sampling::AtSteps,
      [](const Simulation& s) {
        return EventFlag{s.time(), s.inEvent()};
      },
      [&samples](const EventFlag& sample) { samples.push_back(sample); }));
  driver.run();
  EXPECT_GT(driver.simulation().jumps(), 0);
  const std::vector<SlipEvent>& events = driver.simulation().events();
  ASSERT_GE(events.size(), 3U);
  const double dt = scene.integrator.time_step;
  auto onset_between = [&events](double a, double b) {
    return std::any_of(events.begin(), events.end(),
                       [a, b](const SlipEvent& e) { return e.onset_time >= a && e.onset_time <= b; });
  };
  int in_events = 0, idle_gaps = 0, interpolated_gaps = 0;
  for (std::size_t k = 0; k + 1 < samples.size(); ++k) {
    const EventFlag &sample = samples[k], &next = samples[k + 1];
    const double gap = next.time - sample.time;
    if (sample.interpolated && next.interpolated && !onset_between(sample.time, next.time)) {
      ++interpolated_gaps;
      EXPECT_NEAR(gap, 1e-3, 1e-12) << "after t = " << sample.time;
    } else if (sample.in_event) {
      ++in_events;
      EXPECT_LE(gap, 1e-5 + dt + 1e-12) << "after t = " << sample.time;
    } else if (!next.in_event && !onset_between(sample.time, next.time)) {
      ++idle_gaps;
      EXPECT_NEAR(gap, 1e-3, dt + 1e-12) << "after t = " << sample.time;
    }
  }
  if (events_stepped) {
    // A sample at most 10 µs + dt after the one before, from the event's first step on.
    for (const SlipEvent& event : events) {
      const auto inside = std::count_if(samples.begin(), samples.end(), [&event](const EventFlag& sample) {
        return sample.time >= event.onset_time && sample.time <= event.end_time;
      });
      EXPECT_GE(inside, std::floor((event.end_time - event.onset_time - 2.0 * dt) / 1e-5)) << event.index;
    }
  }
  EXPECT_GT(in_events, 0);
  EXPECT_GT(idle_gaps + interpolated_gaps, 0);
  EXPECT_GT(interpolated_gaps, 0);
  // Between events no faster than the idle rate: one sample per millisecond, and one more per event.
  EXPECT_LE(samples.size() - in_events, driver.simulation().time() * 1e3 + events.size() + 1);
}

TEST(RunDriver, StreamsWithAnEventRateSampleFastInEventsAndSlowlyBetween) {
  // The 2D slider with precursors and fast-forward between them.
  expectEventAndIdleRates(coarseSliderScene(true), true);
}

TEST(RunDriver, StreamsWithAnEventRateKeepTheIdleClockAcrossCreepSteps) {
  // With rate-and-state friction, fast-forward's quasi-static creep steps are jumps, and an event may
  // start at the end of one: the jump's samples keep the idle clock all the same.
  Scene scene = coarseSliderScene(true);
  scene.friction.law = FrictionLawKind::RateState;
  scene.instruments.event_slip_speed = 1e-3;
  scene.stop.global_events = 1;
  expectEventAndIdleRates(scene, false);
}

TEST(RunDriver, RatesSetAgainUnchangedLeaveTheClocksAlone) {
  // dynamic_reconfigure's first call carries the settings as they are: no stream may take a sample early.
  CameraStream camera({1e5, 100.0}, [](const InterfaceFrame&) {});
  SampledStream<Instant> gauges(
      {1e5, 1e3}, Sampling::AtSteps, [](const Simulation& s) { return Instant{s.time()}; }, [](const Instant&) {});
  EXPECT_EQ(camera.nextTime(), 0.01);
  EXPECT_EQ(gauges.nextTime(), 1e-3);
  camera.setRates({1e5, 100.0}, 0.002);
  gauges.setRates({1e5, 1e3}, 0.0002);
  EXPECT_EQ(camera.nextTime(), 0.01);
  EXPECT_EQ(gauges.nextTime(), 1e-3);
  // New rates bring the next sample within a period of the camera's fastest and of the stream's idle one.
  camera.setRates({2e5, 100.0}, 0.002);
  gauges.setRates({1e5, 1e4}, 0.0002);
  EXPECT_DOUBLE_EQ(camera.nextTime(), 0.002 + 5e-6);
  EXPECT_DOUBLE_EQ(gauges.nextTime(), 0.0002 + 1e-4);
}

TEST(RunDriver, PacedRunsEndTheirJumpsAtTheCamerasFrames) {
  // Cut at frames, every idle frame of the stuck block is a jump's end, at its time on the clock; uncut,
  // one jump covers the whole 0.1 s and its frames are interpolated.
  const Scene scene = blockScene(true, 0.1);
  for (bool cut : {false, true}) {
    RunOptions options;
    options.cut_jumps_at_frames = cut;
    RunDriver driver(scene, requireValidScene(scene), options);
    std::vector<InterfaceFrame> frames;
    driver.add(std::make_unique<CameraStream>(SampleRates{1e5, 100.0},
                                              [&frames](const InterfaceFrame& f) { frames.push_back(f); }));
    driver.run();
    ASSERT_EQ(frames.size(), 10U) << cut;
    for (std::size_t k = 0; k < frames.size(); ++k) EXPECT_NEAR(frames[k].time, (k + 1) * 0.01, 1e-12);
    if (cut) {
      EXPECT_GE(driver.simulation().jumps(), 10);
    } else {
      EXPECT_LT(driver.simulation().jumps(), 10);
    }
  }
}

TEST(RunDriver, CommandsActWhenDueAndTheRunEndsAtTheRunEndSet) {
  // Without the scene's end, the run ends only at the end set: the first global event, whose onset is
  // where K·V·(t − t₀) = µ_s·F_Z for a stage started at t₀ = 0.1 s by a command.
  Scene scene = blockScene(false, 5.0);
  scene.stage.program = {StageSegment{StageMode::Hold, 0.0}};
  RunOptions options;
  options.stop_at_scene_end = false;
  RunDriver driver(scene, requireValidScene(scene), options);
  TimedCommand start;
  start.time = 0.1;
  start.stage = {StageMode::Velocity, kStageSpeed, 0.0};
  driver.schedule(start);
  std::vector<double> applied_at;
  driver.onCommandDue([&](const TimedCommand&, const std::string& refusal) {
    EXPECT_EQ(refusal, "");
    applied_at.push_back(driver.simulation().time());
  });
  EXPECT_EQ(driver.setRunEnd({1, kInf, kInf}), "");
  EXPECT_NE(driver.setRunEnd({-1, kInf, kInf}), "");
  driver.run();
  ASSERT_EQ(applied_at.size(), 1U);
  EXPECT_NEAR(applied_at[0], 0.1, 1e-12);
  ASSERT_EQ(driver.simulation().events().size(), 1U);
  EXPECT_NEAR(driver.simulation().events()[0].onset_time, 0.1 + kFirstSlip, 2.0 * scene.integrator.time_step);
}

TEST(RunDriver, AnEventUnderWayWhereTheRunStopsIsReportedUnfinished) {
  // The block slips from t = 0.48 s for half a period, π·√(m/K) = 0.43 ms; the run stops 0.2 ms in, when
  // it has slid Δ·(1 − cos ωτ) + V·τ with Δ = (µ_s − µ_k)·F_Z/K and ω = √(K/m) (MODEL.md §7.1).
  const double into_slip = 2e-4;
  const Scene scene = blockScene(false, kFirstSlip + into_slip);
  RunDriver driver(scene, requireValidScene(scene));
  Counts counts;
  addEveryStream(driver, counts);
  driver.run();
  ASSERT_TRUE(driver.simulation().events().empty());
  ASSERT_TRUE(driver.simulation().inEvent());
  driver.finishRun();
  const Simulation& simulation = driver.simulation();
  ASSERT_EQ(simulation.events().size(), 1u);
  EXPECT_EQ(counts.ended, 1);
  const SlipEvent& event = simulation.events()[0];
  EXPECT_TRUE(event.unfinished);
  EXPECT_EQ(event.end_time, simulation.time());
  const double mass = scene.material.density * scene.geometry.length * scene.geometry.height * scene.geometry.width;
  const double drop =
      (scene.friction.static_coefficient - scene.friction.kinetic_coefficient) * 1920.0 / kStageStiffness;
  const double slipping = simulation.time() - event.onset_time;  // the run ends on a step: up to dt past its stop
  const double slid = drop * (1.0 - std::cos(std::sqrt(kStageStiffness / mass) * slipping)) + kStageSpeed * slipping;
  EXPECT_NEAR(event.node_slip[0] / slid, 1.0, 1e-3);
  EXPECT_TRUE(summarize(simulation, 0.0).events.last_event_unfinished);
  // Nothing more to end.
  driver.finishRun();
  EXPECT_EQ(simulation.events().size(), 1u);
}

TEST(RunDriver, CommandsStampedPastAKnownRunEndAreRefused) {
  const Scene scene = blockScene(false, 1.0);
  const double limit = requireValidScene(scene);
  TimedCommand late;
  late.time = 2.0;
  late.stage = {StageMode::Hold, 0.0, 0.0};
  TimedCommand due = late;
  due.time = 0.5;
  RunDriver ending(scene, limit);
  EXPECT_EQ(ending.checkCommandTime(late),
            "stamped at t = 2 s, after the run's end at t = 1 s: it would never be applied");
  EXPECT_EQ(ending.checkCommandTime(due), "");
  // Where the scene's end does not end the run (a controller drives it), any time may come, until a
  // run end is set.
  RunOptions open_ended;
  open_ended.stop_at_scene_end = false;
  RunDriver controlled(scene, limit, open_ended);
  EXPECT_EQ(controlled.checkCommandTime(late), "");
  ASSERT_EQ(controlled.setRunEnd(StopSpec{0, 3.0, kInf}), "");
  EXPECT_EQ(controlled.checkCommandTime(late), "");
  late.time = 4.0;
  EXPECT_NE(controlled.checkCommandTime(late).find("after the run's end at t = 3 s"), std::string::npos);
}

}  // namespace
}  // namespace friction::testing
