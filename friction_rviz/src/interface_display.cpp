#include "interface_display.h"

#include <OGRE/OgreManualObject.h>
#include <OGRE/OgreSceneManager.h>
#include <OGRE/OgreSceneNode.h>
#include <rviz/properties/enum_property.h>
#include <rviz/properties/float_property.h>
#include <rviz/properties/int_property.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "frame_placement.h"
#include "friction_rviz/color_map.h"
#include "vertex_colour_material.h"

namespace friction_rviz {

static_assert(kStuck == friction_msgs::InterfaceState::STUCK && kSliding == friction_msgs::InterfaceState::SLIDING &&
                  kDetached == friction_msgs::InterfaceState::DETACHED,
              "color_map.h numbers the contact states as InterfaceState does");

InterfaceDisplay::InterfaceDisplay() : history_(kDefaultRows) {
  rows_ = new rviz::IntProperty("History", kDefaultRows, "Frames kept in the strip (older ones scroll out).", this,
                                SLOT(startHistoryOver()));
  rows_->setMin(2);
  rows_->setMax(5000);
  // Another field starts the strip over: its rows would mix m/s with m or µ_s under one colour range.
  field_ = new rviz::EnumProperty("Field", "slip velocity", "What the strip shows.", this, SLOT(startHistoryOver()));
  field_->addOption("slip velocity", 0);
  field_->addOption("slip", 1);
  field_->addOption("static friction", 2);
  height_ = new rviz::FloatProperty("Strip height", 0.06, "Height of the strip in the slider frame (m).", this,
                                    SLOT(markDirty()));
  offset_ =
      new rviz::FloatProperty("Strip base", 0.09, "z of the strip's bottom (newest) row (m).", this, SLOT(markDirty()));
  scale_ = new rviz::FloatProperty("Full scale", 0.0,
                                   "Value drawn at full colour (m/s or m); 0 takes the largest in the strip. Static "
                                   "friction spans the strip's own range.",
                                   this, SLOT(markDirty()));
}

InterfaceDisplay::~InterfaceDisplay() {
  if (strip_) scene_manager_->destroyManualObject(strip_);
}

void InterfaceDisplay::onInitialize() {
  MFDClass::onInitialize();
  strip_ = scene_manager_->createManualObject();
  strip_->setDynamic(true);
  scene_node_->attachObject(strip_);
}

void InterfaceDisplay::reset() {
  MFDClass::reset();
  history_.clear();
  if (strip_) strip_->clear();
}

void InterfaceDisplay::startHistoryOver() {
  history_ = SpaceTimeHistory(static_cast<std::size_t>(rows_->getInt()));
  dirty_ = true;
}

void InterfaceDisplay::markDirty() { dirty_ = true; }

void InterfaceDisplay::processMessage(const friction_msgs::InterfaceState::ConstPtr& msg) {
  if (!placeAtMessageFrame(*this, *context_, msg->header, *scene_node_)) return;
  const int field = field_->getOptionInt();
  const auto& values = field == 0 ? msg->slip_velocity : field == 1 ? msg->slip : msg->static_coefficient;
  if (history_.add(msg->header.stamp.toSec(), msg->position, values, msg->state)) {
    setStatus(rviz::StatusProperty::Warn, "Time", "time jumped back: history cleared");
  }
  dirty_ = true;
}

void InterfaceDisplay::update(float, float) {
  if (!dirty_) return;
  dirty_ = false;
  redraw();
}

Range InterfaceDisplay::colourRange() const {
  // Static friction differs from node to node by a few per cent around 0.3–0.6: black to yellow over the
  // strip's own spread shows its pattern. The other fields run from zero.
  const bool spread = field_->getOptionInt() == 2;
  double low = spread ? std::numeric_limits<double>::infinity() : 0.0, high = scale_->getFloat();
  if (spread || high <= 0.0) {
    high = 0.0;
    for (std::size_t r = 0; r < history_.size(); ++r) {
      for (double value : history_.row(r)) {
        high = std::max(high, std::abs(value));
        low = std::min(low, std::abs(value));
      }
    }
  }
  if (!(high > low)) return {0.0, high > 0.0 ? high : 1.0};
  return {low, high};
}

void InterfaceDisplay::redraw() {
  strip_->clear();
  const std::size_t rows = history_.size();
  const auto& x = history_.positions();
  if (rows < 1 || x.size() < 2) return;
  const Range range = colourRange();
  const float height = height_->getFloat(), base = offset_->getFloat();
  const float row_height = height / static_cast<float>(rows_->getInt());
  const double half = 0.5 * (x[1] - x[0]);
  // Newest row at the base, older rows above it.
  auto row_z = [&](std::size_t r) { return base + row_height * static_cast<float>(rows - 1 - r); };
  strip_->begin(vertexColourMaterial(), Ogre::RenderOperation::OT_TRIANGLE_LIST,
                Ogre::ResourceGroupManager::DEFAULT_RESOURCE_GROUP_NAME);
  for (std::size_t r = 0; r < rows; ++r) {
    const auto& row = history_.row(r);
    const float z0 = row_z(r), z1 = z0 + row_height;
    for (std::size_t i = 0; i < row.size() && i < x.size(); ++i) {
      // Black at rest, through red to yellow at full scale: the camera's |dA/dt| picture.
      const double s = std::clamp((std::abs(row[i]) - range.min) / (range.max - range.min), 0.0, 1.0);
      const Ogre::ColourValue c(static_cast<float>(std::min(1.0, 2.0 * s)),
                                static_cast<float>(std::max(0.0, 2.0 * s - 1.0)), 0.05f);
      const float xa = static_cast<float>(x[i] - half), xb = static_cast<float>(x[i] + half);
      for (const auto& p : {Ogre::Vector3(xa, 0, z0), Ogre::Vector3(xb, 0, z0), Ogre::Vector3(xb, 0, z1),
                            Ogre::Vector3(xa, 0, z0), Ogre::Vector3(xb, 0, z1), Ogre::Vector3(xa, 0, z1)}) {
        strip_->position(p);
        strip_->colour(c);
      }
    }
  }
  strip_->end();
  // Event outlines: a box over the event's rows and slipped range; its top edge marks L_p.
  const std::vector<StripEvent> events = history_.visibleEvents();
  if (events.empty()) return;
  strip_->begin(vertexColourMaterial(), Ogre::RenderOperation::OT_LINE_LIST,
                Ogre::ResourceGroupManager::DEFAULT_RESOURCE_GROUP_NAME);
  const Ogre::ColourValue outline(0.2f, 0.9f, 1.0f);
  for (const StripEvent& event : events) {
    const float xa = static_cast<float>(event.x_min - half), xb = static_cast<float>(event.x_max + half);
    const float za = row_z(event.last_row), zb = row_z(event.first_row) + row_height;
    const Ogre::Vector3 corners[4] = {{xa, 0, za}, {xb, 0, za}, {xb, 0, zb}, {xa, 0, zb}};
    for (int k = 0; k < 4; ++k) {
      strip_->position(corners[k]);
      strip_->colour(outline);
      strip_->position(corners[(k + 1) % 4]);
      strip_->colour(outline);
    }
  }
  strip_->end();
}

}  // namespace friction_rviz

#include <pluginlib/class_list_macros.hpp>
PLUGINLIB_EXPORT_CLASS(friction_rviz::InterfaceDisplay, rviz::Display)
