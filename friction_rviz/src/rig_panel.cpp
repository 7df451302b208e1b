#include "rig_panel.h"

#include <friction_msgs/SendStageCommand.h>
#include <std_srvs/SetBool.h>

#include <QDoubleSpinBox>
#include <QGridLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QLineEdit>
#include <QPainter>
#include <QPushButton>
#include <QTimer>
#include <QVBoxLayout>
#include <algorithm>
#include <cmath>

#include "friction_rviz/commands.h"

namespace friction_rviz {

static_assert(static_cast<int>(EventKind::Precursor) == friction_msgs::SlipEvent::PRECURSOR &&
                  static_cast<int>(EventKind::SingleNodeSlip) == friction_msgs::SlipEvent::SINGLE_NODE_SLIP &&
                  static_cast<int>(EventKind::BackSlip) == friction_msgs::SlipEvent::BACK_SLIP &&
                  static_cast<int>(EventKind::Global) == friction_msgs::SlipEvent::GLOBAL &&
                  static_cast<int>(EventKind::AfterGlobal) == friction_msgs::SlipEvent::AFTER_GLOBAL,
              "EventKind numbers the kinds as SlipEvent does");
static_assert(friction_msgs::StageState::VELOCITY == 0 && friction_msgs::StageState::HOLD == 1 &&
                  friction_msgs::StageState::POSITION == 2,
              "the state line names the modes by these numbers");

namespace {
/// The state line of the stage state `state`.
QString stateLine(const friction_msgs::StageState& state) {
  const char* modes[] = {"velocity", "hold", "position"};
  return QString("stage: t = %1 s, %2, X_s = %3 mm, V = %4 mm/s, F_X = %5 N, F_Z = %6 N, global events %7%8")
      .arg(state.header.stamp.toSec(), 0, 'f', 4)
      .arg(modes[std::min<int>(state.mode, 2)])
      .arg(state.position * 1e3, 0, 'f', 4)
      .arg(state.velocity * 1e3, 0, 'f', 3)
      .arg(state.shear_force, 0, 'f', 1)
      .arg(state.normal_force, 0, 'f', 1)
      .arg(state.global_events)
      .arg(state.paused ? " (paused)" : "");
}
}  // namespace

PlotWidget::PlotWidget(const QString& x_label, const QString& y_label, QWidget* parent)
    : QWidget(parent), x_label_(x_label), y_label_(y_label) {
  setMinimumHeight(120);
}

void PlotWidget::setSeries(std::vector<Series> series) {
  series_ = std::move(series);
  update();
}

void PlotWidget::paintEvent(QPaintEvent*) {
  QPainter painter(this);
  painter.fillRect(rect(), Qt::white);
  const QRectF area(74, 8, width() - 84, height() - 34);
  painter.setPen(Qt::gray);
  painter.drawRect(area);
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  for (const Series& s : series_) {
    for (double v : s.x) x0 = std::min(x0, v), x1 = std::max(x1, v);
    for (double v : s.y) y0 = std::min(y0, v), y1 = std::max(y1, v);
  }
  painter.setPen(Qt::black);
  painter.drawText(QRectF(area.left(), area.bottom() + 4, area.width(), 16), Qt::AlignCenter, x_label_);
  painter.save();
  painter.translate(10, area.center().y());
  painter.rotate(-90);
  painter.drawText(QRectF(-area.height() / 2, -10, area.height(), 16), Qt::AlignCenter, y_label_);
  painter.restore();
  if (x0 == x1) {  // one point so far, or one value: centred
    const double pad = x0 != 0.0 ? 0.05 * std::abs(x0) : 1.0;
    x0 -= pad;
    x1 += pad;
  }
  if (!(x0 < x1)) return;  // no data
  y0 = std::min(y0, 0.0);
  if (!(y0 < y1)) y1 = y0 + 1.0;
  // The legend gets its own band at the top, so that no data is drawn under it; its entries go left to
  // right, on as many rows as the width needs.
  constexpr double kRow = 18.0, kKey = 30.0, kGap = 14.0;
  std::vector<QPointF> keys(series_.size());
  QPointF next(area.left() + 8, area.top() + 2);
  double legend_bottom = area.top();
  for (std::size_t i = 0; i < series_.size(); ++i) {
    if (series_[i].label.isEmpty()) continue;
    const double width = kKey + painter.fontMetrics().horizontalAdvance(series_[i].label);
    if (next.x() + width > area.right() && next.x() > area.left() + 8) next = QPointF(area.left() + 8, next.y() + kRow);
    keys[i] = next;
    next.rx() += width + kGap;
    legend_bottom = next.y() + kRow;
  }
  // Inset a little, so that markers at the ends are drawn whole.
  const QRectF data_area(QPointF(area.left() + 5, std::max(legend_bottom + 2, area.top() + 5)),
                         QPointF(area.right() - 5, area.bottom() - 5));
  painter.drawText(QRectF(20, data_area.top() - 7, 50, 14), Qt::AlignRight, QString::number(y1, 'g', 4));
  painter.drawText(QRectF(20, data_area.bottom() - 7, 50, 14), Qt::AlignRight, QString::number(y0, 'g', 4));
  painter.drawText(QRectF(area.left(), area.bottom() + 4, 80, 16), Qt::AlignLeft, QString::number(x0, 'g', 4));
  painter.drawText(QRectF(area.right() - 80, area.bottom() + 4, 80, 16), Qt::AlignRight, QString::number(x1, 'g', 4));
  auto map = [&](double x, double y) {
    return QPointF(data_area.left() + (x - x0) / (x1 - x0) * data_area.width(),
                   data_area.bottom() - (y - y0) / (y1 - y0) * data_area.height());
  };
  for (std::size_t i = 0; i < series_.size(); ++i) {
    const Series& s = series_[i];
    painter.setPen(QPen(s.colour, 1.5));
    if (s.hollow) {
      painter.setBrush(Qt::NoBrush);
    } else {
      painter.setBrush(s.colour);
    }
    if (!s.label.isEmpty()) {
      const QPointF key = keys[i] + QPointF(8, kRow / 2);
      if (s.points) {
        painter.drawEllipse(key, 3, 3);
      } else {
        painter.drawLine(key - QPointF(7, 0), key + QPointF(7, 0));
      }
      painter.drawText(QRectF(keys[i].x() + kKey - 10, keys[i].y(), area.width(), kRow),
                       Qt::AlignLeft | Qt::AlignVCenter, s.label);
    }
    if (s.points) {
      for (std::size_t i = 0; i < s.x.size(); ++i) painter.drawEllipse(map(s.x[i], s.y[i]), 3, 3);
      continue;
    }
    // One vertex per horizontal pixel at most: drawing stays cheap at any data rate.
    QPolygonF line;
    double last_pixel = -1;
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      const QPointF p = map(s.x[i], s.y[i]);
      if (p.x() - last_pixel < 1.0 && i + 1 < s.x.size()) continue;
      last_pixel = p.x();
      line << p;
    }
    painter.drawPolyline(line);
  }
}

