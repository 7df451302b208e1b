// friction_run: runs a scene offline (no ROS master) to its stop condition and writes the results.
// `friction_run --help` lists its arguments and the files it writes (help() below).
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>

#include "friction_sim/instruments/results_io.h"
#include "friction_sim/run/run_driver.h"
#include "friction_sim/scene/scene_io.h"

namespace {

constexpr const char* kUsage =
    "usage: friction_run SCENE.yaml [--out DIR] [--set key=value]... [--commands COMMANDS.csv | --protocol "
    "PROTOCOL.yaml]";

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
  std::cout << kUsage
            << "\n\n"
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

struct Arguments {
  std::string scene_path, out_dir, commands_path, protocol_path;
  std::vector<std::pair<std::string, std::string>> overrides;
};

/// Reads the command line into `args`; returns an exit status if the run must not go on.
std::optional<int> parseArguments(int argc, char** argv, Arguments& args) {
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--help" || std::string(argv[i]) == "-h") return help();
  }
  if (argc < 2) return refuseCommandLine("no scene file given");
  if (argv[1][0] == '-') return refuseCommandLine(std::string("the scene file comes first, got '") + argv[1] + "'");
  args.scene_path = argv[1];
  const std::map<std::string, std::string*> paths = {
      {"--out", &args.out_dir}, {"--commands", &args.commands_path}, {"--protocol", &args.protocol_path}};
  for (int i = 2; i < argc; ++i) {
    const std::string arg = argv[i];
    if ((paths.count(arg) > 0 || arg == "--set") && i + 1 == argc) return refuseCommandLine(arg + " needs a value");
    if (paths.count(arg) > 0) {
      *paths.at(arg) = argv[++i];
    } else if (arg == "--set") {
      const std::string assignment = argv[++i];
      const auto equals = assignment.find('=');
      if (equals == std::string::npos || equals == 0 || equals + 1 == assignment.size()) {
        return refuseCommandLine("--set needs key=value, got '" + assignment + "'");
      }
      args.overrides.emplace_back(assignment.substr(0, equals), assignment.substr(equals + 1));
    } else {
      return refuseCommandLine("unknown argument '" + arg + "'");
    }
  }
  if (!args.commands_path.empty() && !args.protocol_path.empty()) {
    return refuseCommandLine("--commands and --protocol both drive the stage; give one");
  }
  return std::nullopt;
}

/// The commands of --commands or --protocol, every one checked against the run before it starts.
std::vector<friction::TimedCommand> loadCommands(const Arguments& args, const friction::LoadingProtocol& protocol,
                                                 const friction::Simulation& simulation) {
  auto check = [&simulation](const friction::TimedCommand& command) { return simulation.checkCommand(command); };
  if (!args.protocol_path.empty()) {
    friction::checkProtocolSteps(protocol, args.protocol_path, check);
    return friction::protocolCommands(protocol, simulation.scene().load.normal_force);
  }
  if (args.commands_path.empty()) return {};
  auto commands = friction::loadCommandTable(args.commands_path, check);
  if (commands.empty()) {
    std::cerr << "warning: " << args.commands_path << " holds no commands: the scene's stage program drives the run\n";
  }
  return commands;
}

/// The loading curve into `loading`, and the stresses at each event's onset and end into `stresses_csv`
/// (its header written), each event printed as it ends.
void addStreams(friction::RunDriver& driver, std::vector<friction::LoadCellReading>& loading,
                std::ofstream& stresses_csv) {
  driver.add(std::make_unique<friction::SampledStream<friction::LoadCellReading>>(
      driver.simulation().scene().instruments.loading_curve_rate, friction::Sampling::Interpolated,
      [](const friction::Simulation& s) { return s.loadCells(); },
      [&loading](const friction::LoadCellReading& reading) { loading.push_back(reading); }));
  friction::writeStressesHeader(stresses_csv);
  driver.add(std::make_unique<friction::EventStream>(
      [&](const friction::Simulation& s) {
        // The loaded state that gave way: the nodes that unstuck in the onset step at their thresholds.
        const int event = static_cast<int>(s.events().size());
        friction::writeStressRows(stresses_csv, event, "onset", s.interfaceFrameBeforeUnsticking(), s.gaugeProfile());
      },
      [&](const friction::Simulation& s, const friction::SlipEvent& event) {
        friction::writeStressRows(stresses_csv, event.index, "end", s.interfaceFrame(), s.gaugeProfile());
        std::cout << "event " << event.index << " at t = " << event.onset_time
                  << " s: F_X/F_Z = " << event.onset_shear_force / event.onset_normal_force
                  << ", L_p/L = " << event.rupture_length / s.scene().geometry.length
                  << (event.global ? " (global)" : "") << std::endl;
      }));
}

