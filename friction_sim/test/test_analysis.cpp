// The ROS-free cores of the controller and the precursor detector: the loading protocol and its
// schedule, and the instrument-only event detector against the simulator's own events.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include "friction_sim/instruments/frame_event_detector.h"
#include "friction_sim/instruments/results_io.h"
#include "friction_sim/run/command_schedule.h"
#include "friction_sim/run/simulation.h"
#include "friction_sim/scene/loading_protocol.h"
#include "test_helpers.h"

namespace friction {
namespace {

TEST(LoadingProtocol, RampHoldDriveBecomesATimedSchedule) {
  const LoadingProtocol protocol = parseProtocol(
      "steps:\n"
      "  - {action: normal_load, normal_force: 2000, ramp_time: 0.01}\n"
      "  - {action: hold, duration: 0.005}\n"
      "  - {action: drive, speed: 4.0e-4, duration: 0.1}\n"
      "  - {action: move_to, speed: 1.0e-3, target: 0.0, duration: .inf}\n"
      "end: {global_events: 3}\n"
      "ramp_commands: 4\n");
  const auto whole = scheduleProtocol(protocol, 1.0, 1000.0);
  ASSERT_EQ(whole.size(), 1u + 4u + 3u);
  // The stage holds from the start while F_Z ramps: the protocol drives it, not the scene's program
  // (which had driven it through stop_and_go's ramp).
  EXPECT_EQ(whole[0].kind, TimedCommand::Kind::Stage);
  EXPECT_EQ(whole[0].stage.mode, StageMode::Hold);
  EXPECT_DOUBLE_EQ(whole[0].time, 1.0);
  const std::vector<TimedCommand> schedule(whole.begin() + 1, whole.end());
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(schedule[k].kind, TimedCommand::Kind::NormalLoad);
    EXPECT_DOUBLE_EQ(schedule[k].time, 1.0 + 0.0025 * k);
    EXPECT_DOUBLE_EQ(schedule[k].normal_force, 1000.0 + 250.0 * (k + 1));
  }
  EXPECT_EQ(schedule[4].stage.mode, StageMode::Hold);
  EXPECT_DOUBLE_EQ(schedule[4].time, 1.01);
  EXPECT_EQ(schedule[5].stage.mode, StageMode::Velocity);
  EXPECT_DOUBLE_EQ(schedule[5].time, 1.015);
  EXPECT_EQ(schedule[6].stage.mode, StageMode::Position);
  EXPECT_DOUBLE_EQ(schedule[6].time, 1.115);
  // A protocol that starts with a stage step needs no hold before it.
  const auto driven = scheduleProtocol(parseProtocol("steps:\n  - {action: drive, speed: 4.0e-4, duration: .inf}\n"
                                                     "end: {global_events: 1}\n"),
                                       0.0, 1000.0);
  ASSERT_EQ(driven.size(), 1u);
  EXPECT_EQ(driven[0].stage.mode, StageMode::Velocity);
  // Its end, from a start at t = 5 s: the third global event ends it, whenever it comes.
  const StopSpec stop = protocol.end.stopFrom(5.0);
  EXPECT_FALSE(stopReached(stop, 2, 15.0, 0.0));
  EXPECT_TRUE(stopReached(stop, 3, 15.0, 0.0));
}

/// Expects the protocol text refused with exactly `problems.size()` problems, each containing one of
/// `problems`.
void expectProtocolRefused(const std::string& yaml, const std::vector<std::string>& problems) {
  try {
    parseProtocol(yaml);
    ADD_FAILURE() << "accepted";
  } catch (const ConfigError& error) {
    const std::string text = error.what();
    EXPECT_EQ(error.problems().size(), problems.size()) << text;
    for (const std::string& problem : problems) EXPECT_NE(text.find(problem), std::string::npos) << text;
  }
}

TEST(LoadingProtocol, BadProtocolListsEveryProblem) {
  expectProtocolRefused(
      "steps:\n"
      "  - {action: normal_load, normal_force: -5}\n"
      "  - {action: drive, speed: .nan, duration: .inf}\n"
      "  - {action: jump}\n"  // refused alone: its other keys are not checked against a guessed action
      "  - {action: hold, duration: 1.0}\n"
      "end: {global_events: -1, cycles: 3}\n",
      {"steps[0].normal_force: value -5", "steps[1].speed: value nan", "steps[1].duration: value inf",
       "steps[2].action: value 'jump'", "end.cycles: unknown key", "end.global_events: value -1"});
}

TEST(LoadingProtocol, AFieldItsStepDoesNotActWithIsRefusedNamingWhatItTakes) {
  // A writer who gives a normal_load a duration, or a hold a speed, expects it to act; it would not.
  expectProtocolRefused(
      "steps:\n"
      "  - {action: normal_load, normal_force: 2000, duration: 0.1}\n"
      "  - {action: hold, speed: 4.0e-4, duration: 0.1}\n"
      "  - {action: drive, speed: 4.0e-4, target: 0.01, duration: .inf}\n"
      "end: {global_events: 1}\n",
      {"steps[0].duration: unknown key; allowed keys here: action, normal_force, ramp_time",
       "steps[1].speed: unknown key; allowed keys here: action, duration",
       "steps[2].target: unknown key; allowed keys here: action, duration, speed"});
}

TEST(LoadingProtocol, WhatAStepActsWithAndAnEndMustBeGiven) {
  // A move_to without its target drove the stage back to 0, and a protocol without an end ran (and
  // recorded) until stopped. Each missing field is named once, not
  // also by its default's value.
  expectProtocolRefused(
      "steps:\n"
      "  - {action: move_to, speed: 1.0e-3, duration: 0.05}\n"
      "  - {action: drive, duration: 0.1}\n"
      "  - {action: normal_load, ramp_time: 0.01}\n"
      "  - {action: hold, duration: .inf}\n",
      {"steps[0].target: not given; needed: the stage position to move to, m",
       "steps[1].speed: not given; needed: the stage's speed, m/s",
       "steps[2].normal_force: not given; needed: the F_Z to reach, N",
       "end: no condition, so the run would never end"});
}

TEST(CommandTable, ReadsEachCommandWithTheTimeTheRigComparedItsClockWith) {
  const auto commands = parseCommandTable(
      "time_s,command,speed_m_s,target_m,normal_force_N\n"
      "0.000000000,hold,,,\n"
      "0.130000200,velocity,-0.0004,,\n"
      "0.2,position,0.001,1.5e-4,\n"
      "1.000000001,normal_load,,,2500\n");
  ASSERT_EQ(commands.size(), 4u);
  EXPECT_EQ(commands[0].kind, TimedCommand::Kind::Stage);
  EXPECT_EQ(commands[0].stage.mode, StageMode::Hold);
  EXPECT_EQ(commands[0].time, 0.0);
  EXPECT_EQ(commands[1].stage.mode, StageMode::Velocity);
  EXPECT_EQ(commands[1].stage.speed, -4e-4);
  // Whole seconds plus nanoseconds, summed as ros::Time::toSec() sums a stamp's: the double the rig
  // compared its clock with, which the nearest double to the decimal text need not be.
  EXPECT_EQ(commands[1].time, 0.0 + 1e-9 * 130000200.0);
  EXPECT_EQ(commands[2].stage.mode, StageMode::Position);
  EXPECT_EQ(commands[2].stage.speed, 1e-3);
  EXPECT_EQ(commands[2].stage.target, 1.5e-4);
  EXPECT_EQ(commands[2].time, 0.0 + 1e-9 * 200000000.0);
  EXPECT_EQ(commands[3].kind, TimedCommand::Kind::NormalLoad);
  EXPECT_EQ(commands[3].normal_force, 2500.0);
  EXPECT_EQ(commands[3].time, 1.0 + 1e-9 * 1.0);
}

TEST(CommandTable, BadTableListsEveryProblemWithItsLine) {
  try {
    parseCommandTable(
        "time_s,command,speed_m_s,target_m,normal_force_N\n"
        "0.1,hold,0.0004,,\n"
        "0.05,velocity,,,\n"
        "-1,jump,,,\n"
        "0.2,position,0.001\n"
        "inf,normal_load,,,abc\n",
        "run/stage_commands.csv");
    ADD_FAILURE() << "accepted";
  } catch (const ConfigError& error) {
    const std::string text = error.what();
    const std::vector<std::string> problems{
        "run/stage_commands.csv, line 2: hold takes no speed_m_s, got '0.0004'; leave it empty",
        "run/stage_commands.csv, line 3: time_s 0.05 is earlier than the row before; allowed: rows in time order",
        "run/stage_commands.csv, line 3: velocity needs speed_m_s as a number, got ''",
        "run/stage_commands.csv, line 4: time_s '-1' is not allowed; allowed: a finite time >= 0 s",
        "run/stage_commands.csv, line 4: command 'jump' is unknown; allowed: velocity, hold, position, normal_load",
        "run/stage_commands.csv, line 5: 5 fields expected (time_s, command, speed_m_s, target_m, normal_force_N), "
        "got 3",
        "run/stage_commands.csv, line 6: time_s 'inf' is not allowed",
        "run/stage_commands.csv, line 6: normal_load needs normal_force_N as a number, got 'abc'"};
    EXPECT_EQ(error.problems().size(), problems.size()) << text;
    for (const std::string& problem : problems)
      EXPECT_NE(text.find(problem), std::string::npos) << problem << "\n" << text;
  }
  try {
    parseCommandTable("time,mode\n0,hold\n");
    ADD_FAILURE() << "accepted";
  } catch (const ConfigError& error) {
    EXPECT_NE(std::string(error.what())
                  .find("line 1: the header must be 'time_s,command,speed_m_s,target_m,"
                        "normal_force_N', got 'time,mode'"),
              std::string::npos)
        << error.what();
  }
}

TEST(CommandTable, ARunRefusesWhatItsSceneRefusesAndAppliesTheRest) {
  Scene scene;
  scene.model = ModelKind::Chain1D;
  scene.chain.blocks = 1;
  Simulation simulation(scene);
  const auto commands = parseCommandTable(
      "time_s,command,speed_m_s,target_m,normal_force_N\n"
      "0,velocity,2.0,,\n"    // beyond stage.max_speed, 1 m/s
      "0,normal_load,,,-5\n"  // F_Z must be > 0
      "0,normal_load,,,2500\n"
      "0,position,0.001,2e-4,\n");
  EXPECT_NE(simulation.checkCommand(commands[0]).find("exceeds the stage's max_speed"), std::string::npos);
  EXPECT_NE(simulation.checkCommand(commands[1]).find("normal load -5 N is not allowed"), std::string::npos);
  EXPECT_EQ(simulation.checkCommand(commands[2]), "");
  EXPECT_NE(simulation.apply(commands[0]), "");
  EXPECT_EQ(simulation.stage().current().speed, scene.stage.program[0].speed);  // unchanged
  EXPECT_EQ(simulation.apply(commands[2]), "");
  EXPECT_EQ(simulation.loadCells().normal_force, 2500.0);
  EXPECT_EQ(simulation.apply(commands[3]), "");
  EXPECT_EQ(simulation.stage().current().mode, StageMode::Position);
  EXPECT_EQ(simulation.stage().current().target, 2e-4);
}

TEST(CommandSchedule, AppliesWhatIsDueInTimeOrderAndNamesWhereToCutTheNextJump) {
  Scene scene;
  scene.model = ModelKind::Chain1D;
  scene.chain.blocks = 1;
  scene.integrator.time_step = 1e-6;
  Simulation simulation(scene);
  auto stage = [](double time, StageMode mode, double speed) {
    TimedCommand command;
    command.time = time;
    command.stage = {mode, speed, 0.0};
    return command;
  };
  TimedCommand load;
  load.kind = TimedCommand::Kind::NormalLoad;
  load.normal_force = 2500.0;
  CommandSchedule schedule;
  EXPECT_TRUE(std::isinf(schedule.nextTime()));
  schedule.add(stage(1e-3, StageMode::Velocity, 4e-4));
  schedule.add(stage(0.0, StageMode::Velocity, 2.0));  // beyond max_speed: refused, and reported
  schedule.add(load);                                  // t = 0, after the one before
  std::vector<std::string> reports;
  auto report = [&](const TimedCommand& command, const std::string& refusal) {
    reports.push_back(std::to_string(command.time) + (refusal.empty() ? " applied" : " refused"));
  };
  EXPECT_EQ(schedule.nextTime(), 0.0);
  EXPECT_EQ(schedule.applyDue(simulation, report), 1);
  EXPECT_EQ(reports, (std::vector<std::string>{"0.000000 refused", "0.000000 applied"}));
  EXPECT_EQ(simulation.loadCells().normal_force, 2500.0);
  EXPECT_EQ(schedule.nextTime(), 1e-3);
  EXPECT_EQ(schedule.applyDue(simulation, report), 0);  // not due before its time
  for (int step = 0; step < 5; ++step) simulation.advance(schedule.nextTime());
  // A time recorded a third of a nanosecond after the step's (rounded to whole nanoseconds) is due on
  // that step with half a nanosecond's grace, not without.
  CommandSchedule exact, recorded(0.5e-9);
  exact.add(stage(simulation.time() + 0.3e-9, StageMode::Hold, 0.0));
  recorded.add(stage(simulation.time() + 0.3e-9, StageMode::Hold, 0.0));
  EXPECT_EQ(exact.applyDue(simulation, report), 0);
  EXPECT_EQ(recorded.applyDue(simulation, report), 1);
  EXPECT_EQ(simulation.stage().current().mode, StageMode::Hold);
}

TEST(FrontSpeeds, AFrontAt600MetresPerSecondLeavingANucleationPatch) {
  // Nodes 0–2 (2.5 mm apart) unstick together; a front then runs at 600 m/s up to node 10; node 11 holds.
  const double spacing = 0.0025, speed = 600.0;
  std::vector<double> positions, first_unstick;
  for (int node = 0; node < 12; ++node) {
    positions.push_back(node * spacing);
    first_unstick.push_back(node <= 2 ? 0.0 : (node - 2) * spacing / speed);
  }
  first_unstick[11] = std::nan("");
  const std::vector<double> v_c = frontSpeeds(positions, first_unstick, 5);
  // A five-node fit is exact where all five lie on the front; the patch's fits are apparent speeds.
  EXPECT_TRUE(std::isinf(v_c[0]));
  EXPECT_NEAR(v_c[1], 2000.0, 1e-9);
  EXPECT_NEAR(v_c[2], 1200.0, 1e-9);
  EXPECT_NEAR(v_c[3], 750.0, 1e-9);
  for (int node = 4; node <= 10; ++node) EXPECT_NEAR(v_c[node], speed, 1e-9) << "node " << node;
  EXPECT_TRUE(std::isnan(v_c[11]));

  Scene scene;  // pmma_2d
  const WaveSpeeds c = waveSpeeds(scene);
  EXPECT_NEAR(c.shear, 968.25, 0.01);          // √(3E/8ρ)
  EXPECT_NEAR(c.longitudinal, 1677.05, 0.01);  // √3·c_S, plane stress with ν = 1/3
  // c_R/c_S = ξ solves the Rayleigh equation (2 − ξ²)² = 4·√(1 − ξ²)·√(1 − ξ²·c_S²/c_L²).
  const double k2 = std::pow(c.shear / c.longitudinal, 2);
  auto rayleigh = [&](double xi) {
    return std::pow(2 - xi * xi, 2) - 4 * std::sqrt(1 - xi * xi) * std::sqrt(1 - xi * xi * k2);
  };
  double low = 0.5, high = 0.99;
  for (int i = 0; i < 60; ++i) (rayleigh(0.5 * (low + high)) < 0 ? low : high) = 0.5 * (low + high);
  EXPECT_NEAR(c.rayleigh / c.shear, low, 1e-3);
  // The median is the running front's: the patch (nodes 0–2, which unstuck first) and the fits whose
  // five-node window reaches into it (nodes 3 and 4) are left out.
  const FrontSpeedSummary summary = summarizeFrontSpeeds(v_c, first_unstick, 5, c.longitudinal);
  EXPECT_EQ(summary.left_out, 5);
  EXPECT_NEAR(summary.median, speed, 1e-9);
  // With c_L unknown (0) the patch is the same here: its nodes unstuck at the same time.
  const FrontSpeedSummary unknown = summarizeFrontSpeeds(v_c, first_unstick, 5, 0.0);
  EXPECT_EQ(unknown.left_out, 5);
  EXPECT_NEAR(unknown.median, speed, 1e-9);

  // A short precursor, arresting after node 5. Its fits next to the patch read fast but below c_L (1200
  // and 750 m/s): leaving out only fits above c_L would give a median of 675 m/s, not the front's 600.
  std::vector<double> short_unstick = first_unstick;
  std::fill(short_unstick.begin() + 6, short_unstick.end(), std::nan(""));
  const std::vector<double> short_v_c = frontSpeeds(positions, short_unstick, 5);
  EXPECT_NEAR(short_v_c[2], 1200.0, 1e-9);
  EXPECT_NEAR(short_v_c[3], 750.0, 1e-9);
  const FrontSpeedSummary short_front = summarizeFrontSpeeds(short_v_c, short_unstick, 5, c.longitudinal);
  EXPECT_EQ(short_front.left_out, 5);
  EXPECT_NEAR(short_front.median, speed, 1e-9);

  // The patch grows from the node that unstuck first through neighbours whose fits beat c_L: here nodes
  // 1 and 2 follow node 0 within nanoseconds, and node 1's fit beats c_L (node 2's window reaches the
  // running front and reads 1200 m/s again). The patch is nodes 0–1; their window, through node 3.
  std::vector<double> staggered = first_unstick;
  staggered[1] = 1e-9;
  staggered[2] = 2e-9;
  for (int node = 3; node <= 10; ++node) staggered[node] += 2e-9;
  const std::vector<double> staggered_v_c = frontSpeeds(positions, staggered, 5);
  EXPECT_GT(staggered_v_c[1], c.longitudinal);
  EXPECT_NEAR(staggered_v_c[2], 1200.0, 1.0);
  const FrontSpeedSummary staggered_front = summarizeFrontSpeeds(staggered_v_c, staggered, 5, c.longitudinal);
  EXPECT_EQ(staggered_front.left_out, 4);
  EXPECT_NEAR(staggered_front.median, speed, 1e-6);

  // Two spots that unstick at once are two patches, not one spanning the front between them: here node
  // 11 unsticks with node 0 while a front runs from node 0 through node 10.
  std::vector<double> two_spots(12);
  for (int node = 0; node < 12; ++node) two_spots[node] = node * spacing / speed;
  two_spots[11] = 0.0;
  const std::vector<double> two_spots_v_c = frontSpeeds(positions, two_spots, 5);
  const FrontSpeedSummary two_spots_front = summarizeFrontSpeeds(two_spots_v_c, two_spots, 5, c.longitudinal);
  EXPECT_EQ(two_spots_front.left_out, 6);  // nodes 0–2 and 9–11, whose windows hold node 0 or node 11
  EXPECT_NEAR(two_spots_front.median, speed, 1e-9);

  // A patch in the middle (nodes 5–7) with fronts running out both ways, and an even window (4 nodes:
  // 2 behind, 1 ahead): left out are the nodes whose window [node − 2, node + 1] holds a patch node, 4–9.
  std::vector<double> middle_positions, middle(13);
  for (int node = 0; node < 13; ++node) {
    middle_positions.push_back(node * spacing);
    middle[node] = (node < 5 ? 5 - node : node > 7 ? node - 7 : 0) * spacing / speed;
  }
  const std::vector<double> middle_v_c = frontSpeeds(middle_positions, middle, 4);
  const FrontSpeedSummary middle_front = summarizeFrontSpeeds(middle_v_c, middle, 4, c.longitudinal);
  EXPECT_EQ(middle_front.left_out, 6);
  EXPECT_NEAR(middle_front.median, speed, 1e-9);

  // Away from the patch only fits above c_L are left out (with c_L unknown, infinite ones); an even
  // count takes the mean of the middle two.
  const double infinity = std::numeric_limits<double>::infinity();
  const std::vector<double> times{0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0};
  const std::vector<double> fits{500.0, 500.0, 500.0, 600.0, 750.0, 1200.0, 1500.0, 5000.0, infinity};
  const FrontSpeedSummary elsewhere = summarizeFrontSpeeds(fits, times, 5, c.longitudinal);
  EXPECT_EQ(elsewhere.left_out, 5);  // nodes 0–2 (the patch, node 0, and its window), 5000 m/s and inf
  EXPECT_NEAR(elsewhere.median, 975.0, 1e-9);
  const FrontSpeedSummary elsewhere_unknown = summarizeFrontSpeeds(fits, times, 5, 0.0);
  EXPECT_EQ(elsewhere_unknown.left_out, 4);
  EXPECT_NEAR(elsewhere_unknown.median, 1200.0, 1e-9);

  // An even window is as long as asked: two nodes are the difference from the node behind.
  const std::vector<double> pairs = frontSpeeds(positions, first_unstick, 2);
  EXPECT_TRUE(std::isnan(pairs[0]));  // nothing behind it
  EXPECT_TRUE(std::isinf(pairs[1]));
  EXPECT_TRUE(std::isinf(pairs[2]));
  for (int node = 3; node <= 10; ++node) EXPECT_NEAR(pairs[node], speed, 1e-9) << "node " << node;
  EXPECT_TRUE(std::isnan(pairs[11]));

  // All together: no front ran, so no median.
  const std::vector<double> all_at_once(12, 0.0);
  const FrontSpeedSummary together =
      summarizeFrontSpeeds(frontSpeeds(positions, all_at_once, 5), all_at_once, 5, c.longitudinal);
  EXPECT_EQ(together.left_out, 12);
  EXPECT_TRUE(std::isnan(together.median));
}

/// Runs `simulation` to its end and feeds `detector` as the simulator node publishes: frames every
/// 1e-5 s during events, every 0.01 s between them, and at every step where the interface changed
/// (Simulation::interfaceChangedLastStep); load cells every 1e-4 s and at the event boundaries. Returns
/// what it found. `after_step` sees the simulation after each step, `after_frame` each frame fed.
constexpr double kFrameIntervalBetweenEvents = 1e-2;  // s
std::vector<SlipEvent> eventsSeenByTheInstruments(Simulation& simulation, FrameEventDetector& detector,
                                                  const std::function<void()>& after_step = {},
                                                  const std::function<void(const InterfaceFrame&)>& after_frame = {}) {
  std::vector<SlipEvent> found;
  double next_frame = 0.0, next_cells = 0.0;
  while (!simulation.finished()) {
    simulation.step();
    if (after_step) after_step();
    const double t = simulation.time();
    const bool boundary = simulation.eventStartedLastStep() || simulation.eventEndedLastStep();
    if (boundary || t >= next_cells) {
      detector.addLoadCells(simulation.loadCells());
      if (t >= next_cells) next_cells += 1e-4;
    }
    if (simulation.interfaceChangedLastStep() || t >= next_frame) {
      const InterfaceFrame frame = simulation.interfaceFrame();
      EXPECT_EQ(detector.addFrame(frame), "");
      if (after_frame) after_frame(frame);
      next_frame = t + (simulation.inEvent() ? 1e-5 : kFrameIntervalBetweenEvents);
    }
    for (SlipEvent& event : detector.takeCompletedEvents()) found.push_back(std::move(event));
  }
  return found;
}

/// Which events, and which nodes slipped in each: the instruments must agree with the simulator.
void expectTheSameEventsAndExtents(const std::vector<SlipEvent>& found, const std::vector<SlipEvent>& truth) {
  ASSERT_EQ(found.size(), truth.size());
  for (std::size_t e = 0; e < truth.size(); ++e) {
    SCOPED_TRACE("event " + std::to_string(e));
    EXPECT_EQ(found[e].global, truth[e].global);
    EXPECT_DOUBLE_EQ(found[e].rupture_length, truth[e].rupture_length);
    EXPECT_DOUBLE_EQ(found[e].slip_min_x, truth[e].slip_min_x);
    EXPECT_DOUBLE_EQ(found[e].nucleation_position, truth[e].nucleation_position);
  }
}

TEST(FrameEventDetector, FindsTheSimulatorsEventsFromTheInstrumentsAlone) {
  Simulation simulation(testing::coarseSideChainScene());
  FrameEventDetector detector(simulation.scene().instruments.front_fit_nodes,
                              waveSpeeds(simulation.scene()).longitudinal);
  const std::vector<SlipEvent> found = eventsSeenByTheInstruments(simulation, detector);
  EXPECT_DOUBLE_EQ(detector.sliderLength(), simulation.scene().geometry.length);
  const auto& truth = simulation.events();
  expectTheSameEventsAndExtents(found, truth);
  for (std::size_t e = 0; e < std::min(found.size(), truth.size()); ++e) {
    SCOPED_TRACE("event " + std::to_string(e));
    // The camera sees the onset at the end of the step; the simulator interpolates within it.
    EXPECT_NEAR(found[e].onset_time, truth[e].onset_time, simulation.timeStep());
    // F_X differs by at most one step of loading, K·V·dt.
    const Scene& scene = simulation.scene();
    const double one_step = scene.pusher.stiffness * scene.stage.program[0].speed * simulation.timeStep();
    EXPECT_NEAR(found[e].onset_shear_force, truth[e].onset_shear_force, one_step);
    EXPECT_DOUBLE_EQ(found[e].onset_normal_force, truth[e].onset_normal_force);
    // The mean F_X over the event from the load cells' samples (10 kHz and the event's boundary steps)
    // against the simulator's step-by-step mean: events of 5–600 µs are seen by few samples. Measured: at
    // most 0.16 of the event's force drop.
    EXPECT_NEAR(found[e].mean_shear_force, truth[e].mean_shear_force,
                0.25 * std::abs(truth[e].onset_shear_force - truth[e].end_shear_force));
    EXPECT_NEAR(found[e].mean_normal_force, truth[e].mean_normal_force, 1e-9 * truth[e].mean_normal_force);
    // Their slips agree, so their kinds do (where a creeping interface's camera counts creep into a
    // slip, a slip of a few nanometres may change sign and with it a back-slip's kind).
    EXPECT_EQ(found[e].kind, truth[e].kind);
    for (std::size_t node = 0; node < truth[e].node_slip.size(); ++node) {
      EXPECT_NEAR(found[e].node_slip[node], truth[e].node_slip[node], 1e-12);
    }
  }
}

TEST(FrameEventDetector, RateStateEventsEndOnTheirSlipSpeedWhileTheInterfaceCreeps) {
  // The rate-and-state slider on a coarse lattice (5 mm spacing), to its first global event. Its
  // trailing edge creeps from F_X/F_Z ≈ 0.1 on (nodes sliding at 1e-5 to 1e-4 m/s, under the 1e-3 m/s
  // of instruments.event_slip_speed): the events end while nodes still slide.
  Scene scene = loadScene(testing::scenePath("pmma_2d_rate_state"));
  scene.lattice.nodes_x = 29;
  scene.lattice.nodes_z = 16;
  scene.integrator.time_step = 4e-7;
  Simulation simulation(scene);
  const SlipCriterion criterion = slipCriterion(scene);
  ASSERT_GT(criterion.speed, 0.0);
  FrameEventDetector detector(scene.instruments.front_fit_nodes, waveSpeeds(scene).longitudinal, scene.geometry.length,
                              criterion);
  int most_sliding_at_an_end = 0;
  std::vector<SlipEvent> truth;  // more than the simulation keeps (SlipEventDetector::kKeptEvents)
  const std::vector<SlipEvent> found = eventsSeenByTheInstruments(simulation, detector, [&] {
    if (simulation.eventEndedLastStep()) {
      most_sliding_at_an_end = std::max(most_sliding_at_an_end, simulation.loadCells().sliding_nodes);
      truth.push_back(simulation.events().back());
    }
  });
  ASSERT_EQ(simulation.globalEventCount(), 1);
  EXPECT_GT(most_sliding_at_an_end, 0);
  EXPECT_GE(truth.size(), 2u);
  expectTheSameEventsAndExtents(found, truth);
  for (std::size_t e = 0; e < std::min(found.size(), truth.size()); ++e) {
    SCOPED_TRACE("event " + std::to_string(e));
    // An event ends at the first moment of a quiet time with no node slipping, so the next starts after it.
    if (e > 0) {
      EXPECT_GE(truth[e].onset_time - truth[e - 1].end_time, criterion.quiet_time);
    }
    // The camera sees a crossing of the slip speed at the end of its step; the simulator interpolates.
    EXPECT_NEAR(found[e].onset_time, truth[e].onset_time, simulation.timeStep());
    EXPECT_NEAR(found[e].end_time, truth[e].end_time, simulation.timeStep());
    // The camera's slip counts from its last frame with no node slipping, up to one frame interval
    // before the onset: creep since then, slower than the slip speed, adds to it.
    for (std::size_t node = 0; node < truth[e].node_slip.size(); ++node) {
      EXPECT_NEAR(found[e].node_slip[node], truth[e].node_slip[node], criterion.speed * kFrameIntervalBetweenEvents);
      // The frames sample some of the steps whose largest slip speed the simulator keeps.
      EXPECT_LE(found[e].peak_slip_velocity[node], truth[e].peak_slip_velocity[node]);
      // Each frame comes at the end of a step; the simulator watches every step.
      if (!std::isnan(truth[e].last_slip_time[node])) {
        EXPECT_LE(found[e].last_slip_time[node], truth[e].last_slip_time[node]);
      }
    }
  }
}

TEST(SlipEvents, AnInterfaceThatCreepsGivesWayAtItsPeakForceNotAtItsFirstUnsticking) {
  // Slip weakening over ξ_µ = 10 µm is stable on the chain (its bonds, 5.4e8 N/m, are far stiffer than
  // the weakening, (µ_s − µ_k)·w/ξ_µ ≈ 7.7e5 N/m): the first block unsticks at F_X = µ_s·F_Z/57 and the
  // chain creeps on, taking load, in one event. Its peak is the largest F_X the load cell reads until
  // the last block has slipped.
  Scene scene = testing::coarseSideChainScene();
  scene.friction.law = FrictionLawKind::SlipWeakening;
  scene.friction.weakening_length = 1e-5;
  Simulation simulation(scene);
  std::vector<std::pair<double, double>> event_loads;  // (s, N): t and F_X at each step of the event
  while (!simulation.finished()) {
    simulation.step();
    if (simulation.inEvent() || simulation.eventEndedLastStep()) {
      event_loads.emplace_back(simulation.time(), simulation.loadCells().shear_force);
    }
  }
  ASSERT_EQ(simulation.events().size(), 1u);
  const SlipEvent& event = simulation.events()[0];
  ASSERT_TRUE(event.global);
  const double all_slipped = *std::max_element(event.first_unstick_time.begin(), event.first_unstick_time.end());
  double largest = 0.0;
  for (const auto& [time, shear_force] : event_loads) {
    if (time <= all_slipped) largest = std::max(largest, shear_force);
  }
  EXPECT_NEAR(event.onset_shear_force, scene.friction.static_coefficient * scene.load.normal_force / 57, 1e-3);
  // The step ends sample F_X; the peak, interpolated to the last first-unsticking, may exceed the last
  // sample by one step of loading, K·V·dt = 3.2e-4 N.
  EXPECT_NEAR(event.peak_shear_force, largest, 3.2e-4);
  EXPECT_GT(event.peakShearRatio(), 10.0 * event.onset_shear_force / event.onset_normal_force);
  EXPECT_EQ(summarize(simulation, 0.0).events.static_friction_macro, event.peakShearRatio());
}

TEST(FrameEventDetector, TheSingleBlocksSlipsSpanTheSliderAsTheSimulatorsDo) {
  // One interface node has no span: given the scene's L, its global slips have L_p = L, as the
  // simulator's events have.
  Simulation simulation(loadScene(testing::scenePath("single_block")));
  const Scene& scene = simulation.scene();
  FrameEventDetector detector(scene.instruments.front_fit_nodes, waveSpeeds(scene).longitudinal, scene.geometry.length);
  const std::vector<SlipEvent> found = eventsSeenByTheInstruments(simulation, detector);
  ASSERT_EQ(found.size(), 3u);
  expectTheSameEventsAndExtents(found, simulation.events());
  for (const SlipEvent& event : found) {
    EXPECT_TRUE(event.global);
    EXPECT_EQ(event.rupture_length, scene.geometry.length);
  }
}

TEST(SlipEvents, ASliderSlidingAsAWholeWithItsTrailingCornerLiftedSlipsGlobally) {
  // F_Z = 100 N pressing a slider pushed at its top edge: the trailing third of the interface lifts off
  // the track and stays off. Every node in contact slips in the stick-slip cycles: global events, which
  // end the run (before, a lifted node's missing slip made none global: 129 events in 0.05 s and no
  // µ_s,macro). The camera's detector agrees.
  Scene scene = testing::coarseSliderScene(false);
  scene.load.normal_force = 100.0;
  scene.pusher.height = 0.075;
  scene.friction.static_coefficient = 0.7;
  scene.friction.kinetic_coefficient = 0.5;
  scene.stop.time = 0.05;
  scene.stop.global_events = 1;
  Simulation simulation(scene);
  FrameEventDetector detector(scene.instruments.front_fit_nodes, waveSpeeds(scene).longitudinal, scene.geometry.length);
  const std::vector<SlipEvent> found = eventsSeenByTheInstruments(simulation, detector);
  ASSERT_EQ(simulation.globalEventCount(), 1) << simulation.stopReason();
  const SlipEvent& global = simulation.events().back();
  ASSERT_TRUE(global.global);
  const InterfaceFrame frame = simulation.interfaceFrame();
  int lifted = 0;
  for (std::size_t node = 0; node < frame.state.size(); ++node) {
    const bool off = frame.state[node] == static_cast<std::uint8_t>(ContactState::Detached);
    lifted += off;
    // The lifted nodes had no first unsticking, the others all had one.
    EXPECT_EQ(std::isnan(global.first_unstick_time[node]), off) << "node " << node;
  }
  EXPECT_GE(lifted, 5);
  EXPECT_LT(lifted, static_cast<int>(frame.state.size()) / 2);
  EXPECT_NEAR(global.rupture_length, scene.geometry.length - lifted * 0.005, 1e-12);
  expectTheSameEventsAndExtents(found, simulation.events());
}

TEST(FrameEventDetector, FramesThatDoNotFitAreLeftOutNamingWhyAndChangeNothing) {
  // After every frame, one whose states are a node short and, within events, one with a node more: from
  // a topic or a bag they may come, and the arrays index one another.
  Simulation simulation(testing::coarseSideChainScene());
  FrameEventDetector detector(simulation.scene().instruments.front_fit_nodes,
                              waveSpeeds(simulation.scene()).longitudinal);
  int left_out_in_events = 0;
  const std::vector<SlipEvent> found =
      eventsSeenByTheInstruments(simulation, detector, {}, [&](const InterfaceFrame& frame) {
        InterfaceFrame short_of_states = frame;
        short_of_states.state.pop_back();
        const std::string reason = detector.addFrame(short_of_states);
        EXPECT_NE(reason.find("is left out: its arrays differ in length (57 positions, 56 states, 57 slips"),
                  std::string::npos)
            << reason;
        if (!simulation.inEvent()) return;
        InterfaceFrame wider = frame;
        for (auto* values : {&wider.position, &wider.slip_velocity, &wider.slip}) values->push_back(0.0);
        wider.state.push_back(static_cast<std::uint8_t>(ContactState::Sliding));
        EXPECT_NE(detector.addFrame(wider).find("it has 58 nodes, the event under way 57"), std::string::npos);
        ++left_out_in_events;
      });
  EXPECT_GT(left_out_in_events, 0);
  expectTheSameEventsAndExtents(found, simulation.events());
}

TEST(FrameEventDetector, AnEventWaitingForItsLastReadingIsGivenWhenTheStreamRestarts) {
  // A run's last event ends on its last frame; the load cell of that step, on its own topic, may come
  // after a looped bag has started over. Without that reading it waits; told that no more come, it is
  // given from the rest.
  Simulation simulation(loadScene(testing::scenePath("single_block")));
  const Scene& scene = simulation.scene();
  FrameEventDetector detector(scene.instruments.front_fit_nodes, waveSpeeds(scene).longitudinal, scene.geometry.length);
  double next_cells = 0.0;
  detector.addFrame(simulation.interfaceFrame());  // all stuck
  while (!simulation.eventEndedLastStep()) {
    simulation.step();
    if (simulation.eventEndedLastStep()) break;  // its reading withheld
    if (simulation.time() >= next_cells || simulation.eventStartedLastStep()) {
      detector.addLoadCells(simulation.loadCells());
      next_cells += 1e-4;
    }
    if (simulation.interfaceChangedLastStep()) detector.addFrame(simulation.interfaceFrame());
  }
  detector.addFrame(simulation.interfaceFrame());
  EXPECT_TRUE(detector.takeCompletedEvents().empty());
  const std::vector<SlipEvent> given = detector.takeCompletedEvents(true);
  ASSERT_EQ(given.size(), 1u);
  EXPECT_TRUE(given[0].global);
  EXPECT_NEAR(given[0].onset_shear_force, simulation.events()[0].onset_shear_force,
              scene.pusher.stiffness * scene.stage.program[0].speed * 1e-4);
}

TEST(FrameEventDetector, StuckNodesMovingOnTheirInterfacialSpringsDidNotSlip) {
  // With k_T every stuck node moves a little as the load changes; only the nodes seen sliding slipped.
  Scene scene = testing::coarseSideChainScene();
  scene.friction.interfacial_stiffness = 1.0e8;
  Simulation simulation(scene);
  FrameEventDetector detector(scene.instruments.front_fit_nodes, waveSpeeds(scene).longitudinal);
  const std::vector<SlipEvent> found = eventsSeenByTheInstruments(simulation, detector);
  const auto& truth = simulation.events();
  expectTheSameEventsAndExtents(found, truth);
  // Counting any change of slip as a slip would make all 22 global.
  EXPECT_EQ(found.size(), 22u);
  EXPECT_EQ(std::count_if(found.begin(), found.end(), [](const SlipEvent& e) { return !e.global; }), 21);
}

}  // namespace
}  // namespace friction
