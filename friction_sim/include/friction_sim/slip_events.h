// Slip events (MODEL.md §6): an event starts when some interface node unsticks while all were stuck
// and ends when all are stuck again. Detected from the contact interface after every step.
#pragma once

#include <vector>

#include "friction_sim/contact_interface.h"
#include "friction_sim/model.h"
#include "friction_sim/scene.h"

namespace friction {

struct SlipEvent {
  int index = 0;                 ///< 0-based order of the event in the run
  double onset_time = 0.0;       ///< s, first threshold crossing, interpolated within the step
  double end_time = 0.0;         ///< s, last re-stick, interpolated within the step
  double onset_shear_force = 0.0;   ///< N, F_X at onset (interpolated within the step)
  double onset_normal_force = 0.0;  ///< N, F_Z at onset
  double end_shear_force = 0.0;     ///< N, F_X at the end (interpolated within the step)
  double nucleation_position = 0.0;  ///< m, mean x of the nodes that unstuck first
  double slip_min_x = 0.0;          ///< m, smallest x of a node that slipped
  double slip_max_x = 0.0;          ///< m, largest x of a node that slipped
  double rupture_length = 0.0;      ///< m, L_p = slip_max_x − slip_min_x
  bool global = false;              ///< every interface node slipped
  std::vector<double> node_slip;    ///< m, per interface node, displacement during the event
  std::vector<double> first_unstick_time;  ///< s, per node; NaN where the node did not slip
  std::vector<double> front_speed;  ///< m/s, v_c per node from the first-unstick times; NaN where undefined
};

class SlipEventDetector {
 public:
  SlipEventDetector(const Model& model, int front_fit_nodes);

  /// The load cells over the step just taken: F_X at its start and end, F_Z.
  struct StepLoads {
    double shear_start = 0.0;  ///< N
    double shear_end = 0.0;    ///< N
    double normal = 0.0;       ///< N
  };
  /// Call after every step (from step_start to step_start + dt) with the interface's new states.
  /// Returns true when an event has just ended (then `events().back()` is it).
  bool update(double step_start, double dt, const ContactInterface& contact, const Vector& u,
              const StepLoads& loads);
  bool inEvent() const { return in_event_; }
  const std::vector<SlipEvent>& events() const { return events_; }
  int globalEventCount() const { return global_count_; }

 private:
  void finish(double end_time, const Vector& u, double end_shear_force);

  std::vector<double> positions_;
  std::vector<int> dofs_;
  int fit_nodes_;
  bool in_event_ = false;
  SlipEvent current_;
  std::vector<double> onset_u_;
  std::vector<SlipEvent> events_;
  int global_count_ = 0;
};

/// m/s, front speed per node from first-unstick times t(x) (NaN = not slipped): a linear fit of t against
/// x over `fit_nodes` consecutive slipped nodes centred on each node (one more at lower x when
/// even; fewer at the ends and at unslipped gaps); v_c = 1/|dt/dx| (inf if simultaneous).
std::vector<double> frontSpeeds(const std::vector<double>& positions,
                                const std::vector<double>& first_unstick_time, int fit_nodes);

/// The model's elastic wave speeds, the scale of front speeds (MODEL.md §6).
struct WaveSpeeds {
  /// m/s, c_L of the lattice (plane stress, ν = 1/3) or the bar speed √(E/ρ) of the chain: nothing that
  /// elastic waves carry outruns it
  double longitudinal = 0.0;
  double shear = 0.0;     ///< m/s, c_S of the lattice, or the chain's bar speed
  double rayleigh = 0.0;  ///< m/s, c_R of the lattice; 0 for the chain, which has no surface wave
};
WaveSpeeds waveSpeeds(const Scene& scene);

/// An event's front speed in one number.
struct FrontSpeedSummary {
  /// m/s, median v_c over the nodes whose fit is finite and at most c_L (the mean of the middle two
  /// for an even count); NaN if there are none. Fits just below c_L next to a nucleation patch stay in.
  double median = 0.0;
  /// nodes whose fit is faster than c_L or infinite: they unstuck too nearly together for a running
  /// front, as where the pusher's load fails several nodes at once; left out of the median
  int faster_than_longitudinal = 0;
};
/// `longitudinal_speed` ≤ 0 means unknown (an analysis node without the scene): then only infinite
/// fits are left out.
FrontSpeedSummary summarizeFrontSpeeds(const std::vector<double>& front_speed, double longitudinal_speed);

}  // namespace friction