/// The result files in `out_dir`, the summary also printed; false if one could not be written in full.
bool writeResults(const std::string& out_dir, const friction::Simulation& simulation,
                  const std::vector<friction::LoadCellReading>& loading, double wall, std::ofstream& stresses_csv) {
  std::ofstream events_csv(out_dir + "/events.csv"), nodes_csv(out_dir + "/event_nodes.csv"),
      loading_csv(out_dir + "/loading.csv"), scene_yaml(out_dir + "/scene.yaml"), summary_txt(out_dir + "/summary.txt");
  friction::writeEventsCsv(events_csv, simulation.events(), simulation.scene());
  friction::writeEventNodesCsv(nodes_csv, simulation.events(), simulation.model().interfacePositions());
  friction::writeLoadingCsv(loading_csv, loading);
  scene_yaml << friction::sceneToYaml(simulation.scene());
  const friction::RunSummary summary = friction::summarize(simulation, wall);
  friction::printSummary(summary_txt, summary);
  friction::printSummary(std::cout, summary);
  for (std::ofstream* file : {&stresses_csv, &events_csv, &nodes_csv, &loading_csv, &scene_yaml, &summary_txt}) {
    if (!file->flush()) return false;
  }
  return true;
}

int run(int argc, char** argv) {
  Arguments args;
  if (const auto status = parseArguments(argc, argv, args)) return *status;
  double stability_limit = 0.0;
  friction::Scene scene = friction::loadScene(args.scene_path, args.overrides, &stability_limit);
  for (const std::string& warning : friction::sceneWarnings(scene)) std::cerr << "warning: " << warning << "\n";
  friction::LoadingProtocol protocol;
  if (!args.protocol_path.empty()) {
    protocol = friction::loadProtocol(args.protocol_path);
    scene.stop = {protocol.end.global_events, protocol.end.time, protocol.end.stage_travel};
  }
  const auto start = std::chrono::steady_clock::now();
  friction::RunOptions options;
  // A recorded time is its step's rounded to whole nanoseconds: due within half of one. A protocol's
  // times are the ones the rig compared its clock with: due exactly then.
  options.command_early = args.commands_path.empty() ? 0.0 : 0.5e-9;
  friction::RunDriver driver(scene, stability_limit, options);
  const friction::Simulation& simulation = driver.simulation();
  const std::vector<friction::TimedCommand> commands = loadCommands(args, protocol, simulation);
  const std::string out_dir = args.out_dir.empty() ? "results/" + scene.name : args.out_dir;
  std::error_code directory_error;
  std::filesystem::create_directories(out_dir, directory_error);
  if (directory_error) return refuseOutput(out_dir, "cannot create the directory (" + directory_error.message() + ")");
  std::ofstream stresses_csv(out_dir + "/stresses.csv");
  if (!stresses_csv) return refuseOutput(out_dir, "cannot create files in it");
  for (const friction::TimedCommand& command : commands) driver.schedule(command);
  int applied_commands = 0;
  driver.onCommandDue([&](const friction::TimedCommand& command, const std::string& refusal) {
    if (refusal.empty()) {
      ++applied_commands;
    } else {
      std::cerr << "warning: command at t = " << command.time << " s refused: " << refusal << "\n";
    }
  });
  std::vector<friction::LoadCellReading> loading{simulation.loadCells()};
  addStreams(driver, loading, stresses_csv);
  driver.run();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::string& commands_source = args.commands_path.empty() ? args.protocol_path : args.commands_path;
  if (!commands_source.empty()) {
    std::cout << "commands: " << applied_commands << " of " << commands.size() << " applied (" << commands_source
              << ")\n";
  }
  if (scene.integrator.fast_forward) {
    std::cout << "fast-forward: " << simulation.jumps() << " jumps covering " << simulation.jumpedTime() << " s of "
              << simulation.time() << " s\n";
  }
  if (!writeResults(out_dir, simulation, loading, wall, stresses_csv)) {
    return refuseOutput(out_dir, "a result file could not be written in full");
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
