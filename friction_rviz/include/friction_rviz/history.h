// Bounded histories the displays and the panel draw from (drawing-free, unit-tested): they keep at
// most a fixed number of entries, and forget everything when time jumps backwards (looped playback,
// a reset).
#pragma once

#include <array>
#include <cstddef>
#include <deque>
#include <vector>

namespace friction_rviz {

/// A time series of (t, y) samples with a maximum length.
class SeriesHistory {
 public:
  explicit SeriesHistory(std::size_t capacity) : capacity_(capacity) {}
  /// Adds a sample; returns true if time jumped back and the history was cleared first.
  bool add(double time, double value);
  void clear() {
    times_.clear();
    values_.clear();
  }
  const std::deque<double>& times() const { return times_; }
  const std::deque<double>& values() const { return values_; }

 private:
  std::size_t capacity_;
  std::deque<double> times_, values_;
};

/// The kinds of slip event the panel's L_p/L against F_X/F_Z plot tells apart, numbered as
/// friction_msgs/SlipEvent's `kind` constants: the simulator classifies each event (friction_sim's
/// classifySlipEvent), the panel only draws it.
enum class EventKind { Precursor = 0, SingleNodeSlip = 1, BackSlip = 2, Global = 3, AfterGlobal = 4 };

/// The points of the precursor plot, (F_X/F_Z at onset, L_p/L), by kind.
class PrecursorScatter {
 public:
  struct Points {
    std::vector<double> shear_ratio, length_ratio;
  };
  /// Forces in N, lengths in m, `kind` a SlipEvent message's. An event whose ratios are not finite (F_Z or
  /// L zero), or whose kind is none of EventKind's, adds no point.
  void add(double onset_shear_force, double onset_normal_force, double rupture_length, double slider_length, int kind);
  void clear() { points_ = {}; }
  const Points& points(EventKind kind) const { return points_[static_cast<int>(kind)]; }

 private:
  std::array<Points, 5> points_;
};

/// A slip event as the space–time strip outlines it.
struct StripEvent {
  std::size_t first_row = 0;        ///< absolute index of the row where it started
  std::size_t last_row = 0;         ///< absolute index of the row where it ended (or the newest row)
  double x_min = 0.0, x_max = 0.0;  ///< m, slipped range
  bool ended = false;
};

/// The interface camera's rows (one per frame: a value per node and the contact states), newest last,
/// with the slip events outlined from the states.
class SpaceTimeHistory {
 public:
  explicit SpaceTimeHistory(std::size_t capacity) : capacity_(capacity) {}
  /// Adds a frame; returns true if time jumped back and the history was cleared first.
  bool add(double time, const std::vector<double>& positions, const std::vector<double>& values,
           const std::vector<unsigned char>& states);
  void clear();

  std::size_t size() const { return rows_.size(); }
  const std::vector<double>& row(std::size_t i) const { return rows_[i]; }  ///< 0 = oldest kept
  const std::vector<double>& positions() const { return positions_; }
  /// Events whose rows are (partly) still kept; row indices relative to the oldest kept row.
  std::vector<StripEvent> visibleEvents() const;

 private:
  std::size_t capacity_;
  std::deque<std::vector<double>> rows_;
  double last_time_ = 0.0;  ///< s, of the newest row (when there is one), to notice time jumping back
  std::vector<double> positions_;
  std::size_t dropped_ = 0;  ///< rows dropped from the front so far
  std::vector<StripEvent> events_;
};

}  // namespace friction_rviz
