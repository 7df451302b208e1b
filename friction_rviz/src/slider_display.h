// rviz display of the slider from friction_msgs/LatticeSnapshot: nodes and springs at their deformed
// positions (displacements magnified), coloured by a chosen field with a colour bar, the interface row
// drawn stuck (blue) or sliding (red), the pusher and the top load drawn where they act.
#pragma once

#ifndef Q_MOC_RUN
#include <friction_msgs/LatticeSnapshot.h>
#include <rviz/message_filter_display.h>
#endif

#include <memory>
#include <vector>

namespace Ogre {
class ManualObject;
class SceneNode;
}  // namespace Ogre

namespace rviz {
class BoolProperty;
class EnumProperty;
class FloatProperty;
class MovableText;
}  // namespace rviz

namespace friction_rviz {

class SliderDisplay : public rviz::MessageFilterDisplay<friction_msgs::LatticeSnapshot> {
  Q_OBJECT
 public:
  SliderDisplay();
  ~SliderDisplay() override;

 protected:
  void onInitialize() override;
  void reset() override;
  void update(float wall_dt, float ros_dt) override;

 private Q_SLOTS:
  void markDirty();

 private:
  void processMessage(const friction_msgs::LatticeSnapshot::ConstPtr& msg) override;
  void redraw();

  rviz::FloatProperty* magnification_;
  rviz::EnumProperty* field_;
  rviz::BoolProperty* auto_range_;
  rviz::FloatProperty* range_min_;
  rviz::FloatProperty* range_max_;
  rviz::BoolProperty* draw_springs_;
  Ogre::ManualObject* lattice_ = nullptr;
  Ogre::ManualObject* overlay_ = nullptr;
  Ogre::SceneNode* label_node_ = nullptr;
  std::unique_ptr<rviz::MovableText> min_label_, max_label_, title_label_;
  friction_msgs::LatticeSnapshot::ConstPtr latest_;
  ros::Time last_stamp_;
  bool dirty_ = false;
};

}  // namespace friction_rviz
