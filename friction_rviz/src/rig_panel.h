// rviz panel of the rig: the loading curve F_X(t) as it comes in (F_Z in the stage line), the precursors'
// L_p/L against F_X/F_Z, the stage state, and buttons that send stage commands through the
// simulator's send_command service, showing its reply (and the reason for a refusal).
//
// Subscribes (under the namespace typed in the panel, default /rig): load_cells, slip_events,
// stage_state. Calls: send_command, pause.
#pragma once

#ifndef Q_MOC_RUN
#include <friction_msgs/SlipEvent.h>
#include <friction_msgs/StageCommand.h>
#include <friction_msgs/StageState.h>
#include <geometry_msgs/WrenchStamped.h>
#include <ros/ros.h>
#include <rviz/panel.h>

#include "friction_rviz/history.h"
#endif

#include <QWidget>
#include <optional>
#include <string>

class QDoubleSpinBox;
class QLabel;
class QLineEdit;

namespace friction_rviz {

/// A small scatter/line plot drawn with QPainter.
class PlotWidget : public QWidget {
  Q_OBJECT
 public:
  PlotWidget(const QString& x_label, const QString& y_label, QWidget* parent = nullptr);
  struct Series {
    std::vector<double> x, y;
    QColor colour;
    bool points = false;  ///< markers rather than a line
    bool hollow = false;  ///< markers outlined only
    QString label;        ///< in the legend; none if empty
  };
  void setSeries(std::vector<Series> series);
  QSize sizeHint() const override { return QSize(320, 160); }

 protected:
  void paintEvent(QPaintEvent* event) override;

 private:
  QString x_label_, y_label_;
  std::vector<Series> series_;
};

class RigPanel : public rviz::Panel {
  Q_OBJECT
 public:
  explicit RigPanel(QWidget* parent = nullptr);
  void load(const rviz::Config& config) override;
  void save(rviz::Config config) const override;

 private Q_SLOTS:
  void connectToRig();
  void refresh();
  void drive();
  void hold();
  void moveTo();
  void setNormalLoad();
  void togglePause();

 private:
  void send(const friction_msgs::StageCommand& command);
  void onLoadCells(const geometry_msgs::WrenchStamped::ConstPtr& msg);
  void onEvent(const friction_msgs::SlipEvent::ConstPtr& msg);
  void onStageState(const friction_msgs::StageState::ConstPtr& msg);

  ros::Subscriber load_cells_sub_, events_sub_, stage_sub_;
  ros::ServiceClient command_client_, pause_client_;
  QLineEdit* namespace_edit_;
  QDoubleSpinBox *speed_, *target_, *normal_load_;
  QLabel *state_label_, *reply_label_;
  PlotWidget *loading_plot_, *precursor_plot_;
  SeriesHistory shear_{20000};
  PrecursorScatter events_;
  std::optional<friction_msgs::StageState> last_state_;  ///< none yet from the rig connected to
  std::string connected_namespace_;                      ///< resolved, of the rig the panel shows
};

}  // namespace friction_rviz
