// Plain-text results of a run: the slip-event table, the per-node event table, the loading curve and
// the one-screen summary.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "friction_sim/instruments/instruments.h"
#include "friction_sim/instruments/slip_events.h"
#include "friction_sim/run/run_driver.h"
#include "friction_sim/run/simulation.h"

namespace friction {

struct PrecursorPoint {
  double shear_ratio = 0.0;   ///< F_X/F_Z at onset
  double length_ratio = 0.0;  ///< L_p/L
};

struct RunSummary {
  std::string scene_name;              ///< the scene's name
  std::string stop_reason;             ///< which stop condition ended the run, or why it was cut short
  int events = 0;                      ///< slip events that ended
  bool last_event_unfinished = false;  ///< the run stopped during its last event (SlipEvent::unfinished)
  int precursors = 0;                  ///< non-global events before the first global one, back-slips not counted
  int back_slips = 0;  ///< events before the first global one in which the interface slid back (SlipEvent::backSlip)
  int single_node_precursors = 0;  ///< of those, events in which one node alone slipped (L_p = 0): no front ran
  std::vector<PrecursorPoint> precursor_points;
  /// µ_s,macro = F_X/F_Z at the first global event, at its peak (SlipEvent::peak_shear_force; NaN if none)
  double static_friction_macro = 0.0;
  /// µ_k,macro = mean F_X / mean F_Z over the first global event, from onset to end (NaN if none)
  double kinetic_friction_macro = 0.0;
  double simulated_time = 0.0;  ///< s
  long long steps = 0;          ///< time steps integrated (a fast-forward jump counts as none)
  double wall_time = 0.0;       ///< s
  double relative_energy_residual =
      0.0;                       ///< work in − (Δelastic + kinetic + dissipated), over the budget's largest term
  double time_step = 0.0;        ///< s
  double stability_limit = 0.0;  ///< s
};

RunSummary summarize(const Simulation& simulation, double wall_time);
void printSummary(std::ostream& out, const RunSummary& summary);

/// One row per event. Its front speed is the running front's median v_c (summarizeFrontSpeeds), also as
/// v_c/c_S and v_c/c_R (MODEL.md §6), with the count of fits left out of it.
void writeEventsCsv(std::ostream& out, const std::vector<SlipEvent>& events, const Scene& scene);
/// One row per (event, interface node): slip, first-unstick time and front speed.
void writeEventNodesCsv(std::ostream& out, const std::vector<SlipEvent>& events,
                        const std::vector<double>& node_positions);
void writeLoadingCsv(std::ostream& out, const std::vector<LoadCellReading>& readings);
/// stresses.csv, written as the run goes: its header, then per event and `phase` (onset, end) one row per
/// interface node with the strain gauge above it (NaN where there is none) and the interface's stresses.
void writeStressesHeader(std::ostream& out);
void writeStressRows(std::ostream& out, int event, const char* phase, const InterfaceFrame& frame,
                     const GaugeProfile& gauges);
/// A stream that writes stresses.csv as the run goes, its header first: at each event's onset the loaded
/// state that gave way, at its end the state then; `ended`, if given, is called after the end's rows.
std::unique_ptr<EventStream> stressesStream(std::ostream& out, const EventStream::Ended& ended = nullptr);

/// The result folder's files written at a run's end, in `out_dir`: events.csv, event_nodes.csv,
/// loading.csv, scene.yaml (the scene as run) and summary.txt, the summary also printed to `console`.
/// False if one could not be written in full.
bool writeRunEndFiles(const std::string& out_dir, const Simulation& simulation,
                      const std::vector<LoadCellReading>& loading, double wall_time, std::ostream& console);

}  // namespace friction
