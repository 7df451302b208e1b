// rviz display of the interface camera from friction_msgs/InterfaceState: a space–time strip of slip
// velocity (or slip) along x, newest frame at the bottom, scrolling as frames arrive, with each slip
// event outlined and its slipped length L_p marked. Drawn above the slider in the slider's frame.
#pragma once

#ifndef Q_MOC_RUN
#include <friction_msgs/InterfaceState.h>
#include <rviz/message_filter_display.h>

#include "friction_rviz/color_map.h"
#include "friction_rviz/history.h"
#endif

namespace Ogre {
class ManualObject;
}

namespace rviz {
class EnumProperty;
class FloatProperty;
class IntProperty;
}  // namespace rviz

namespace friction_rviz {

class InterfaceDisplay : public rviz::MessageFilterDisplay<friction_msgs::InterfaceState> {
  Q_OBJECT
 public:
  InterfaceDisplay();
  ~InterfaceDisplay() override;

 protected:
  void onInitialize() override;
  void reset() override;
  void update(float wall_dt, float ros_dt) override;

 private Q_SLOTS:
  /// The strip emptied, with as many rows as "History" says.
  void startHistoryOver();
  void markDirty();

 private:
  void processMessage(const friction_msgs::InterfaceState::ConstPtr& msg) override;
  void redraw();
  /// The values drawn black and full yellow: from zero, or over the strip's own spread (static friction).
  Range colourRange() const;

  rviz::IntProperty* rows_;
  rviz::EnumProperty* field_;
  rviz::FloatProperty* height_;
  rviz::FloatProperty* offset_;
  rviz::FloatProperty* scale_;
  static constexpr int kDefaultRows = 300;  ///< frames the strip keeps unless "History" says otherwise
  SpaceTimeHistory history_;
  Ogre::ManualObject* strip_ = nullptr;
  bool dirty_ = false;
};

}  // namespace friction_rviz