RigPanel::RigPanel(QWidget* parent) : rviz::Panel(parent) {
  auto* layout = new QVBoxLayout;
  auto* top = new QHBoxLayout;
  top->addWidget(new QLabel("Rig namespace"));
  namespace_edit_ = new QLineEdit("/rig");
  top->addWidget(namespace_edit_);
  layout->addLayout(top);
  // F_X alone: on F_Z's scale (1920 N by default) the stick-slip would be a flat line. F_Z is in the
  // stage line below.
  loading_plot_ = new PlotWidget("t (s)", "F_X (N)");
  precursor_plot_ = new PlotWidget("F_X / F_Z", "L_p / L");
  layout->addWidget(loading_plot_);
  layout->addWidget(precursor_plot_);
  state_label_ = new QLabel;
  // As wide as a state's line from the start: the dock, sized by it, must not change width when the first
  // state replaces the shorter "waiting" line (the 3D view beside it would move). A state of the default
  // experiment's sizes.
  friction_msgs::StageState typical;
  typical.header.stamp.fromSec(0.837);
  typical.position = 3.348e-4;
  typical.velocity = 4e-4;
  typical.shear_force = 261.1;
  typical.normal_force = 1920.0;
  typical.global_events = 4;
  state_label_->setMinimumWidth(state_label_->fontMetrics().horizontalAdvance(stateLine(typical)));
  layout->addWidget(state_label_);
  auto* controls = new QGridLayout;
  speed_ = new QDoubleSpinBox;
  speed_->setRange(-1000.0, 1000.0);
  speed_->setDecimals(3);
  speed_->setValue(0.4);
  speed_->setSuffix(" mm/s");
  target_ = new QDoubleSpinBox;
  target_->setRange(-100.0, 100.0);
  target_->setDecimals(4);
  target_->setSuffix(" mm");
  normal_load_ = new QDoubleSpinBox;
  normal_load_->setRange(-100.0, 100.0);
  normal_load_->setDecimals(3);
  normal_load_->setValue(1.92);
  normal_load_->setSuffix(" kN");
  auto button = [&](const char* text, const char* slot) {
    auto* b = new QPushButton(text);
    connect(b, SIGNAL(clicked()), this, slot);
    return b;
  };
  controls->addWidget(speed_, 0, 0);
  controls->addWidget(button("Drive", SLOT(drive())), 0, 1);
  controls->addWidget(button("Hold", SLOT(hold())), 0, 2);
  controls->addWidget(target_, 1, 0);
  controls->addWidget(button("Move to", SLOT(moveTo())), 1, 1);
  controls->addWidget(button("Pause / resume", SLOT(togglePause())), 1, 2);
  controls->addWidget(normal_load_, 2, 0);
  controls->addWidget(button("Set F_Z", SLOT(setNormalLoad())), 2, 1);
  layout->addLayout(controls);
  reply_label_ = new QLabel("reply: -");
  reply_label_->setWordWrap(true);
  layout->addWidget(reply_label_);
  setLayout(layout);
  connect(namespace_edit_, SIGNAL(editingFinished()), this, SLOT(connectToRig()));
  auto* timer = new QTimer(this);
  connect(timer, SIGNAL(timeout()), this, SLOT(refresh()));
  timer->start(100);  // redraw at 10 Hz whatever the data rate
  connectToRig();
}

