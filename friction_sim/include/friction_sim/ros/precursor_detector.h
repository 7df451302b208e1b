// The precursor detector: an analysis node that sees the rig only through its instrument topics, live
// or from `rosbag play --clock`, and publishes the slip events and L_p–F_X points it finds. It is the
// template for your own analysis node: copy this class, keep the subscriptions you need, and put the
// analysis itself in a ROS-free class (here FrameEventDetector) that you can unit-test.
//
// Parameters (private, ~):
//   front_fit_nodes (int, 5)   nodes in the sliding fit of the front speed
// Subscribed topics (relative to the node's namespace):
//   load_cells (geometry_msgs/WrenchStamped), interface (friction_msgs/InterfaceState)
// Published topics (private):
//   ~slip_events (friction_msgs/SlipEvent), ~precursor_points (friction_msgs/PrecursorPoint)
//   The events' wave speeds are 0 (unknown): the instruments do not tell them.
//
// When time jumps backwards (looped playback), it forgets everything and starts over.
#pragma once

#include <friction_msgs/InterfaceState.h>
#include <geometry_msgs/WrenchStamped.h>
#include <ros/ros.h>

#include <memory>

#include "friction_sim/frame_event_detector.h"

namespace friction {

class PrecursorDetector {
 public:
  PrecursorDetector(ros::NodeHandle nh, ros::NodeHandle private_nh);

 private:
  void onLoadCells(const geometry_msgs::WrenchStamped::ConstPtr& msg);
  void onFrame(const friction_msgs::InterfaceState::ConstPtr& msg);
  void checkTime(const ros::Time& stamp);
  void publishCompleted();

  ros::NodeHandle nh_, private_nh_;
  std::unique_ptr<FrameEventDetector> detector_;
  std::vector<double> positions_;
  ros::Time last_stamp_;
  ros::Subscriber load_cells_sub_, interface_sub_;
  ros::Publisher events_pub_, points_pub_;
};

}  // namespace friction
