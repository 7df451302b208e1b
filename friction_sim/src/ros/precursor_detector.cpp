#include "friction_sim/ros/precursor_detector.h"

#include "friction_sim/ros/conversions.h"
#include "friction_sim/ros/node_parameters.h"
#include "friction_sim/scene/config_error.h"
#include "friction_sim/scene/scene_io.h"

namespace friction {

std::vector<std::string> validateDetectorOptions(const DetectorOptions& options) {
  std::vector<std::string> problems;
  requireSetting(options.front_fit_nodes >= InstrumentSpec::kFewestFrontFitNodes || options.front_fit_nodes == 0,
                 "~front_fit_nodes", options.front_fit_nodes,
                 ">= " + std::to_string(InstrumentSpec::kFewestFrontFitNodes) + ", or 0 for the scene's", problems);
  if (options.scene_path.empty() && !options.overrides.empty()) {
    problems.push_back("~overrides: '" + options.overrides + "' given without ~scene; allowed: overrides of a scene");
  }
  parseOverrides(options.overrides, problems);
  return problems;
}

DetectorOptions readDetectorOptions(const ros::NodeHandle& private_nh) {
  DetectorOptions options;
  ParameterReader reader(private_nh);
  reader.read("front_fit_nodes", options.front_fit_nodes);
  reader.read("scene", options.scene_path);
  reader.read("overrides", options.overrides);
  reader.refuseIfAny(validateDetectorOptions(options));
  return options;
}

DetectorSettings detectorSettings(const Scene* scene, int front_fit_nodes) {
  DetectorSettings settings;
  if (scene) {
    settings.wave_speeds = waveSpeeds(*scene);
    settings.front_fit_nodes = scene->instruments.front_fit_nodes;
    settings.slider_length = scene->geometry.length;
    settings.slip = slipCriterion(*scene);
  }
  if (front_fit_nodes != 0) settings.front_fit_nodes = front_fit_nodes;
  return settings;
}

DetectorSettings resolveDetectorSettings(const DetectorOptions& options) {
  if (options.scene_path.empty()) return detectorSettings(nullptr, options.front_fit_nodes);
  std::vector<std::string> problems;
  const auto overrides = parseOverrides(options.overrides, problems);
  refuseParameters(problems);
  const Scene scene = loadScene(options.scene_path, overrides);
  return detectorSettings(&scene, options.front_fit_nodes);
}

PrecursorDetector::PrecursorDetector(ros::NodeHandle nh, ros::NodeHandle private_nh, const DetectorOptions& options)
    : nh_(std::move(nh)), private_nh_(std::move(private_nh)), front_fit_nodes_option_(options.front_fit_nodes) {
  use(resolveDetectorSettings(options));
  // Without ~scene, the run's own: the simulator publishes it (latched), and a bag holds it first.
  if (options.scene_path.empty()) scene_sub_ = nh_.subscribe("scene", 1, &PrecursorDetector::onScene, this);
  events_pub_ = private_nh_.advertise<friction_msgs::SlipEvent>("slip_events", 1000, true);
  points_pub_ = private_nh_.advertise<friction_msgs::PrecursorPoint>("precursor_points", 1000, true);
  // Deep queues: a bag played fast must not drop frames, or events would be merged.
  const auto hints = ros::TransportHints().tcpNoDelay();
  load_cells_sub_ = nh_.subscribe("load_cells", 100000, &PrecursorDetector::onLoadCells, this, hints);
  interface_sub_ = nh_.subscribe("interface", 100000, &PrecursorDetector::onFrame, this, hints);
}

void PrecursorDetector::use(const DetectorSettings& settings) {
  settings_ = settings;
  detector_ = std::make_unique<FrameEventDetector>(settings.front_fit_nodes, settings.wave_speeds.longitudinal,
                                                   settings.slider_length, settings.slip);
}

void PrecursorDetector::onScene(const std_msgs::String::ConstPtr& msg) {
  DetectorSettings settings = detectorSettings(nullptr, front_fit_nodes_option_);
  std::string name;  // empty while no scene is accepted
  try {
    const Scene scene = parseScene(msg->data);
    settings = detectorSettings(&scene, front_fit_nodes_option_);
    name = scene.name;
  } catch (const ConfigError& error) {
    ROS_WARN_STREAM("precursor detector: the run's scene is refused, so the wave speeds are unknown: " << error.what());
  }
  // A scene the detector measures the same with goes on with the analysis: the rig publishes its scene
  // again with a new run end, and a looped bag starts its next pass with its first scene, ahead of the
  // last frames of this pass (the time jumping back starts the analysis over once they are in; a new
  // detector here would lose the last event on every pass).
  if (settings.sameAs(settings_)) return;
  // A new detector otherwise: what the old one saw was measured against another scene, or none. The
  // scene is its bag's first message, but it travels apart from the frames, which may come first.
  if (frames_seen_ > 0) {
    ROS_WARN_STREAM("precursor detector: the run's scene came after "
                    << frames_seen_ << " interface frames; starting over without them");
  }
  frames_seen_ = 0;
  use(settings);
  if (!name.empty()) {
    ROS_INFO_STREAM("precursor detector: using the run's scene " << name << " (c_S = " << settings.wave_speeds.shear
                                                                 << " m/s, L = " << settings.slider_length << " m)");
  }
}

void PrecursorDetector::checkTime(const ros::Time& stamp) {
  // Seconds, not ros::Time: near t = 0 the margin would underflow ros::Time's unsigned range.
  if (stamp.toSec() < last_stamp_.toSec() - 1e-3) {
    ROS_WARN_STREAM("precursor detector: time jumped back to " << stamp.toSec() << " s; starting over");
    // An event that ended on the last frames (a run's last) may still wait for a load-cell reading that,
    // on its own topic, comes after the next pass has begun: published from the readings there are.
    publishCompleted(true);
    detector_->reset();
  }
  last_stamp_ = stamp;
}

void PrecursorDetector::onLoadCells(const geometry_msgs::WrenchStamped::ConstPtr& msg) {
  detector_->addLoadCells(fromMsg(*msg));
  publishCompleted();
}

void PrecursorDetector::onFrame(const friction_msgs::InterfaceState::ConstPtr& msg) {
  checkTime(msg->header.stamp);
  const std::string left_out = detector_->addFrame(fromMsg(*msg));
  if (!left_out.empty()) {
    ROS_WARN_STREAM_THROTTLE(5.0, "precursor detector: " << left_out);
    return;
  }
  positions_ = msg->position;
  frame_id_ = msg->header.frame_id;
  ++frames_seen_;
  publishCompleted();
}

void PrecursorDetector::publishCompleted(bool no_more_readings) {
  for (const SlipEvent& event : detector_->takeCompletedEvents(no_more_readings)) {
    const double length = detector_->sliderLength();
    events_pub_.publish(toMsg(event, positions_, length, settings_.wave_speeds, frame_id_));
    const friction_msgs::PrecursorPoint point = toPointMsg(event, length, frame_id_);
    points_pub_.publish(point);
    ROS_INFO_STREAM("precursor detector: event " << event.index << " F_X/F_Z = " << point.shear_ratio << ", L_p/L = "
                                                 << point.length_ratio << (event.global ? " (global)" : ""));
  }
}

}  // namespace friction
