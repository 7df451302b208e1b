// Slip events seen from the instruments alone (ROS-free core of the precursor detector node): the
// interface camera's frames and the load cells, as an experimentalist has them. An event starts at a
// frame with a slipping node (SlipCriterion) after a frame with none and ends at the next frame with
// none, once the frames show none for the criterion's quiet time; the slipped nodes are those seen
// slipping in between. The simulator publishes a frame at every step where a node begins slipping and
// where an event ends, so the camera misses no node's slip and no event, provided that every frame
// arrives (a frame lost, or a bag whose simulator published frames at its rate alone, can hide a short
// slip).
#pragma once

#include <deque>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "friction_sim/instruments/instruments.h"
#include "friction_sim/instruments/slip_events.h"

namespace friction {

class FrameEventDetector {
 public:
  /// `front_fit_nodes` as in the scene; `longitudinal_speed` (m/s, c_L; ≤ 0 unknown) for the events'
  /// median front speed (summarizeFrontSpeeds); `slider_length` (m, L; 0 unknown: the frames' span);
  /// `criterion` the scene's (instruments.event_slip_speed).
  FrameEventDetector(int front_fit_nodes, double longitudinal_speed, double slider_length = 0.0,
                     SlipCriterion criterion = {});

  /// Load-cell samples, in time order.
  void addLoadCells(const LoadCellReading& reading);
  /// Interface frames, in time order. A frame whose arrays differ in length, or that has another number
  /// of nodes than the event under way, is left out: returns why ("" when taken).
  std::string addFrame(const InterfaceFrame& frame);
  /// Events that have ended and whose load-cell readings have arrived (the two topics travel
  /// separately, so the load cells of an event's last step may come after its last frame); with
  /// `no_more_readings`, every ended event, from the readings there are (the stream restarts).
  std::vector<SlipEvent> takeCompletedEvents(bool no_more_readings = false);
  /// Forgets everything (time jumped backwards, e.g. looped playback).
  void reset();

  /// m, the slider's length L: as given, or as the frames show it (the last interface node sits at
  /// x = L; 0 before the first frame, and for a single block).
  double sliderLength() const { return given_length_ > 0.0 ? given_length_ : frames_length_; }

 private:
  /// The event's forces from the load cells kept: at its onset and end, its peak, and its means.
  void addLoadCellsTo(SlipEvent& event) const;
  int front_fit_nodes_;
  double longitudinal_speed_;
  double given_length_;  ///< m, L from the run's scene; 0 unknown
  SlipCriterion criterion_;
  double frames_length_ = 0.0;  ///< m, the last interface node's x in the frames
  double last_frame_time_ = -std::numeric_limits<double>::infinity();
  int next_index_ = 0;
  std::deque<LoadCellReading> load_cells_;
  std::optional<InterfaceFrame> last_stuck_frame_;
  std::optional<InterfaceFrame> quiet_frame_;  ///< the first of the current event's frames with no node slipping
  bool in_event_ = false;
  bool seen_global_ = false;  ///< a global event has ended: the later non-global ones come after it
  SlipEvent current_;
  ContactDuringEvent in_contact_;  ///< of the current event
  std::deque<SlipEvent> ended_;    ///< waiting for their load cells
};

}  // namespace friction
