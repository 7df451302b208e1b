#include "friction_rviz/history.h"

#include <algorithm>
#include <cmath>

#include "friction_rviz/color_map.h"

namespace friction_rviz {

bool SeriesHistory::add(double time, double value) {
  const bool jumped = !times_.empty() && time < times_.back();
  if (jumped) clear();
  times_.push_back(time);
  values_.push_back(value);
  while (times_.size() > capacity_) {
    times_.pop_front();
    values_.pop_front();
  }
  return jumped;
}

void PrecursorScatter::add(double onset_shear_force, double onset_normal_force, double rupture_length,
                           double slider_length, int kind) {
  const double shear_ratio = onset_shear_force / onset_normal_force;
  const double length_ratio = rupture_length / slider_length;
  if (kind < 0 || kind >= static_cast<int>(points_.size())) return;
  if (!std::isfinite(shear_ratio) || !std::isfinite(length_ratio)) return;
  Points& points = points_[kind];
  points.shear_ratio.push_back(shear_ratio);
  points.length_ratio.push_back(length_ratio);
}

void SpaceTimeHistory::clear() {
  rows_.clear();
  events_.clear();
  dropped_ = 0;
}

bool SpaceTimeHistory::add(double time, const std::vector<double>& positions, const std::vector<double>& values,
                           const std::vector<unsigned char>& states) {
  const bool jumped_back = !rows_.empty() && time < last_time_;
  if (jumped_back || positions.size() != positions_.size()) clear();
  positions_ = positions;
  rows_.push_back(values);
  last_time_ = time;
  const std::size_t row = dropped_ + rows_.size() - 1;
  double x_min = 0.0, x_max = 0.0;
  bool sliding = false;
  for (std::size_t i = 0; i < states.size() && i < positions.size(); ++i) {
    if (states[i] != kSliding) continue;
    x_min = sliding ? std::min(x_min, positions[i]) : positions[i];
    x_max = sliding ? std::max(x_max, positions[i]) : positions[i];
    sliding = true;
  }
  const bool open = !events_.empty() && !events_.back().ended;
  if (sliding && !open) events_.push_back(StripEvent{row, row, x_min, x_max, false});
  if (sliding && open) {
    StripEvent& event = events_.back();
    event.last_row = row;
    event.x_min = std::min(event.x_min, x_min);
    event.x_max = std::max(event.x_max, x_max);
  }
  if (!sliding && open) {
    events_.back().last_row = row;
    events_.back().ended = true;
  }
  while (rows_.size() > capacity_) {
    rows_.pop_front();
    ++dropped_;
  }
  events_.erase(std::remove_if(events_.begin(), events_.end(),
                               [&](const StripEvent& e) { return e.ended && e.last_row < dropped_; }),
                events_.end());
  return jumped_back;
}

std::vector<StripEvent> SpaceTimeHistory::visibleEvents() const {
  std::vector<StripEvent> out;
  for (StripEvent event : events_) {
    event.first_row = event.first_row < dropped_ ? 0 : event.first_row - dropped_;
    event.last_row -= dropped_;
    out.push_back(event);
  }
  return out;
}

}  // namespace friction_rviz
