// Slip events (MODEL.md §6): an event starts when some interface node starts slipping while none did
// and ends when none does again. Detected from the contact interface after every step.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "friction_sim/contact/contact_interface.h"
#include "friction_sim/model/model.h"
#include "friction_sim/scene/scene.h"

namespace friction {

/// What an event was (MODEL.md §6), as friction_msgs/SlipEvent's `kind` constants number them.
enum class SlipEventKind : std::uint8_t {
  Precursor = 0,       ///< before the first global event, a front that arrested (L_p > 0), slid forward
  SingleNodeSlip = 1,  ///< before the first global event, one node alone (L_p = 0): no front ran
  BackSlip = 2,        ///< before the first global event, the interface slid back, against x
  Global = 3,          ///< every node in contact slipped
  AfterGlobal = 4,     ///< not global, after the first global event: in a later stick–slip cycle
};

struct SlipEvent {
  int index = 0;                                  ///< 0-based order of the event in the run
  SlipEventKind kind = SlipEventKind::Precursor;  ///< classifySlipEvent's, set by the detector
  double onset_time = 0.0;                        ///< s, first threshold crossing, interpolated within the step
  double end_time = 0.0;                          ///< s, last re-stick, interpolated within the step
  double onset_shear_force = 0.0;                 ///< N, F_X at onset (interpolated within the step)
  double onset_normal_force = 0.0;                ///< N, F_Z at onset
  double end_shear_force = 0.0;                   ///< N, F_X at the end (interpolated within the step)
  /// N, the F_X of largest magnitude from the onset until every interface node in contact has slipped (until the
  /// end if they never all do): the load the interface bore while it gave way. For a dynamic event it is
  /// the onset's, as F_X drops while the front runs; an interface that creeps (slip weakening with a
  /// long ξ_µ) goes on taking load after its first node unsticks and gives way as a whole later. Not
  /// beyond that moment: a stage driven fast may load the sliding slider further (the single block).
  double peak_shear_force = 0.0;
  /// F_X/F_Z at the peak: µ_s,macro over a global event
  double peakShearRatio() const { return peak_shear_force / onset_normal_force; }
  /// N, F_X averaged over time from onset to end; F_Z likewise. Their ratio over a global event is
  /// µ_k,macro (MODEL.md §6): where the slider is at rest before and after, the pusher's mean force is
  /// the interface's mean friction during the event (exactly so for the chain, whose blocks stand still
  /// when stuck: µ_k·N for a single block; nearly so for the lattice, whose bulk may still ring).
  double mean_shear_force = 0.0;
  double mean_normal_force = 0.0;  ///< N
  /// mean F_X / mean F_Z (µ_k,macro over a global event)
  double meanShearRatio() const { return mean_shear_force / mean_normal_force; }
  double nucleation_position = 0.0;  ///< m, mean x of the nodes that unstuck first
  double slip_min_x = 0.0;           ///< m, smallest x of a node that slipped
  double slip_max_x = 0.0;           ///< m, largest x of a node that slipped
  double rupture_length = 0.0;       ///< m, L_p = slip_max_x − slip_min_x (L for one node: measureExtent)
  bool global = false;               ///< every interface node in contact with the track slipped (measureExtent)
  /// The run stopped during the event: it ends where the run ended, its extent and slips as they were then.
  bool unfinished = false;
  std::vector<double> node_slip;           ///< m, per interface node, displacement during the event
  std::vector<double> first_unstick_time;  ///< s, per node; NaN where the node did not slip
  /// s, per node, the end of the last step (the simulator) or frame (the camera) in which it slipped; NaN
  /// where it did not slip: whether the slip behind a front still runs when the front reaches a point
  std::vector<double> last_slip_time;
  std::vector<double> front_speed;  ///< m/s, v_c per node from the first-unstick times; NaN where undefined
  /// m/s, per node, the largest slip speed |dx/dt| it slid at during the event (0 where it did not
  /// slide): the slip velocity behind the front, which the experiments find proportional to v_c
  std::vector<double> peak_slip_velocity;
  double median_front_speed = std::numeric_limits<double>::quiet_NaN();  ///< m/s, summarizeFrontSpeeds; NaN: none
  int front_fits_left_out = 0;  ///< fits left out of that median (summarizeFrontSpeeds)
  /// m, mean slip of the nodes that slipped (NaN if none did); negative for a back-slip.
  double meanSlip() const;
  /// The interface slid back, against x (meanSlip() < 0), as where the stage draws back and the shear
  /// it stored relaxes, or beside a trailing corner that lifts off: an event, but no precursor of
  /// sliding, whatever its extent (a global one is a global event, slid back as a whole).
  bool backSlip() const { return meanSlip() < 0.0; }
};

/// The kind of a finished `event` (its extent and slips measured), given whether a global event came
/// before it in the run. The one rule behind the summary's counts, the messages and the plots.
SlipEventKind classifySlipEvent(const SlipEvent& event, bool after_a_global_event);

/// FNV-1a over bytes: the run's state hash (Simulation::stateHash), its events' included.
class StateHash {
 public:
  void mix(const void* data, std::size_t bytes) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < bytes; ++i) {
      value_ ^= p[i];
      value_ *= 1099511628211ULL;
    }
  }
  std::uint64_t value() const { return value_; }

 private:
  std::uint64_t value_ = 1469598103934665603ULL;
};

