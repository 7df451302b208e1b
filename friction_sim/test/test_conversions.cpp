// Core structs to messages and back, command checks and node options — all without a master.
#include <gtest/gtest.h>

#include <cmath>

#include "friction_sim/ros/conversions.h"
#include "friction_sim/ros/node_parameters.h"
#include "friction_sim/ros/precursor_detector.h"
#include "friction_sim/ros/rig_simulator.h"
#include "friction_sim/ros/stage_controller.h"
#include "friction_sim/scene/config_error.h"
#include "friction_sim/scene/scene_io.h"
#include "friction_sim/solvers/integrator.h"

namespace friction {
namespace {

TEST(Conversions, LoadCellsAreTheWrenchOnTheSliderWithFzPressingDown) {
  LoadCellReading reading;
  reading.time = 0.25;
  reading.shear_force = 123.5;
  reading.normal_force = 1920.0;
  const auto msg = toMsg(reading, "slider");
  EXPECT_EQ(msg.header.stamp, ros::Time(0.25));
  EXPECT_EQ(msg.header.frame_id, "slider");
  EXPECT_DOUBLE_EQ(msg.wrench.force.x, 123.5);
  EXPECT_DOUBLE_EQ(msg.wrench.force.z, -1920.0);  // F_Z presses down: −z in REP 103
  EXPECT_DOUBLE_EQ(msg.wrench.force.y, 0.0);
  const LoadCellReading back = fromMsg(msg);
  EXPECT_DOUBLE_EQ(back.time, 0.25);
  EXPECT_DOUBLE_EQ(back.shear_force, 123.5);
  EXPECT_DOUBLE_EQ(back.normal_force, 1920.0);
  // A bag recorded before load_cells followed REP 103 holds +F_Z: read as the same load.
  geometry_msgs::WrenchStamped old = msg;
  old.wrench.force.z = 1920.0;
  EXPECT_DOUBLE_EQ(fromMsg(old).normal_force, 1920.0);
}

TEST(Conversions, InterfaceFrameRoundTrips) {
  InterfaceFrame frame;
  frame.time = 1.5e-3;
  frame.position = {0.0, 0.0025, 0.005};
  frame.state = {0, 1, 2};
  frame.slip_velocity = {0.0, 0.1, -0.2};
  frame.slip = {0.0, 1e-6, 2e-6};
  frame.normal_force = {30.0, 31.0, 0.0};
  frame.friction_force = {-3.0, -5.27, 0.0};
  frame.normal_stress = {2e6, 2.1e6, 0.0};
  frame.shear_stress = {2e5, 3.5e5, 0.0};
  frame.static_coefficient = {0.55, 0.43, 0.56};
  const auto msg = toMsg(frame, 42, "slider");
  EXPECT_EQ(msg.frame_index, 42u);
  EXPECT_EQ(msg.state[1], friction_msgs::InterfaceState::SLIDING);
  EXPECT_EQ(msg.state[2], friction_msgs::InterfaceState::DETACHED);
  const InterfaceFrame back = fromMsg(msg);
  EXPECT_DOUBLE_EQ(back.time, frame.time);
  EXPECT_EQ(back.state, frame.state);
  EXPECT_EQ(back.slip, frame.slip);
  EXPECT_EQ(back.friction_force, frame.friction_force);
  EXPECT_EQ(back.shear_stress, frame.shear_stress);
  EXPECT_EQ(back.static_coefficient, frame.static_coefficient);
}

TEST(Conversions, SlipEventKindsAreNumberedAsTheMessagesConstants) {
  EXPECT_EQ(static_cast<int>(SlipEventKind::Precursor), friction_msgs::SlipEvent::PRECURSOR);
  EXPECT_EQ(static_cast<int>(SlipEventKind::SingleNodeSlip), friction_msgs::SlipEvent::SINGLE_NODE_SLIP);
  EXPECT_EQ(static_cast<int>(SlipEventKind::BackSlip), friction_msgs::SlipEvent::BACK_SLIP);
  EXPECT_EQ(static_cast<int>(SlipEventKind::Global), friction_msgs::SlipEvent::GLOBAL);
  EXPECT_EQ(static_cast<int>(SlipEventKind::AfterGlobal), friction_msgs::SlipEvent::AFTER_GLOBAL);
}

TEST(Conversions, SlipEventCarriesEveryQuantity) {
  SlipEvent event;
  event.index = 3;
  event.onset_time = 0.1;
  event.end_time = 0.1004;
  event.onset_shear_force = 200.0;
  event.onset_normal_force = 1920.0;
  event.end_shear_force = 190.0;
  event.mean_shear_force = 180.0;
  event.mean_normal_force = 1921.0;
  event.nucleation_position = 0.0;
  event.slip_min_x = 0.0;
  event.slip_max_x = 0.05;
  event.rupture_length = 0.05;
  event.global = false;
  event.kind = SlipEventKind::AfterGlobal;
  event.node_slip = {1e-6, 5e-7, 0.0};
  event.first_unstick_time = {0.1, 0.10001, std::nan("")};
  event.front_speed = {250.0, 250.0, std::nan("")};
  event.median_front_speed = 250.0;
  event.front_fits_left_out = 1;
  const auto msg = toMsg(event, {0.0, 0.0025, 0.005}, 0.14, WaveSpeeds{1677.0, 968.0, 890.0}, "slider");
  EXPECT_EQ(msg.header.stamp, ros::Time(0.1004));
  EXPECT_DOUBLE_EQ(msg.slider_length, 0.14);
  EXPECT_DOUBLE_EQ(msg.rayleigh_speed, 890.0);
  EXPECT_DOUBLE_EQ(msg.shear_wave_speed, 968.0);
  EXPECT_DOUBLE_EQ(msg.longitudinal_wave_speed, 1677.0);
  const SlipEvent back = fromMsg(msg);
  EXPECT_EQ(back.index, 3);
  EXPECT_DOUBLE_EQ(back.onset_shear_force, 200.0);
  EXPECT_DOUBLE_EQ(back.end_shear_force, 190.0);
  EXPECT_DOUBLE_EQ(back.mean_shear_force, 180.0);
  EXPECT_DOUBLE_EQ(back.mean_normal_force, 1921.0);
  EXPECT_DOUBLE_EQ(back.rupture_length, 0.05);
  EXPECT_EQ(msg.kind, friction_msgs::SlipEvent::AFTER_GLOBAL);
  EXPECT_EQ(back.kind, SlipEventKind::AfterGlobal);
  EXPECT_EQ(back.node_slip, event.node_slip);
  EXPECT_TRUE(std::isnan(back.first_unstick_time[2]));
  EXPECT_DOUBLE_EQ(back.median_front_speed, 250.0);
  EXPECT_EQ(back.front_fits_left_out, 1);
  const auto point = toPointMsg(event, 0.14, "slider");
  EXPECT_DOUBLE_EQ(point.shear_ratio, 200.0 / 1920.0);
  EXPECT_DOUBLE_EQ(point.length_ratio, 0.05 / 0.14);
  EXPECT_EQ(point.header.stamp, ros::Time(0.1));
}

TEST(Conversions, CommandsRoundTripWithTheirTime) {
  TimedCommand load;
  load.kind = TimedCommand::Kind::NormalLoad;
  load.time = 0.02;
  load.normal_force = 2500.0;
  const auto load_msg = toMsg(load);
  EXPECT_EQ(load_msg.mode, friction_msgs::StageCommand::NORMAL_LOAD);
  EXPECT_EQ(fromMsg(load_msg).kind, TimedCommand::Kind::NormalLoad);
  EXPECT_DOUBLE_EQ(fromMsg(load_msg).normal_force, 2500.0);
  TimedCommand move;
  move.time = 0.5;
  move.stage = {StageMode::Position, 1e-3, 2e-4};
  const TimedCommand back = fromMsg(toMsg(move));
  EXPECT_EQ(back.stage.mode, StageMode::Position);
  EXPECT_DOUBLE_EQ(back.stage.speed, 1e-3);
  EXPECT_DOUBLE_EQ(back.stage.target, 2e-4);
  EXPECT_DOUBLE_EQ(back.time, 0.5);
}

TEST(Conversions, AStampCarriesTheTimeTheCoreRoundsCommandsTo) {
  // The offline runner applies a protocol's commands at stampSeconds(t), the time the rig reads from the
  // controller's stamp: the same double, so that its run is the live one to the last digit. Among them
  // a ramp's staircase, a time that rounds up into the next second and a time off the nanosecond grid.
  for (const double t : {0.0, 0.00025 * 3, 0.001, 0.1300002, 0.4006564345821, 1.9999999996, 16.022026744912, 1e-10}) {
    EXPECT_EQ(stampSeconds(t), ros::Time(t).toSec()) << t;
    TimedCommand command;
    command.time = t;
    EXPECT_EQ(stampSeconds(t), fromMsg(toMsg(command)).time) << t;
  }
}

TEST(CommandChecks, BadCommandsAreRefusedWithAReason) {
  Scene scene;
  scene.model = ModelKind::Chain1D;
  scene.chain.blocks = 3;
  const RunDriver driver(scene, sceneStabilityLimit(scene));
  const Simulation& simulation = driver.simulation();
  friction_msgs::StageCommand msg;
  msg.mode = friction_msgs::StageCommand::VELOCITY;
  msg.speed = -std::nan("");
  EXPECT_NE(checkCommand(msg, driver).find("speed nan m/s"), std::string::npos) << checkCommand(msg, driver);
  EXPECT_NE(checkCommand(msg, driver).find("finite"), std::string::npos);
  msg.speed = 2.0;
  EXPECT_NE(checkCommand(msg, driver).find("max_speed"), std::string::npos);
  msg.speed = 4e-4;
  EXPECT_EQ(checkCommand(msg, driver), "");
  msg.mode = friction_msgs::StageCommand::NORMAL_LOAD;
  msg.normal_force = 2500.0;
  EXPECT_EQ(checkCommand(msg, driver), "");
  msg.normal_force = -10.0;
  EXPECT_NE(checkCommand(msg, driver).find("normal load -10 N"), std::string::npos);
  msg.normal_force = std::numeric_limits<double>::infinity();
  EXPECT_NE(checkCommand(msg, driver).find("finite F_Z"), std::string::npos);
  // Beyond a small strain (10⁹ N was accepted and the run went NaN).
  msg.normal_force = 1e9;
  const double largest = largestNormalForce(simulation.scene());
  EXPECT_NE(checkCommand(msg, driver).find("at most " + std::to_string(static_cast<int>(largest)) + " N"),
            std::string::npos)
      << checkCommand(msg, driver);
  msg.mode = 9;
  EXPECT_NE(checkCommand(msg, driver).find("mode 9 is unknown"), std::string::npos);
}

TEST(CommandChecks, AHoldIgnoresTheSpeedAndTargetItCarries) {
  Scene scene;
  scene.model = ModelKind::Chain1D;
  scene.chain.blocks = 3;
  RunDriver driver(scene, sceneStabilityLimit(scene));
  Simulation& simulation = driver.simulation();
  friction_msgs::StageCommand msg;
  msg.mode = friction_msgs::StageCommand::HOLD;
  msg.speed = 5.0;  // beyond max_speed, and meaningless for a hold
  msg.target = std::nan("");
  ASSERT_EQ(checkCommand(msg, driver), "");
  const TimedCommand hold = fromMsg(msg);
  EXPECT_EQ(hold.stage.mode, StageMode::Hold);
  // Accepted means applied: the stage, driven at the scene's speed before, stands still after.
  ASSERT_GT(std::abs(simulation.stage().velocity()), 0.0);
  EXPECT_EQ(simulation.stage().command(hold.stage), "");
  EXPECT_EQ(simulation.stage().velocity(), 0.0);
}

TEST(CommandChecks, NormalLoadChangesAreRefusedWithTheSpringMattress) {
  Scene scene;
  scene.lattice.nodes_x = 29;  // square cells of 5 mm in the default 140 × 75 mm slider
  scene.lattice.nodes_z = 16;
  scene.load.top = TopLoadKind::SpringMattress;
  RunDriver driver(scene, sceneStabilityLimit(scene));
  Simulation& simulation = driver.simulation();
  friction_msgs::StageCommand msg;
  msg.mode = friction_msgs::StageCommand::NORMAL_LOAD;
  msg.normal_force = 2500.0;
  EXPECT_NE(checkCommand(msg, driver).find("spring_mattress"), std::string::npos) << checkCommand(msg, driver);
  // Refused where it would be applied too, with the load unchanged.
  const double load = simulation.loadCells().normal_force;
  EXPECT_NE(simulation.setNormalLoad(2500.0), "");
  EXPECT_EQ(simulation.loadCells().normal_force, load);
}

TEST(SimulatorOptions, EveryBadParameterIsNamedWithValueAndRange) {
  SimulatorOptions options;
  options.scene_path = "scene.yaml";
  EXPECT_TRUE(validateOptions(options).empty());
  options.scene_path.clear();
  options.real_time_factor = -1.0;
  options.load_cell_rate = 0.0;
  options.overrides = "pusher.height=0.01 broken";
  options.bag_compression = "zip";
  options.threads = 0;
  const auto problems = validateOptions(options);
  ASSERT_EQ(problems.size(), 6u);
  EXPECT_NE(problems[0].find("~scene"), std::string::npos);
  EXPECT_NE(problems[1].find("~real_time_factor: value -1"), std::string::npos);
  EXPECT_NE(problems[2].find("~load_cell_rate: value 0"), std::string::npos);
  EXPECT_NE(problems[3].find("~bag_compression: value 'zip' is not allowed; allowed: lz4, bz2, none"),
            std::string::npos);
  EXPECT_NE(problems[4].find("~overrides: item 'broken'"), std::string::npos);
  EXPECT_NE(problems[5].find("~threads: value 0 is not allowed; allowed: a whole number from 1"), std::string::npos)
      << problems[5];
  std::vector<std::string> ignored;
  const auto overrides = parseOverrides("pusher.height=0.01  stop.global_events=3", ignored);
  ASSERT_EQ(overrides.size(), 2u);
  EXPECT_EQ(overrides[1].first, "stop.global_events");
  EXPECT_EQ(overrides[1].second, "3");
}

TEST(SimulatorOptions, LiveSettingsStartFromTheParametersDefaults) {
  // The node reads its parameters (written back with their defaults) before dynamic_reconfigure does;
  // the generator's defaults are the parameters' all the same, for a reader of cfg/Simulator.cfg.
  const SimulatorConfig config = SimulatorConfig::__getDefault__();
  const SimulatorOptions options;
  for (const LiveSetting& setting : kLiveSettings) EXPECT_EQ(config.*setting.in_config, options.*setting.in_options);
  // Each live setting refuses a negative value, as its parameter does: a change refused live names it.
  for (const LiveSetting& setting : kLiveSettings) {
    SimulatorOptions bad = options;
    bad.scene_path = "scene.yaml";
    bad.*setting.in_options = -1.0;
    EXPECT_EQ(validateOptions(bad).size(), 1u);
  }
}

TEST(ControllerOptions, EveryBadParameterIsNamedWithValueAndRange) {
  ControllerOptions options;
  options.protocol_path = "protocol.yaml";
  EXPECT_TRUE(validateControllerOptions(options).empty());
  options.protocol_path.clear();
  options.start_delay = -0.5;
  auto problems = validateControllerOptions(options);
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_NE(problems[0].find("~protocol: no value"), std::string::npos);
  EXPECT_NE(problems[1].find("~start_delay: value -0.5 is not allowed; allowed: >= 0 s"), std::string::npos);
  options.start_delay = std::nan("");
  problems = validateControllerOptions(options);
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_NE(problems[1].find("~start_delay: value nan"), std::string::npos);
}

TEST(DetectorOptions, EveryBadParameterIsNamedWithValueAndRange) {
  DetectorOptions options;
  EXPECT_TRUE(validateDetectorOptions(options).empty());
  options.front_fit_nodes = 1;
  options.overrides = "material.density=1200 broken";
  const auto problems = validateDetectorOptions(options);
  ASSERT_EQ(problems.size(), 3u);
  EXPECT_NE(problems[0].find("~front_fit_nodes: value 1 is not allowed; allowed: >= 2, or 0 for the scene's"),
            std::string::npos);
  EXPECT_NE(problems[1].find("~overrides: 'material.density=1200 broken' given without ~scene"), std::string::npos);
  EXPECT_NE(problems[2].find("~overrides: item 'broken'"), std::string::npos);
}

TEST(DetectorOptions, TheRunsSceneGivesTheModelsWaveSpeedsFitWindowAndLength) {
  DetectorOptions options;
  const DetectorSettings without_scene = resolveDetectorSettings(options);
  const WaveSpeeds unknown = without_scene.wave_speeds;
  EXPECT_EQ(unknown.longitudinal, 0.0);
  EXPECT_EQ(unknown.shear, 0.0);
  EXPECT_EQ(unknown.rayleigh, 0.0);
  EXPECT_EQ(without_scene.front_fit_nodes, 5);
  EXPECT_EQ(without_scene.slider_length, 0.0);
  // MODEL.md §2 with the default numbers: c_S = √(3E/(8ρ)) ≈ 968 m/s, c_L ≈ 1677 m/s, c_R ≈ 0.919·c_S.
  options.scene_path = SCENE_DIR "/pmma_2d.yaml";
  const WaveSpeeds lattice = resolveDetectorSettings(options).wave_speeds;
  EXPECT_NEAR(lattice.shear, 968.2, 0.1);
  EXPECT_NEAR(lattice.longitudinal, 1677.05, 0.01);
  EXPECT_NEAR(lattice.rayleigh, 0.919 * lattice.shear, 1e-9);
  EXPECT_EQ(resolveDetectorSettings(options).slider_length, 0.14);
  // The run's overrides apply: a quarter of the density doubles every speed.
  options.overrides = "material.density=300 instruments.front_fit_nodes=7";
  const DetectorSettings overridden = resolveDetectorSettings(options);
  EXPECT_NEAR(overridden.wave_speeds.shear, 2 * lattice.shear, 1e-9);
  EXPECT_EQ(overridden.front_fit_nodes, 7);  // fitted as the simulator fits that run
  options.front_fit_nodes = 3;
  EXPECT_EQ(resolveDetectorSettings(options).front_fit_nodes, 3);
  options.front_fit_nodes = 0;
  // The chain has the bar speed √(E/ρ) and no surface wave.
  options.scene_path = SCENE_DIR "/pmma_1d_side.yaml";
  options.overrides.clear();
  const WaveSpeeds chain = resolveDetectorSettings(options).wave_speeds;
  EXPECT_NEAR(chain.shear, std::sqrt(3.0e9 / 1200.0), 1e-9);
  EXPECT_EQ(chain.rayleigh, 0.0);
  // A single block's interface has no span: L comes from the scene, so that L_p/L is finite.
  options.scene_path = SCENE_DIR "/single_block.yaml";
  EXPECT_EQ(resolveDetectorSettings(options).slider_length, 0.14);
  options.scene_path = SCENE_DIR "/pmma_1d_side.yaml";
  // A scene the simulator would refuse is refused here too.
  options.overrides = "material.density=-1";
  EXPECT_THROW(resolveDetectorSettings(options), ConfigError);
}

}  // namespace
}  // namespace friction