void RigPanel::connectToRig() {
  const std::string ns = namespace_edit_->text().toStdString();
  // A typo typed or loaded from a config ("my rig") would throw out of this slot and end rviz.
  std::string invalid;
  if (!ros::names::validate(ns, invalid)) {
    reply_label_->setText(QString::fromStdString("namespace '" + ns + "' is not a valid ROS name (" + invalid +
                                                 "); still showing " + connected_namespace_));
    return;
  }
  connected_namespace_ = ros::names::resolve(ns);
  ros::NodeHandle rig(ns);
  load_cells_sub_ = rig.subscribe("load_cells", 100, &RigPanel::onLoadCells, this);
  events_sub_ = rig.subscribe("slip_events", 100, &RigPanel::onEvent, this);
  stage_sub_ = rig.subscribe("stage_state", 10, &RigPanel::onStageState, this);
  command_client_ = rig.serviceClient<friction_msgs::SendStageCommand>("send_command");
  pause_client_ = rig.serviceClient<std_srvs::SetBool>("pause");
  shear_.clear();
  events_.clear();
  last_state_.reset();
  Q_EMIT configChanged();
}

void RigPanel::onLoadCells(const geometry_msgs::WrenchStamped::ConstPtr& msg) {
  const double t = msg->header.stamp.toSec();
  if (shear_.add(t, msg->wrench.force.x)) events_.clear();  // time jumped back (looped playback or a reset)
}

void RigPanel::onEvent(const friction_msgs::SlipEvent::ConstPtr& msg) {
  events_.add(msg->onset_shear_force, msg->onset_normal_force, msg->rupture_length, msg->slider_length, msg->kind);
}

void RigPanel::onStageState(const friction_msgs::StageState::ConstPtr& msg) { last_state_ = *msg; }

void RigPanel::refresh() {
  auto series = [](std::vector<double> x, std::vector<double> y, QColor colour, const char* label) {
    PlotWidget::Series s;
    s.x = std::move(x);
    s.y = std::move(y);
    s.colour = colour;
    s.label = label;
    return s;
  };
  auto history = [&](const SeriesHistory& h, QColor colour, const char* label) {
    return series({h.times().begin(), h.times().end()}, {h.values().begin(), h.values().end()}, colour, label);
  };
  loading_plot_->setSeries({history(shear_, QColor(20, 20, 20), "F_X (stage spring)")});
  auto events = [&](EventKind kind, QColor colour, bool hollow, const char* label) {
    PlotWidget::Series s = series(events_.points(kind).shear_ratio, events_.points(kind).length_ratio, colour, label);
    s.points = true;
    s.hollow = hollow;
    return s;
  };
  const QColor blue(40, 90, 220);
  precursor_plot_->setSeries({events(EventKind::Precursor, blue, false, "precursor"),
                              events(EventKind::SingleNodeSlip, blue, true, "single-node slip (L_p = 0)"),
                              events(EventKind::BackSlip, QColor(30, 150, 60), true, "back-slip (against x)"),
                              events(EventKind::AfterGlobal, QColor(150, 150, 150), false, "after a global slip"),
                              events(EventKind::Global, QColor(210, 30, 30), false, "global event")});
  if (!last_state_) {
    state_label_->setText(
        QString::fromStdString("stage: waiting for " + ros::names::append(connected_namespace_, "stage_state")));
    return;
  }
  state_label_->setText(stateLine(*last_state_));
}

void RigPanel::send(const friction_msgs::StageCommand& command) {
  friction_msgs::SendStageCommand call;
  call.request.command = command;
  const bool ok = command_client_.call(call);
  reply_label_->setText(
      QString::fromStdString("reply: " + replyText(ok, call.response.accepted, call.response.reason)));
}

void RigPanel::drive() { send(driveCommand(speed_->value())); }
void RigPanel::hold() { send(holdCommand()); }
void RigPanel::moveTo() { send(moveCommand(target_->value(), std::abs(speed_->value()))); }
void RigPanel::setNormalLoad() { send(normalLoadCommand(normal_load_->value())); }

void RigPanel::togglePause() {
  std_srvs::SetBool call;
  call.request.data = !(last_state_ && last_state_->paused);  // unknown yet: pause
  const bool ok = pause_client_.call(call);
  reply_label_->setText(ok ? "reply: " + QString::fromStdString(call.response.message) : "reply: no reply from pause");
}

void RigPanel::load(const rviz::Config& config) {
  rviz::Panel::load(config);
  QString ns;
  if (config.mapGetString("Namespace", &ns)) {
    namespace_edit_->setText(ns);
    connectToRig();
  }
}

void RigPanel::save(rviz::Config config) const {
  rviz::Panel::save(config);
  config.mapSetValue("Namespace", namespace_edit_->text());
}

}  // namespace friction_rviz

#include <pluginlib/class_list_macros.hpp>
PLUGINLIB_EXPORT_CLASS(friction_rviz::RigPanel, rviz::Panel)
