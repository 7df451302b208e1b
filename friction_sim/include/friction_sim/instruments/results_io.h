// Plain-text results of a run: the slip-event table, the per-node event table, the loading curve, the
// stresses at each event and the one-screen summary.
#pragma once

#include <fstream>
#include <ostream>
#include <string>
#include <vector>

#include "friction_sim/instruments/instruments.h"
#include "friction_sim/instruments/slip_events.h"
#include "friction_sim/run/run_driver.h"
#include "friction_sim/run/simulation.h"

namespace friction {

struct RunSummary {
  std::string scene_name;       ///< the scene's name
  std::string stop_reason;      ///< which stop condition ended the run, or why it was cut short
  EventTally events;            ///< the run's slip events summed up
  double simulated_time = 0.0;  ///< s
  long long steps = 0;          ///< time steps integrated (a fast-forward jump counts as none)
  double wall_time = 0.0;       ///< s
  double startup_time = 0.0;    ///< s of the wall time before the first step; 0 where not measured
  double relative_energy_residual =
      0.0;                       ///< work in − (Δelastic + kinetic + dissipated), over the budget's largest term
  double time_step = 0.0;        ///< s
  double stability_limit = 0.0;  ///< s
};

RunSummary summarize(const Simulation& simulation, double wall_time, double startup_time = 0.0);
void printSummary(std::ostream& out, const RunSummary& summary);

/// One row per event. Its front speed is the running front's median v_c (summarizeFrontSpeeds), also as
/// v_c/c_S and v_c/c_R (MODEL.md §6), with the count of fits left out of it.
void writeEventsHeader(std::ostream& out);
void writeEventRow(std::ostream& out, const SlipEvent& event, const Scene& scene);
void writeEventsCsv(std::ostream& out, const std::vector<SlipEvent>& events, const Scene& scene);
/// One row per (event, interface node): slip, first-unstick and last-slip times, front speed, peak slip velocity.
void writeEventNodesHeader(std::ostream& out);
void writeEventNodeRows(std::ostream& out, const SlipEvent& event, const std::vector<double>& node_positions);
void writeEventNodesCsv(std::ostream& out, const std::vector<SlipEvent>& events,
                        const std::vector<double>& node_positions);
void writeLoadingHeader(std::ostream& out);
void writeLoadingRow(std::ostream& out, const LoadCellReading& reading);
/// stresses.csv, written as the run goes: its header, then per event and `phase` (onset, end) one row per
/// interface node with the strain gauge above it (NaN where there is none) and the interface's stresses.
void writeStressesHeader(std::ostream& out);
void writeStressRows(std::ostream& out, int event, const char* phase, const InterfaceFrame& frame,
                     const GaugeProfile& gauges);
/// A stream that writes stresses.csv as the run goes, its header first: at each event's onset the loaded
/// state that gave way, at its end the state then; `ended`, if given, is called after the end's rows.
std::unique_ptr<EventStream> stressesStream(std::ostream& out, const EventStream::Ended& ended = nullptr);

/// A run's result folder (docs/offline_runner.md), written as the run goes so that its memory stays
/// flat however long it runs: events.csv, event_nodes.csv, loading.csv and stresses.csv row by row,
/// scene.yaml and summary.txt at the end.
class ResultsFolder {
 public:
  /// Creates `directory` and its files; throws std::runtime_error, saying why, if it cannot.
  explicit ResultsFolder(const std::string& directory);
  /// Registers the streams that write the tables on `driver`, the loading curve at the scene's
  /// instruments.loading_curve_rate from the state now; `ended` is called after each event's rows.
  void addStreams(RunDriver& driver, const EventStream::Ended& ended = nullptr);
  /// Writes scene.yaml and summary.txt, the summary also to `console`; `startup_time` is the part of
  /// `wall_time` before the first step. False if a file could not be written in full.
  bool finish(const Simulation& simulation, double wall_time, double startup_time, std::ostream& console);

 private:
  std::string directory_;
  std::ofstream events_, event_nodes_, loading_, stresses_;
};

}  // namespace friction