/// A precursor in the L_p/L–F_X/F_Z plane.
struct PrecursorPoint {
  double shear_ratio = 0.0;   ///< F_X/F_Z at onset
  double length_ratio = 0.0;  ///< L_p/L
};

/// A run's events summed up as each ends, so that the events themselves need not all be kept and a long
/// run's memory stays flat: the counts, the precursors before the first global event, that event's
/// macroscopic friction (MODEL.md §6), and a hash of every event for the run's state hash.
struct EventTally {
  int events = 0;                      ///< slip events that ended
  int global_events = 0;               ///< of them, global
  bool last_event_unfinished = false;  ///< the run stopped during its last event (SlipEvent::unfinished)
  int precursors = 0;                  ///< non-global events before the first global one, back-slips not counted
  int back_slips = 0;  ///< events before the first global one in which the interface slid back (SlipEvent::backSlip)
  int single_node_precursors = 0;  ///< of those, events in which one node alone slipped (L_p = 0): no front ran
  std::vector<PrecursorPoint> precursor_points;
  /// µ_s,macro = F_X/F_Z at the first global event, at its peak (SlipEvent::peak_shear_force; NaN if none)
  double static_friction_macro = std::numeric_limits<double>::quiet_NaN();
  /// µ_k,macro = mean F_X / mean F_Z over the first global event, from onset to end (NaN if none)
  double kinetic_friction_macro = std::numeric_limits<double>::quiet_NaN();
  StateHash hash;  ///< of every event's times, forces, extent and slips
  /// Counts `event` in, on a slider of length `slider_length` (m).
  void add(const SlipEvent& event, double slider_length);
};

/// The nodes that touched the track during an event so far: every one while none is lifted, which is
/// the rule and is checked in constant time.
class ContactDuringEvent {
 public:
  /// A new event on `nodes` interface nodes.
  void start(std::size_t nodes);
  /// Notes the states now (ContactState values); `detached` of them lifted.
  template <class StateOf>
  void note(std::size_t detached, StateOf state_of) {
    if (count_ == touched_.size()) return;
    for (std::size_t node = 0; node < touched_.size(); ++node) {
      if (detached == 0 || state_of(node) != ContactState::Detached) touch(node);
    }
  }
  /// A node seen slipping touched the track, whatever its state now (it may have lifted in the same step).
  void touch(std::size_t node) {
    if (!touched_[node]) {
      touched_[node] = 1;
      ++count_;
    }
  }
  std::size_t count() const { return count_; }

 private:
  std::vector<char> touched_;
  std::size_t count_ = 0;
};

/// When a node counts as slipping in an event, and when an event is over. Speed 0 counts every sliding
/// node, and an event ends when none slides: for laws whose nodes stick between events. Rate-and-state
/// nodes creep between events, slowly and under the load, so their events need a speed above that creep;
/// a node near that speed, and a lattice ringing, cross it back and forth within one rupture, so such an
/// event ends only once no node has slipped for a quiet time (slipCriterion).
struct SlipCriterion {
  double speed = 0.0;       ///< m/s, the least slip speed of a slipping node
  double quiet_time = 0.0;  ///< s, no node slipping for this long ends an event (at the first moment of it)
  bool slipping(ContactState state, double slip_velocity) const {
    return state == ContactState::Sliding && std::abs(slip_velocity) >= speed;
  }
};

