#include "slider_display.h"

#include <OGRE/OgreManualObject.h>
#include <OGRE/OgreSceneManager.h>
#include <OGRE/OgreSceneNode.h>
#include <rviz/ogre_helpers/movable_text.h>
#include <rviz/properties/bool_property.h>
#include <rviz/properties/enum_property.h>
#include <rviz/properties/float_property.h>

#include <cmath>
#include <iomanip>
#include <sstream>

#include "frame_placement.h"
#include "friction_rviz/color_map.h"
#include "vertex_colour_material.h"

namespace friction_rviz {

namespace {
std::string shortNumber(double value) {
  std::ostringstream text;
  text << std::setprecision(3) << value;
  return text.str();
}
}  // namespace

SliderDisplay::SliderDisplay() {
  // 100: at 300 the cells under the pusher of the default experiment fold over each other.
  magnification_ = new rviz::FloatProperty("Magnification", 100.0,
                                           "Displacements are drawn this many times larger (they are micrometres "
                                           "on a 14 cm slider).",
                                           this, SLOT(markDirty()));
  magnification_->setMin(0.0);
  field_ = new rviz::EnumProperty("Colour field", "sigma_zz", "Field the nodes and springs are coloured by.", this,
                                  SLOT(markDirty()));
  field_->addOption("sigma_zz", static_cast<int>(Field::SigmaZZ));
  field_->addOption("tau_xz", static_cast<int>(Field::TauXZ));
  field_->addOption("tau/sigma", static_cast<int>(Field::StressRatio));
  field_->addOption("von Mises", static_cast<int>(Field::VonMises));
  field_->addOption("speed", static_cast<int>(Field::Speed));
  auto_range_ =
      new rviz::BoolProperty("Auto range", true, "Take the colour range from each snapshot.", this, SLOT(markDirty()));
  range_min_ = new rviz::FloatProperty("Range min", -2e6, "Value drawn fully blue (when not automatic).", this,
                                       SLOT(markDirty()));
  range_max_ =
      new rviz::FloatProperty("Range max", 2e6, "Value drawn fully red (when not automatic).", this, SLOT(markDirty()));
  draw_springs_ =
      new rviz::BoolProperty("Springs", true, "Draw the springs, not only the interface.", this, SLOT(markDirty()));
}

SliderDisplay::~SliderDisplay() {
  if (lattice_) scene_manager_->destroyManualObject(lattice_);
  if (overlay_) scene_manager_->destroyManualObject(overlay_);
}

void SliderDisplay::onInitialize() {
  MFDClass::onInitialize();
  lattice_ = scene_manager_->createManualObject();
  lattice_->setDynamic(true);
  overlay_ = scene_manager_->createManualObject();
  overlay_->setDynamic(true);
  scene_node_->attachObject(lattice_);
  scene_node_->attachObject(overlay_);
  label_node_ = scene_node_->createChildSceneNode();
  min_label_ = std::make_unique<rviz::MovableText>("", "Liberation Sans", 0.008f, Ogre::ColourValue::Black);
  max_label_ = std::make_unique<rviz::MovableText>("", "Liberation Sans", 0.008f, Ogre::ColourValue::Black);
  title_label_ = std::make_unique<rviz::MovableText>("", "Liberation Sans", 0.008f, Ogre::ColourValue::Black);
  // One scene node per label: Ogre refuses two unnamed texts on one node.
  for (auto* label : {min_label_.get(), max_label_.get(), title_label_.get()}) {
    label->setTextAlignment(rviz::MovableText::H_LEFT, rviz::MovableText::V_CENTER);
    label_node_->createChildSceneNode()->attachObject(label);
  }
}

void SliderDisplay::reset() {
  MFDClass::reset();
  latest_.reset();
  last_stamp_ = ros::Time();
  if (lattice_) lattice_->clear();
  if (overlay_) overlay_->clear();
}

void SliderDisplay::markDirty() { dirty_ = true; }

void SliderDisplay::processMessage(const friction_msgs::LatticeSnapshot::ConstPtr& msg) {
  // Time running backwards (looped playback, a reset): start over.
  if (!last_stamp_.isZero() && msg->header.stamp < last_stamp_) reset();
  last_stamp_ = msg->header.stamp;
  if (!placeAtMessageFrame(*this, *context_, msg->header, *scene_node_)) return;
  // Only the newest snapshot is drawn, once per rendered frame.
  latest_ = msg;
  dirty_ = true;
}

void SliderDisplay::update(float, float) {
  if (!dirty_ || !latest_) return;
  dirty_ = false;
  redraw();
}

void SliderDisplay::redraw() {
  const auto& m = *latest_;
  const int nx = static_cast<int>(m.nodes_x), nz = static_cast<int>(m.nodes_z);
  const std::size_t n = m.x.size();
  // Per-node arrays may be left empty (drawn grey) but not of another length: they index one another.
  const auto fits = [n](const std::vector<float>& values) { return values.empty() || values.size() == n; };
  if (nx < 1 || nz < 1 || n != static_cast<std::size_t>(nx) * nz || m.z.size() != n || !fits(m.sigma_xx) ||
      !fits(m.sigma_zz) || !fits(m.tau_xz) || !fits(m.speed)) {
    setStatus(rviz::StatusProperty::Error, "Snapshot", "node arrays do not match nodes_x * nodes_z");
    ROS_ERROR_THROTTLE(5.0, "friction_rviz Slider: node arrays do not match nodes_x * nodes_z");
    return;
  }
  setStatus(rviz::StatusProperty::Ok, "Snapshot", QString("%1 x %2 nodes").arg(nx).arg(nz));
  const Field field = static_cast<Field>(field_->getOptionInt());
  const std::vector<double> values = fieldValues(field, m.sigma_xx, m.sigma_zz, m.tau_xz, m.speed);
  Range range = autoRange(values, signedField(field));
  const Range manual{range_min_->getFloat(), range_max_->getFloat()};
  const bool manual_refused = !auto_range_->getBool() && !(manual.max > manual.min);
  if (manual_refused) {
    setStatus(rviz::StatusProperty::Error, "Range",
              QString("Range max (%1) must exceed Range min (%2): the automatic range is drawn")
                  .arg(manual.max)
                  .arg(manual.min));
  } else {
    deleteStatus("Range");
    if (!auto_range_->getBool()) range = manual;
  }
  const double gain = magnification_->getFloat();
  const double l = m.spacing;
  // Drawn position: rest position plus the magnified deformation. The slider's mean x displacement
  // (its travel, which would carry the magnified drawing off the screen) is left out.
  double mean_shift = 0.0;
  for (std::size_t node = 0; node < n; ++node) mean_shift += (m.x[node] - (node % nx) * l) / n;
  auto point = [&](int node) {
    const int i = node % nx, j = node / nx;
    const double rest_x = i * l, rest_z = j * l;
    return Ogre::Vector3(rest_x + gain * (m.x[node] - rest_x - mean_shift), 0.0f, rest_z + gain * (m.z[node] - rest_z));
  };
  auto colour = [&](int node) {
    const Rgb c = node < static_cast<int>(values.size()) ? colorOf(values[node], range) : Rgb{0.8f, 0.8f, 0.8f};
    return Ogre::ColourValue(c.r, c.g, c.b);
  };
  lattice_->clear();
  lattice_->begin(vertexColourMaterial(), Ogre::RenderOperation::OT_LINE_LIST,
                  Ogre::ResourceGroupManager::DEFAULT_RESOURCE_GROUP_NAME);
  auto spring = [&](int a, int b) {
    lattice_->position(point(a));
    lattice_->colour(colour(a));
    lattice_->position(point(b));
    lattice_->colour(colour(b));
  };
  if (draw_springs_->getBool()) {
    for (int j = 0; j < nz; ++j) {
      for (int i = 0; i < nx; ++i) {
        const int node = j * nx + i;
        if (i + 1 < nx) spring(node, node + 1);
        if (j + 1 < nz) spring(node, node + nx);
        if (i + 1 < nx && j + 1 < nz) spring(node, node + nx + 1);
        if (i > 0 && j + 1 < nz) spring(node, node + nx - 1);
      }
    }
  }
  lattice_->end();

  // The interface band (stuck/sliding), the pusher arrow, the top load and the colour bar.
  overlay_->clear();
  overlay_->begin(vertexColourMaterial(), Ogre::RenderOperation::OT_TRIANGLE_LIST,
                  Ogre::ResourceGroupManager::DEFAULT_RESOURCE_GROUP_NAME);
  auto quad = [&](const Ogre::Vector3& a, const Ogre::Vector3& b, const Ogre::Vector3& c, const Ogre::Vector3& d,
                  const Ogre::ColourValue& colour) {
    for (const Ogre::Vector3& p : {a, b, c, a, c, d}) {
      overlay_->position(p);
      overlay_->colour(colour);
    }
  };
  const float band = static_cast<float>(0.4 * l);
  for (int i = 0; i < nx && i < static_cast<int>(m.interface_state.size()); ++i) {
    const Rgb c = contactColor(m.interface_state[i]);
    const Ogre::Vector3 p = point(i);
    const float half = static_cast<float>(0.5 * l);
    quad(p + Ogre::Vector3(-half, 0, -band), p + Ogre::Vector3(half, 0, -band),
         p + Ogre::Vector3(half, 0, -0.1f * band), p + Ogre::Vector3(-half, 0, -0.1f * band),
         Ogre::ColourValue(c.r, c.g, c.b));
  }
  const Ogre::ColourValue dark(0.1f, 0.1f, 0.1f);
  const float arrow = static_cast<float>(4 * l);
  const Ogre::Vector3 push(point(0).x - 0.3f * static_cast<float>(l), 0, static_cast<float>(m.pusher_height));
  quad(push + Ogre::Vector3(-arrow, 0, -0.15f * arrow), push + Ogre::Vector3(-0.4f * arrow, 0, -0.15f * arrow),
       push + Ogre::Vector3(-0.4f * arrow, 0, 0.15f * arrow), push + Ogre::Vector3(-arrow, 0, 0.15f * arrow), dark);
  for (const Ogre::Vector3& p : {push, push + Ogre::Vector3(-0.4f * arrow, 0, 0.35f * arrow),
                                 push + Ogre::Vector3(-0.4f * arrow, 0, -0.35f * arrow)}) {
    overlay_->position(p);
    overlay_->colour(dark);
  }
  if (nz > 1) {
    for (int i = 0; i < nx; i += std::max(1, nx / 8)) {
      const Ogre::Vector3 top = point((nz - 1) * nx + i) + Ogre::Vector3(0, 0, 0.3f * static_cast<float>(l));
      quad(top + Ogre::Vector3(-0.15f * static_cast<float>(l), 0, 0),
           top + Ogre::Vector3(0.15f * static_cast<float>(l), 0, 0),
           top + Ogre::Vector3(0.15f * static_cast<float>(l), 0, 2.5f * static_cast<float>(l)),
           top + Ogre::Vector3(-0.15f * static_cast<float>(l), 0, 2.5f * static_cast<float>(l)), dark);
    }
  }
  const float bar_x = static_cast<float>((nx - 1) * l + 3 * l), bar_w = static_cast<float>(1.5 * l);
  const float bar_h = static_cast<float>(std::max(nz - 1, 8) * l);
  const int steps = 32;
  for (int k = 0; k < steps; ++k) {
    const double value = range.min + (range.max - range.min) * (k + 0.5) / steps;
    const Rgb c = colorOf(value, range);
    const float z0 = bar_h * k / steps, z1 = bar_h * (k + 1) / steps;
    quad(Ogre::Vector3(bar_x, 0, z0), Ogre::Vector3(bar_x + bar_w, 0, z0), Ogre::Vector3(bar_x + bar_w, 0, z1),
         Ogre::Vector3(bar_x, 0, z1), Ogre::ColourValue(c.r, c.g, c.b));
  }
  overlay_->end();
  // The range also goes into the display's status: the labels need rviz's fonts, which some rviz
  // builds do not load.
  setStatus(
      rviz::StatusProperty::Ok, "Colour range",
      QString::fromStdString(fieldLabel(field) + ": " + shortNumber(range.min) + " to " + shortNumber(range.max)));
  min_label_->setCaption(shortNumber(range.min));
  max_label_->setCaption(shortNumber(range.max));
  title_label_->setCaption(fieldLabel(field));
  min_label_->setGlobalTranslation(Ogre::Vector3(bar_x + 1.3f * bar_w, 0, 0));
  max_label_->setGlobalTranslation(Ogre::Vector3(bar_x + 1.3f * bar_w, 0, bar_h));
  title_label_->setGlobalTranslation(Ogre::Vector3(bar_x, 0, bar_h + 2.0f * static_cast<float>(l)));
}

}  // namespace friction_rviz

#include <pluginlib/class_list_macros.hpp>
PLUGINLIB_EXPORT_CLASS(friction_rviz::SliderDisplay, rviz::Display)
