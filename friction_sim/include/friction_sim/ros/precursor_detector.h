// The precursor detector: an analysis node that sees the rig only through its instrument topics, live
// or from `rosbag play --clock`, and publishes the slip events and L_p–F_X points it finds. It is the
// template for your own analysis node: copy this class, keep the subscriptions you need, and put the
// analysis itself in a ROS-free class (here FrameEventDetector) that you can unit-test.
//
// Parameters (private, ~):
//   front_fit_nodes (int, 0)   nodes in the sliding fit of the front speed, >= 2; 0 = the scene's
//                              instruments.front_fit_nodes (as the simulator fits), 5 without a scene
//   scene (string, "")         the run's scene YAML: its model's wave speeds go into the events, so that
//                              v_c/c_R and v_c/c_S can be read off them (the instruments do not tell
//                              them, as a lab takes c_R of its PMMA from the literature). Its
//                              geometry.length is the L of L_p/L, as the simulator's. "" = the scene the
//                              `scene` topic brings (the simulator's, live or from its bag); until one
//                              comes, the speeds are unknown (0) and L is the span of the interface nodes
//                              (none for a single block: L_p/L is NaN)
//                              Validated as the simulator does (a 10^6-node lattice's takes ~15 s)
//   overrides (string, "")     the run's scene overrides, "key=value key=value", as the simulator's
// Subscribed topics (relative to the node's namespace):
//   load_cells (geometry_msgs/WrenchStamped), interface (friction_msgs/InterfaceState)
//   scene (std_msgs/String)    without ~scene only: the run's scene; one the detector measures differently
//                              with (wave speeds, fit window, L) starts the analysis over, the same scene
//                              again (a new run end, a looped bag's next pass) does not
// Published topics (private), in the interface frames' frame_id:
//   ~slip_events (friction_msgs/SlipEvent), ~precursor_points (friction_msgs/PrecursorPoint)
//
// Bad parameters or a refused scene end the node at start (exit status 2), every problem listed.
//
// When time jumps backwards (looped playback), it forgets everything and starts over. A frame whose arrays
// differ in length, or whose node count changes during an event, is left out with a warning.
#pragma once

#include <friction_msgs/InterfaceState.h>
#include <geometry_msgs/WrenchStamped.h>
#include <ros/ros.h>
#include <std_msgs/String.h>

#include <memory>
#include <string>
#include <vector>

#include "friction_sim/instruments/frame_event_detector.h"
#include "friction_sim/instruments/slip_events.h"

namespace friction {

struct DetectorOptions {
  /// nodes in the sliding linear fit of the front speed v_c(x); 0 = the scene's, 5 without one
  int front_fit_nodes = 0;
  std::string scene_path;  ///< the run's scene YAML, for the model's wave speeds; "" = unknown
  std::string overrides;   ///< "key=value ..." scene fields the run replaced
};

/// Every problem of the options, each naming the parameter, the value and the allowed range.
std::vector<std::string> validateDetectorOptions(const DetectorOptions& options);
/// Reads the options from the private parameters; throws ConfigError listing every problem.
DetectorOptions readDetectorOptions(const ros::NodeHandle& private_nh);
/// What the detector takes from the run's scene.
struct DetectorSettings {
  WaveSpeeds wave_speeds;                                  ///< m/s, the model's (all 0, unknown, without a scene)
  int front_fit_nodes = InstrumentSpec{}.front_fit_nodes;  ///< the options' or the scene's (its default without one)
  double slider_length = 0.0;  ///< m, L of L_p/L: the scene's geometry.length; 0 without a scene
  SlipCriterion slip;          ///< the scene's (slipCriterion); any sliding node, without a scene
  /// Whether the detector measures the same with `other`.
  bool sameAs(const DetectorSettings& other) const {
    return wave_speeds.longitudinal == other.wave_speeds.longitudinal && wave_speeds.shear == other.wave_speeds.shear &&
           wave_speeds.rayleigh == other.wave_speeds.rayleigh && front_fit_nodes == other.front_fit_nodes &&
           slider_length == other.slider_length && slip.speed == other.slip.speed &&
           slip.quiet_time == other.slip.quiet_time;
  }
};
/// The settings from a run's `scene` (nullptr: none), with the ~front_fit_nodes option (0: the scene's).
DetectorSettings detectorSettings(const Scene* scene, int front_fit_nodes);
/// Loads the options' scene, if any; throws ConfigError if it is refused.
DetectorSettings resolveDetectorSettings(const DetectorOptions& options);

class PrecursorDetector {
 public:
  PrecursorDetector(ros::NodeHandle nh, ros::NodeHandle private_nh, const DetectorOptions& options);

 private:
  void onLoadCells(const geometry_msgs::WrenchStamped::ConstPtr& msg);
  void onFrame(const friction_msgs::InterfaceState::ConstPtr& msg);
  void checkTime(const ros::Time& stamp);
  void use(const DetectorSettings& settings);
  void onScene(const std_msgs::String::ConstPtr& msg);
  /// `no_more_readings`: as FrameEventDetector::takeCompletedEvents.
  void publishCompleted(bool no_more_readings = false);

  ros::NodeHandle nh_, private_nh_;
  std::unique_ptr<FrameEventDetector> detector_;
  int front_fit_nodes_option_;  ///< ~front_fit_nodes, 0 = the scene's
  DetectorSettings settings_;   ///< in use
  std::vector<double> positions_;
  std::string frame_id_;  ///< the interface frames', for the events
  long frames_seen_ = 0;  ///< interface frames since the analysis last started over
  ros::Time last_stamp_;
  ros::Subscriber load_cells_sub_, interface_sub_, scene_sub_;
  ros::Publisher events_pub_, points_pub_;
};

}  // namespace friction
