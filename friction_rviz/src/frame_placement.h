// Where both displays put their scene node: at the pose of the message's frame in rviz's fixed frame.
#pragma once

#include <OGRE/OgreSceneNode.h>
#include <ros/console.h>
#include <rviz/display.h>
#include <rviz/display_context.h>
#include <rviz/frame_manager.h>
#include <std_msgs/Header.h>

namespace friction_rviz {

/// Moves `node` to the pose of `header`'s frame and sets the display's "Transform" status. Without a
/// transform the status is an error naming the frame (logged at most every 5 s) and false is returned.
inline bool placeAtMessageFrame(rviz::Display& display, rviz::DisplayContext& context, const std_msgs::Header& header,
                                Ogre::SceneNode& node) {
  Ogre::Vector3 position;
  Ogre::Quaternion orientation;
  if (!context.getFrameManager()->getTransform(header, position, orientation)) {
    const std::string problem = "no transform from '" + header.frame_id + "' to the fixed frame";
    display.setStatusStd(rviz::StatusProperty::Error, "Transform", problem);
    ROS_ERROR_THROTTLE(5.0, "friction_rviz %s: %s", display.getName().toStdString().c_str(), problem.c_str());
    return false;
  }
  display.setStatus(rviz::StatusProperty::Ok, "Transform", "OK");
  node.setPosition(position);
  node.setOrientation(orientation);
  return true;
}

}  // namespace friction_rviz
