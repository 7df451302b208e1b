// The precursor detector node; see friction_sim/ros/precursor_detector.h.
#include "friction_sim/ros/precursor_detector.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "precursor_detector");
  friction::PrecursorDetector detector{ros::NodeHandle(), ros::NodeHandle("~")};
  ros::spin();
  return 0;
}
