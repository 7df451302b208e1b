#include "friction_sim/instruments/results_io.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <stdexcept>

#include "friction_sim/scene/scene_io.h"

namespace friction {

RunSummary summarize(const Simulation& simulation, double wall_time, double startup_time) {
  RunSummary summary;
  summary.scene_name = simulation.scene().name;
  summary.stop_reason = simulation.stopReason();
  summary.events = simulation.eventTally();
  summary.simulated_time = simulation.time();
  summary.steps = simulation.steps();
  summary.wall_time = wall_time;
  summary.startup_time = startup_time;
  summary.relative_energy_residual = simulation.energy().relativeResidual();
  summary.time_step = simulation.timeStep();
  summary.stability_limit = simulation.stabilityLimit();
  return summary;
}

void printSummary(std::ostream& out, const RunSummary& s) {
  out << "scene " << s.scene_name << ": " << s.stop_reason << "\n"
      << "  simulated " << s.simulated_time << " s in " << s.steps << " steps of " << s.time_step
      << " s (stability limit " << s.stability_limit << " s)\n"
      << "  wall time " << std::setprecision(3) << s.wall_time << " s";
  if (s.startup_time > 0) out << " (before the first step " << s.startup_time << " s)";
  out << ", " << std::setprecision(4) << (s.wall_time > 0 ? s.steps / s.wall_time : 0.0) << " steps/s\n"
      << "  slip events: " << s.events.events << ", precursors before the first global event: " << s.events.precursors;
  if (s.events.single_node_precursors > 0)
    out << " (single-node slips, L_p = 0, among them: " << s.events.single_node_precursors << ")";
  if (s.events.back_slips > 0) out << "; back-slips before it, not counted: " << s.events.back_slips;
  if (s.events.last_event_unfinished) out << "; the last one unfinished (the run stopped during it)";
  out << "\n";
  if (!s.events.precursor_points.empty()) {
    out << "  precursors (F_X/F_Z, L_p/L):";
    for (const PrecursorPoint& point : s.events.precursor_points) {
      out << " (" << std::setprecision(4) << point.shear_ratio << ", " << point.length_ratio << ")";
    }
    out << "\n";
  }
  out << "  mu_s,macro = F_X/F_Z at the first global event: " << s.events.static_friction_macro << "\n"
      << "  mu_k,macro = mean F_X / mean F_Z over that event: " << s.events.kinetic_friction_macro << "\n"
      << "  energy-balance residual (relative): " << std::setprecision(3) << s.relative_energy_residual
      << (std::isnan(s.relative_energy_residual) ? " (no energy changed hands: nothing to balance)" : "") << "\n";
}

void writeEventsHeader(std::ostream& out) {
  out << "index,onset_time_s,end_time_s,onset_shear_force_N,onset_normal_force_N,shear_ratio,"
         "end_shear_force_N,nucleation_x_m,slip_min_x_m,slip_max_x_m,rupture_length_m,length_ratio,global,"
         "median_front_speed_m_s,front_speed_over_c_s,front_speed_over_c_r,front_fits_left_out,"
         "mean_shear_force_N,mean_normal_force_N,mean_shear_ratio,peak_shear_force_N,peak_shear_ratio,mean_slip_m,"
         "unfinished\n";
  out << std::setprecision(12);
}

void writeEventRow(std::ostream& out, const SlipEvent& e, const Scene& scene) {
  const double slider_length = scene.geometry.length;
  const WaveSpeeds speeds = waveSpeeds(scene);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  out << e.index << ',' << e.onset_time << ',' << e.end_time << ',' << e.onset_shear_force << ','
      << e.onset_normal_force << ',' << e.onset_shear_force / e.onset_normal_force << ',' << e.end_shear_force << ','
      << e.nucleation_position << ',' << e.slip_min_x << ',' << e.slip_max_x << ',' << e.rupture_length << ','
      << e.rupture_length / slider_length << ',' << (e.global ? 1 : 0) << ',' << e.median_front_speed << ','
      << e.median_front_speed / speeds.shear << ','
      << (speeds.rayleigh > 0.0 ? e.median_front_speed / speeds.rayleigh : nan) << ',' << e.front_fits_left_out << ','
      << e.mean_shear_force << ',' << e.mean_normal_force << ',' << e.meanShearRatio() << ',' << e.peak_shear_force
      << ',' << e.peakShearRatio() << ',' << e.meanSlip() << ',' << (e.unfinished ? 1 : 0) << '\n';
}

void writeEventsCsv(std::ostream& out, const std::vector<SlipEvent>& events, const Scene& scene) {
  writeEventsHeader(out);
  for (const SlipEvent& event : events) writeEventRow(out, event, scene);
}

void writeEventNodesHeader(std::ostream& out) {
  out << "event,node,x_m,slip_m,first_unstick_time_s,last_slip_time_s,front_speed_m_s,peak_slip_velocity_m_s\n";
  out << std::setprecision(12);
}

void writeEventNodeRows(std::ostream& out, const SlipEvent& e, const std::vector<double>& node_positions) {
  for (std::size_t node = 0; node < node_positions.size(); ++node) {
    out << e.index << ',' << node << ',' << node_positions[node] << ',' << e.node_slip[node] << ','
        << e.first_unstick_time[node] << ',' << e.last_slip_time[node] << ',' << e.front_speed[node] << ','
        << e.peak_slip_velocity[node] << '\n';
  }
}

void writeEventNodesCsv(std::ostream& out, const std::vector<SlipEvent>& events,
                        const std::vector<double>& node_positions) {
  writeEventNodesHeader(out);
  for (const SlipEvent& event : events) writeEventNodeRows(out, event, node_positions);
}

void writeLoadingHeader(std::ostream& out) {
  out << "time_s,stage_position_m,shear_force_N,normal_force_N,interface_normal_sum_N,sliding_nodes\n";
  out << std::setprecision(12);
}

void writeLoadingRow(std::ostream& out, const LoadCellReading& r) {
  out << r.time << ',' << r.stage_position << ',' << r.shear_force << ',' << r.normal_force << ','
      << r.interface_normal_sum << ',' << r.sliding_nodes << '\n';
}

void writeStressesHeader(std::ostream& out) {
  out << "event,phase,time_s,x_m,gauge_sigma_xx_Pa,gauge_sigma_zz_Pa,gauge_tau_xz_Pa,"
         "interface_normal_stress_Pa,interface_shear_stress_Pa,interface_static_coefficient\n";
  out.precision(10);
}

void writeStressRows(std::ostream& out, int event, const char* phase, const InterfaceFrame& frame,
                     const GaugeProfile& gauges) {
  for (std::size_t i = 0; i < frame.position.size(); ++i) {
    const bool gauge = i < gauges.stress.sigma_zz.size() && gauges.position[i] == frame.position[i];
    out << event << ',' << phase << ',' << frame.time << ',' << frame.position[i] << ','
        << (gauge ? gauges.stress.sigma_xx[i] : NAN) << ',' << (gauge ? gauges.stress.sigma_zz[i] : NAN) << ','
        << (gauge ? gauges.stress.tau_xz[i] : NAN) << ',' << frame.normal_stress[i] << ',' << frame.shear_stress[i]
        << ',' << frame.static_coefficient[i] << '\n';
  }
}

std::unique_ptr<EventStream> stressesStream(std::ostream& out, const EventStream::Ended& ended) {
  writeStressesHeader(out);
  return std::make_unique<EventStream>(
      [&out](const Simulation& s) {
        // The nodes that unstuck in the onset step, at their thresholds.
        const int event = s.eventTally().events;
        writeStressRows(out, event, "onset", s.interfaceFrameBeforeUnsticking(), s.gaugeProfile());
      },
      [&out, ended](const Simulation& s, const SlipEvent& event) {
        writeStressRows(out, event.index, "end", s.interfaceFrame(), s.gaugeProfile());
        if (ended) ended(s, event);
      });
}

namespace {
/// Opens `path` as a new file. An earlier run's file is removed, not truncated: ext4 writes a truncated
/// file back to disk as it is closed (auto_da_alloc), which cost a 57 × 31 run 1.4 ms of its 17.
void openAnew(std::ofstream& file, const std::string& path) {
  std::error_code ignored;  // a file that cannot be removed fails to open, which the caller checks
  std::filesystem::remove(path, ignored);
  file.open(path);
}
}  // namespace

ResultsFolder::ResultsFolder(const std::string& directory) : directory_(directory) {
  std::error_code error;
  std::filesystem::create_directories(directory, error);
  if (error) throw std::runtime_error("cannot create the directory (" + error.message() + ")");
  openAnew(events_, directory + "/events.csv");
  openAnew(event_nodes_, directory + "/event_nodes.csv");
  openAnew(loading_, directory + "/loading.csv");
  openAnew(stresses_, directory + "/stresses.csv");
  if (!events_ || !event_nodes_ || !loading_ || !stresses_) throw std::runtime_error("cannot create files in it");
  writeEventsHeader(events_);
  writeEventNodesHeader(event_nodes_);
  writeLoadingHeader(loading_);
}

void ResultsFolder::addStreams(RunDriver& driver, const EventStream::Ended& ended) {
  const Simulation& simulation = driver.simulation();
  writeLoadingRow(loading_, simulation.loadCells());
  driver.add(std::make_unique<SampledStream<LoadCellReading>>(
      simulation.scene().instruments.loading_curve_rate, Sampling::Interpolated,
      [](const Simulation& s) { return s.loadCells(); },
      [this](const LoadCellReading& reading) { writeLoadingRow(loading_, reading); }));
  driver.add(stressesStream(stresses_, [this, ended](const Simulation& s, const SlipEvent& event) {
    writeEventRow(events_, event, s.scene());
    writeEventNodeRows(event_nodes_, event, s.model().interfacePositions());
    if (ended) ended(s, event);
  }));
}

bool ResultsFolder::finish(const Simulation& simulation, double wall_time, double startup_time, std::ostream& console) {
  std::ofstream scene_yaml, summary_txt;
  openAnew(scene_yaml, directory_ + "/scene.yaml");
  openAnew(summary_txt, directory_ + "/summary.txt");
  scene_yaml << sceneToYaml(simulation.scene());
  const RunSummary summary = summarize(simulation, wall_time, startup_time);
  printSummary(summary_txt, summary);
  printSummary(console, summary);
  for (std::ofstream* file : {&events_, &event_nodes_, &loading_, &stresses_, &scene_yaml, &summary_txt}) {
    if (!file->flush()) return false;
  }
  return true;
}

}  // namespace friction