class SlipEventDetector {
 public:
  /// `longitudinal_speed` (m/s, c_L) for the events' median front speed (summarizeFrontSpeeds).
  /// `slider_length` (m): L, the single block's L_p when it slips (measureExtent).
  SlipEventDetector(const Model& model, int front_fit_nodes, double longitudinal_speed, double slider_length,
                    SlipCriterion criterion = {});
  const SlipCriterion& criterion() const { return criterion_; }

  /// The load cells over the step just taken: F_X at its start and end, F_Z.
  struct StepLoads {
    double shear_start = 0.0;  ///< N
    double shear_end = 0.0;    ///< N
    double normal = 0.0;       ///< N
    /// N, F_X at `time` (s) of the step from `step_start` (s) of `dt` (s), linear across it
    double shearAt(double time, double step_start, double dt) const {
      return dt <= 0.0 ? shear_end : shear_start + (shear_end - shear_start) * (time - step_start) / dt;
    }
  };
  /// Call after every step (from step_start to step_start + dt) with the interface's new states and the
  /// model's displacements `u` and velocities `v`. Returns true when an event has just ended (then
  /// `events().back()` is it).
  bool update(double step_start, double dt, const ContactInterface& contact, const Vector& u, const Vector& v,
              const StepLoads& loads);
  bool inEvent() const { return in_event_; }
  /// Ends the event under way, if any, at `time` (s) with F_X = `shear_force` (N) and the displacements `u`,
  /// flagged unfinished: the run stops during it. One in a quiet spell ends where the spell began, as it
  /// would have had the spell lasted. Returns true if it ended one (then `events().back()` is it).
  bool finishUnfinished(double time, double shear_force, const Vector& u);
  /// In the last update a node began slipping, or an event's quiet spell began (SlipCriterion).
  bool slipChangedLastUpdate() const { return !began_.empty() || quiet_began_; }
  /// The latest events, oldest first: every one of a run with fewer than 2·kKeptEvents, and at least the
  /// last kKeptEvents of a longer run, whose earlier ones are only in tally(). `index` is each one's in
  /// the run.
  const std::vector<SlipEvent>& events() const { return events_; }
  const EventTally& tally() const { return tally_; }
  static constexpr std::size_t kKeptEvents = 256;

 private:
  /// Starts an event at the step's earliest onset of slip among began_.
  void startEvent(double step_start, double dt, const ContactInterface& contact, const Vector& u,
                  const StepLoads& loads);
  void finish();
  /// Records what the event's end will be if the quiet spell beginning now (quiet_since_) lasts: F_X =
  /// `shear_force` (N), the impulses so far and the displacements `u`.
  void noteQuietStart(double shear_force, const Vector& u);
  /// Notes which nodes began and ceased slipping in the step, and when (SlipCriterion).
  void watchSlip(double step_start, double dt, const ContactInterface& contact, const Vector& v);

  std::vector<double> positions_;
  std::vector<int> dofs_;
  int fit_nodes_;
  double longitudinal_speed_;
  double slider_length_;  ///< m, L
  SlipCriterion criterion_;
  // From the first moment of a quiet spell in the current event: what its end will be if it lasts.
  double quiet_since_ = 0.0;  ///< s; NaN while a node slips
  /// s, the end of the step it began in, from which it is timed (as the camera times it)
  double quiet_step_end_ = 0.0;
  bool quiet_began_ = false;           ///< in the last update
  double quiet_shear_force_ = 0.0;     ///< N, F_X then
  double quiet_shear_impulse_ = 0.0;   ///< N·s, ∫F_X dt of the event until then
  double quiet_normal_impulse_ = 0.0;  ///< N·s
  std::vector<double> quiet_u_;        ///< m, the interface's x displacements at the end of that step
  // What watchSlip saw in the last step.
  std::vector<int> began_;          ///< nodes that began slipping
  std::vector<double> began_at_;    ///< s, per node: when it began, for the nodes in began_
  std::size_t slipping_count_ = 0;  ///< nodes slipping at the step's end
  double last_ceased_ = 0.0;        ///< s, when the last node that ceased slipping did; NaN if none did
  // Past steps' speeds, for a criterion with a speed: the crossings interpolated within the step.
  std::vector<double> slip_speed_;  ///< m/s, per node, |v| if sliding, else 0
  bool in_event_ = false;
  SlipEvent current_;
  void notePeak(double shear_force);
  std::size_t slipped_ = 0;        ///< nodes of the current event that have slipped so far
  ContactDuringEvent in_contact_;  ///< of the current event
  double shear_impulse_ = 0.0;     ///< N·s, ∫F_X dt of the current event so far
  double normal_impulse_ = 0.0;    ///< N·s, ∫F_Z dt
  std::vector<double> onset_u_;
  std::vector<SlipEvent> events_;
  EventTally tally_;
};

