// friction_run: runs a scene offline (no ROS master) to its stop condition and writes the results.
// `friction_run --help` lists its arguments and the files it writes (help() below).
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "friction_sim/command_schedule.h"
#include "friction_sim/results_io.h"
#include "friction_sim/scene_io.h"
#include "friction_sim/simulation.h"

namespace {

constexpr const char* kUsage =
    "usage: friction_run SCENE.yaml [--out DIR] [--set key=value]... [--commands COMMANDS.csv | --protocol PROTOCOL.yaml]";

/// Exit statuses: a command line that cannot be read, a scene, command table or protocol refused (ConfigError),
/// and an output directory that cannot be written.
constexpr int kBadCommandLine = 2;
constexpr int kSceneRefused = 3;
constexpr int kOutputUnwritable = 4;

int refuseOutput(const std::string& out_dir, const std::string& reason) {
  std::cerr << "friction_run: --out " << out_dir << ": " << reason << "\n";
  return kOutputUnwritable;
}

int refuseCommandLine(const std::string& problem) {
  std::cerr << "friction_run: " << problem << "\n" << kUsage << "  (--help for more)\n";
  return kBadCommandLine;
}

int help() {
  std::cout << kUsage << "\n\n"
               "Runs a scene offline to its stop condition and writes, in DIR (default results/<scene name>):\n"
               "  events.csv       one row per slip event (onset, F_X, F_Z, extent, L_p, front speeds)\n"
               "  event_nodes.csv  per event and interface node: slip, first-unstick time, front speed\n"
               "  loading.csv      the load cells at instruments.loading_curve_rate\n"
               "  stresses.csv     per event, at onset and end: strain gauges and interface stresses\n"
               "  scene.yaml       the scene as run;  summary.txt  the summary, also printed\n\n"
               "  --set key=value  overrides one scene field, e.g. --set pusher.height=0.01 (SI units);\n"
               "                   validated like the file: a bad scene is refused with every problem listed.\n"
               "  --commands FILE  drives the stage and F_Z by the commands of FILE, each applied at the first\n"
               "                   step (or jump end) at or after its time (within the half nanosecond its\n"
               "                   recorded time was rounded by), as the rig applies a controller's:\n"
               "                   rig_report writes a recorded run's as stage_commands.csv, with its scene.yaml,\n"
               "                   so that `friction_run scene.yaml --commands stage_commands.csv` reruns it.\n"
               "                   Every command is checked against the scene before the run.\n"
               "  --protocol FILE  runs a loading protocol (the stage controller's YAML) as the controller\n"
               "                   does from t = 0: its commands at their times (in whole nanoseconds, as\n"
               "                   they travel), and its end in place of the scene's stop condition.\n\n"
               "Exit status: 0 when the run ends, 2 for a command line it cannot read, 3 for a refused scene,\n"
               "command table or protocol, 4 when DIR cannot be written (checked before the run, and again for\n"
               "the files written after it).\n";
  return 0;
}

/// Refuses `protocol` (from `path`) with every problem listed, before anything runs, if the run would
/// refuse what one of its steps acts with (stepCommand).
void checkProtocol(const friction::LoadingProtocol& protocol, const std::string& path,
                   const friction::CommandCheck& check) {
  std::vector<std::string> problems;
  for (std::size_t i = 0; i < protocol.steps.size(); ++i) {
    const std::string refusal = check(friction::stepCommand(protocol.steps[i]));
    if (!refusal.empty()) problems.push_back(path + ", steps[" + std::to_string(i) + "]: " + refusal);
  }
  if (!problems.empty()) throw friction::ConfigError("protocol", problems);
}

int run(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--help" || std::string(argv[i]) == "-h") return help();
  }
  if (argc < 2) return refuseCommandLine("no scene file given");
  if (argv[1][0] == '-') return refuseCommandLine(std::string("the scene file comes first, got '") + argv[1] + "'");
  std::string scene_path = argv[1], out_dir, commands_path, protocol_path;
  std::vector<std::pair<std::string, std::string>> overrides;
  for (int i = 2; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--out" && i + 1 < argc) {
      out_dir = argv[++i];
    } else if (arg == "--commands" && i + 1 < argc) {
      commands_path = argv[++i];
    } else if (arg == "--protocol" && i + 1 < argc) {
      protocol_path = argv[++i];
    } else if (arg == "--set" && i + 1 < argc) {
      const std::string assignment = argv[++i];
      const auto equals = assignment.find('=');
      if (equals == std::string::npos || equals == 0 || equals + 1 == assignment.size()) {
        return refuseCommandLine("--set needs key=value, got '" + assignment + "'");
      }
      overrides.emplace_back(assignment.substr(0, equals), assignment.substr(equals + 1));
    } else if (arg == "--out" || arg == "--set" || arg == "--commands" || arg == "--protocol") {
      return refuseCommandLine(arg + " needs a value");
    } else {
      return refuseCommandLine("unknown argument '" + arg + "'");
    }
  }
  if (!commands_path.empty() && !protocol_path.empty()) {
    return refuseCommandLine("--commands and --protocol both drive the stage; give one");
  }
  double stability_limit = 0.0;
  friction::Scene scene = friction::loadScene(scene_path, overrides, &stability_limit);
  for (const std::string& warning : friction::sceneWarnings(scene)) std::cerr << "warning: " << warning << "\n";
  std::vector<friction::TimedCommand> commands;
  const std::string commands_source = commands_path.empty() ? protocol_path : commands_path;
  friction::LoadingProtocol protocol;
  if (!protocol_path.empty()) {
    // As the stage controller runs it from t = 0: its schedule, each command at the time its stamp
    // carries, and its end as the run's (set_run_end).
    protocol = friction::loadProtocol(protocol_path);
    commands = friction::scheduleProtocol(protocol, 0.0, scene.load.normal_force);
    for (friction::TimedCommand& command : commands) command.time = friction::stampSeconds(command.time);
    scene.stop = {protocol.end.global_events, protocol.end.time, protocol.end.stage_travel};
  }
  const auto start = std::chrono::steady_clock::now();
  friction::Simulation simulation(scene, stability_limit);
  auto check = [&simulation](const friction::TimedCommand& command) { return simulation.checkCommand(command); };
  if (!commands_path.empty()) {
    commands = friction::loadCommandTable(commands_path, check);
    if (commands.empty()) {
      std::cerr << "warning: " << commands_path << " holds no commands: the scene's stage program drives the run\n";
    }
  } else if (!protocol_path.empty()) {
    checkProtocol(protocol, protocol_path, check);
  }
  if (out_dir.empty()) out_dir = "results/" + scene.name;
  std::error_code directory_error;
  std::filesystem::create_directories(out_dir, directory_error);
  if (directory_error) return refuseOutput(out_dir, "cannot create the directory (" + directory_error.message() + ")");
  std::ofstream stresses_csv(out_dir + "/stresses.csv");
  if (!stresses_csv) return refuseOutput(out_dir, "cannot create files in it");
  // A recorded time is its step's rounded to whole nanoseconds: due within half of one. A protocol's
  // times are the ones the rig compared its clock with: due exactly then.
  friction::CommandSchedule schedule(commands_path.empty() ? 0.0 : 0.5e-9);
  for (const friction::TimedCommand& command : commands) schedule.add(command);
  int applied_commands = 0;
  std::vector<friction::LoadCellReading> loading{simulation.loadCells()};
  stresses_csv << "event,phase,time_s,x_m,gauge_sigma_xx_Pa,gauge_sigma_zz_Pa,gauge_tau_xz_Pa,"
                  "interface_normal_stress_Pa,interface_shear_stress_Pa\n";
  stresses_csv.precision(10);
  // The stress state at an event's onset (the loaded state that gave way: the nodes that unstuck in the
  // onset step at their thresholds) and at its end.
  auto record_stresses = [&](int event, const char* phase, const friction::InterfaceFrame& frame) {
    const friction::GaugeProfile gauges = simulation.gaugeProfile();
    for (std::size_t i = 0; i < frame.position.size(); ++i) {
      const bool gauge = i < gauges.stress.sigma_zz.size() && gauges.position[i] == frame.position[i];
      stresses_csv << event << ',' << phase << ',' << simulation.time() << ',' << frame.position[i] << ','
                   << (gauge ? gauges.stress.sigma_xx[i] : NAN) << ',' << (gauge ? gauges.stress.sigma_zz[i] : NAN)
                   << ',' << (gauge ? gauges.stress.tau_xz[i] : NAN) << ',' << frame.normal_stress[i] << ','
                   << frame.shear_stress[i] << '\n';
    }
  };
  const double sample_interval = 1.0 / scene.instruments.loading_curve_rate;
  double next_sample = sample_interval;
  friction::LoadCellReading before = loading.front();
  while (!simulation.finished()) {
    // The rig's rule (CommandSchedule): the commands due by now, then a step or a jump that ends where
    // the next is due.
    schedule.applyDue(simulation, [&](const friction::TimedCommand& command, const std::string& refusal) {
      if (refusal.empty()) {
        ++applied_commands;
        // The load cells from the command on (F_Z steps, the slider relaxes): samples across the next
        // step or jump are drawn from here, as the rig draws them.
        before = simulation.loadCells();
      } else {
        std::cerr << "warning: command at t = " << command.time << " s refused: " << refusal << "\n";
      }
    });
    const double until = schedule.nextTime();
    // Several plain steps at once where they all end before the next loading-curve sample (and command):
    // the samples stay those of single steps.
    simulation.advance(until, std::min(next_sample, until));
    const friction::LoadCellReading after = simulation.loadCells();
    for (; next_sample <= after.time; next_sample += sample_interval) {
      loading.push_back(friction::interpolate(before, after, next_sample));
    }
    if (simulation.eventStartedLastStep()) {
      record_stresses(static_cast<int>(simulation.events().size()), "onset", simulation.interfaceFrameBeforeUnsticking());
    }
    if (simulation.eventEndedLastStep()) {
      const friction::SlipEvent& event = simulation.events().back();
      record_stresses(event.index, "end", simulation.interfaceFrame());
      std::cout << "event " << event.index << " at t = " << event.onset_time << " s: F_X/F_Z = "
                << event.onset_shear_force / event.onset_normal_force
                << ", L_p/L = " << event.rupture_length / scene.geometry.length
                << (event.global ? " (global)" : "") << std::endl;
    }
    before = after;
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!commands_source.empty()) {
    std::cout << "commands: " << applied_commands << " of " << commands.size() << " applied (" << commands_source
              << ")\n";
  }
  if (scene.integrator.fast_forward) {
    std::cout << "fast-forward: " << simulation.jumps() << " jumps covering " << simulation.jumpedTime()
              << " s of " << simulation.time() << " s\n";
  }

  std::vector<double> positions;
  for (int node = 0; node < simulation.model().interfaceNodeCount(); ++node) {
    positions.push_back(simulation.model().interfacePosition(node));
  }
  std::ofstream events_csv(out_dir + "/events.csv"), nodes_csv(out_dir + "/event_nodes.csv"),
      loading_csv(out_dir + "/loading.csv"), scene_yaml(out_dir + "/scene.yaml"),
      summary_txt(out_dir + "/summary.txt");
  friction::writeEventsCsv(events_csv, simulation.events(), scene);
  friction::writeEventNodesCsv(nodes_csv, simulation.events(), positions);
  friction::writeLoadingCsv(loading_csv, loading);
  scene_yaml << friction::sceneToYaml(scene);
  const friction::RunSummary summary = friction::summarize(simulation, wall);
  friction::printSummary(summary_txt, summary);
  friction::printSummary(std::cout, summary);
  for (std::ofstream* file : {&stresses_csv, &events_csv, &nodes_csv, &loading_csv, &scene_yaml, &summary_txt}) {
    if (!file->flush()) return refuseOutput(out_dir, "a result file could not be written in full");
  }
  std::cout << "results written to " << out_dir << "/\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const friction::ConfigError& error) {
    std::cerr << error.what() << "\n";
    return kSceneRefused;
  }
}
