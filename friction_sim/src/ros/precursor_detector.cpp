#include "friction_sim/ros/precursor_detector.h"

#include "friction_sim/ros/conversions.h"

namespace friction {

PrecursorDetector::PrecursorDetector(ros::NodeHandle nh, ros::NodeHandle private_nh)
    : nh_(std::move(nh)), private_nh_(std::move(private_nh)) {
  int front_fit_nodes = 5;
  private_nh_.param("front_fit_nodes", front_fit_nodes, front_fit_nodes);
  if (front_fit_nodes < 2) {
    ROS_WARN_STREAM("~front_fit_nodes: value " << front_fit_nodes << " is not allowed; allowed: >= 2; using 5");
    front_fit_nodes = 5;
  }
  detector_ = std::make_unique<FrameEventDetector>(front_fit_nodes);
  events_pub_ = private_nh_.advertise<friction_msgs::SlipEvent>("slip_events", 1000, true);
  points_pub_ = private_nh_.advertise<friction_msgs::PrecursorPoint>("precursor_points", 1000, true);
  // Deep queues: a bag played fast must not drop frames, or events would be merged.
  const auto hints = ros::TransportHints().tcpNoDelay();
  load_cells_sub_ = nh_.subscribe("load_cells", 100000, &PrecursorDetector::onLoadCells, this, hints);
  interface_sub_ = nh_.subscribe("interface", 100000, &PrecursorDetector::onFrame, this, hints);
}

void PrecursorDetector::checkTime(const ros::Time& stamp) {
  // Seconds, not ros::Time: near t = 0 the margin would underflow ros::Time's unsigned range.
  if (stamp.toSec() < last_stamp_.toSec() - 1e-3) {
    ROS_WARN_STREAM("precursor detector: time jumped back to " << stamp.toSec() << " s; starting over");
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
  positions_ = msg->position;
  detector_->addFrame(fromMsg(*msg));
  publishCompleted();
}

void PrecursorDetector::publishCompleted() {
  for (const SlipEvent& event : detector_->takeCompletedEvents()) {
    const double length = detector_->sliderLength();
    events_pub_.publish(toMsg(event, positions_, length, WaveSpeeds{}, "slider"));
    points_pub_.publish(toPointMsg(event, length, "slider"));
    ROS_INFO_STREAM("precursor detector: event " << event.index << " F_X/F_Z = "
                                                 << event.onset_shear_force / event.onset_normal_force
                                                 << ", L_p/L = " << event.rupture_length / length
                                                 << (event.global ? " (global)" : ""));
  }
}

}  // namespace friction