/// The nodes of a front-speed fit of `fit_nodes` nodes centred on a node: as many at lower x as at
/// higher, one more at lower x when even (for a front from the trailing edge, the nodes it has
/// crossed: the last node before an arrest has a speed).
struct FitWindow {
  int behind;  ///< nodes at lower x
  int ahead;   ///< nodes at higher x
};
FitWindow frontFitWindow(int fit_nodes);

/// m/s, front speed per node from first-unstick times t(x) (NaN = not slipped): a linear fit of t against
/// x over the slipped nodes of the node's frontFitWindow (fewer at the ends and at unslipped gaps);
/// v_c = 1/|dt/dx| (inf if simultaneous).
std::vector<double> frontSpeeds(const std::vector<double>& positions, const std::vector<double>& first_unstick_time,
                                int fit_nodes);

/// The model's elastic wave speeds, the scale of front speeds (MODEL.md §6).
struct WaveSpeeds {
  /// m/s, c_L of the lattice (plane stress, ν = 1/3) or the bar speed √(E/ρ) of the chain: nothing that
  /// elastic waves carry outruns it
  double longitudinal = 0.0;
  double shear = 0.0;     ///< m/s, c_S of the lattice, or the chain's bar speed
  double rayleigh = 0.0;  ///< m/s, c_R of the lattice; 0 for the chain, which has no surface wave
};
WaveSpeeds waveSpeeds(const Scene& scene);

/// The scene's: instruments.event_slip_speed and, with a speed, a quiet time of one shear-wave transit of
/// the slider, L/c_S (145 µs for the PMMA slider): a front still running, or the slider still ringing
/// from the same rupture, sets a node slipping again within it.
SlipCriterion slipCriterion(const Scene& scene);

/// An event's front speed in one number: the speed of the front that ran, not of the nucleation.
struct FrontSpeedSummary {
  /// m/s, median v_c over the fits of a running front (the mean of the middle two for an even count);
  /// NaN if there are none
  double median = 0.0;
  /// fits left out of the median. A fit faster than c_L (or infinite) is of nodes that unstuck too nearly
  /// together for a running front, as where the pusher's load fails several nodes at once. Around the
  /// nucleation those nodes form a patch: from the node(s) that unstuck first, through the neighbours
  /// whose fits are that fast. Left out are the patch, every fit whose window reaches into it (its
  /// slope mixes the patch's near-simultaneous times with the front's, so it reads fast, yet may stay
  /// below c_L) and any other fit faster than c_L.
  int left_out = 0;
};
/// From an event's per-node front_speed and first_unstick_time (NaN where not slipped), fitted over
/// `fit_nodes` nodes. `longitudinal_speed` ≤ 0 means unknown (an analysis node without the scene): then
/// only infinite fits count as too fast.
FrontSpeedSummary summarizeFrontSpeeds(const std::vector<double>& front_speed,
                                       const std::vector<double>& first_unstick_time, int fit_nodes,
                                       double longitudinal_speed);

/// Sets an ended event's front_speed (frontSpeeds, from its first_unstick_time at the nodes' `positions`,
/// m), median_front_speed and front_fits_left_out (summarizeFrontSpeeds).
void measureFronts(SlipEvent& event, const std::vector<double>& positions, int fit_nodes, double longitudinal_speed);

/// Sets slip_min_x, slip_max_x, rupture_length and global from the nodes that slipped (those with a
/// first-unstick time) at `positions` (m). L_p spans them; a one-node interface, the single block, is the
/// whole slider: L_p = `slider_length` (m) once it slips. The event is global when every node that touched
/// the track during it slipped (`nodes_in_contact` of them): a node lifted throughout cannot slip, and a
/// slider that slides as a whole with its trailing corner lifted does so globally.
void measureExtent(SlipEvent& event, const std::vector<double>& positions, double slider_length,
                   std::size_t nodes_in_contact);

}  // namespace friction
