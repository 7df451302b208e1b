// friction_run: runs a scene offline (no ROS master) to its stop condition and writes the results.
// `friction_run --help` lists its arguments and the files it writes (help() below).
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <optional>
#include <stdexcept>

#include "friction_sim/instruments/results_io.h"
#include "friction_sim/model/lattice_2d.h"
#include "friction_sim/run/run_driver.h"
#include "friction_sim/scene/scene_io.h"
#include "process_memory.h"

namespace {

constexpr const char* kUsage =
    "usage: friction_run SCENE.yaml [--out DIR] [--set key=value...]... [--commands COMMANDS.csv | --protocol "
    "PROTOCOL.yaml] [--threads N]";

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
            << "\n\nRuns a scene offline to its stop condition and writes events.csv, event_nodes.csv, loading.csv,\n"
               "stresses.csv, scene.yaml and summary.txt in DIR (default results/<scene name>).\n"
               "  --set key=value...  overrides scene fields (SI units), validated like the file\n"
               "  --commands FILE  drives the stage and F_Z by a command table (rig_report's stage_commands.csv)\n"
               "  --protocol FILE  runs a stage controller's loading protocol from t = 0; its end ends the run\n"
               "  --threads N  threads for the 2D lattice's force sweeps, used from "
            << friction::Lattice2D::kThreadedNodes
            << " nodes (default 1);\n"
               "               the same results for any N\n"
               "Exit status: 0 the run ended, 2 a bad command line, 3 a refused scene, command table or protocol,\n"
               "4 DIR cannot be written. On a terminal, a progress line on standard error.\n"
               "Reference: docs/offline_runner.md\n";
  return 0;
}

struct Arguments {
  std::string scene_path, out_dir, commands_path, protocol_path, threads_text = "1";
  int threads = 1;
  std::vector<std::pair<std::string, std::string>> overrides;
};

/// The thread count `text` (--threads) gives, if it is a whole number from 1.
std::optional<int> threadCount(const std::string& text) {
  std::size_t end = 0;
  try {
    const int threads = std::stoi(text, &end);
    if (end == text.size() && threads >= 1) return threads;
  } catch (const std::logic_error&) {
  }
  return std::nullopt;
}

/// Reads the command line into `args`; returns an exit status if the run must not go on.
std::optional<int> parseArguments(int argc, char** argv, Arguments& args) {
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--help" || std::string(argv[i]) == "-h") return help();
  }
  if (argc < 2) return refuseCommandLine("no scene file given");
  if (argv[1][0] == '-') return refuseCommandLine(std::string("the scene file comes first, got '") + argv[1] + "'");
  args.scene_path = argv[1];
  const std::map<std::string, std::string*> paths = {{"--out", &args.out_dir},
                                                     {"--commands", &args.commands_path},
                                                     {"--protocol", &args.protocol_path},
                                                     {"--threads", &args.threads_text}};
  for (int i = 2; i < argc; ++i) {
    const std::string arg = argv[i];
    if ((paths.count(arg) > 0 || arg == "--set") && i + 1 == argc) return refuseCommandLine(arg + " needs a value");
    if (paths.count(arg) > 0) {
      *paths.at(arg) = argv[++i];
    } else if (arg == "--set") {
      // Every argument up to the next option is an assignment.
      do {
        const std::string assignment = argv[++i];
        const auto equals = assignment.find('=');
        if (equals == std::string::npos || equals == 0 || equals + 1 == assignment.size()) {
          return refuseCommandLine("--set needs key=value, got '" + assignment + "'");
        }
        args.overrides.emplace_back(assignment.substr(0, equals), assignment.substr(equals + 1));
      } while (i + 1 < argc && argv[i + 1][0] != '-');
    } else {
      return refuseCommandLine("unknown argument '" + arg + "'");
    }
  }
  if (!args.commands_path.empty() && !args.protocol_path.empty()) {
    return refuseCommandLine("--commands and --protocol both drive the stage; give one");
  }
  const std::optional<int> threads = threadCount(args.threads_text);
  if (!threads) return refuseCommandLine("--threads " + args.threads_text + ": allowed: a whole number from 1");
  args.threads = *threads;
  return std::nullopt;
}

/// Schedules the commands of --commands or --protocol, every one checked before the run; returns how many.
std::size_t scheduleCommands(const Arguments& args, const friction::LoadingProtocol& protocol,
                             friction::RunDriver& driver) {
  if (!args.protocol_path.empty()) return driver.scheduleProtocol(protocol, args.protocol_path);
  if (args.commands_path.empty()) return 0;
  const std::size_t scheduled = driver.scheduleCommandTable(args.commands_path);
  if (scheduled == 0) {
    std::cerr << "warning: " << args.commands_path << " holds no commands: the scene's stage program drives the run\n";
  }
  return scheduled;
}

/// On a terminal, a line on standard error that the run rewrites twice a second: simulated time against
/// the stop time, steps and jumps per second of wall time, events so far, and the wall time left were
/// the run to go on at its mean pace to its time limit (it ends sooner if its events stop it).
class ProgressLine : public friction::RunStream {
 public:
  using Clock = std::chrono::steady_clock;
  void after(const friction::Simulation& simulation, bool /*jumped*/) override {
    // Cleared before an event's line goes to standard output (this stream comes before that one).
    if (simulation.eventEndedLastStep()) clear();
    const Clock::time_point now = Clock::now();
    if (now - last_ < std::chrono::milliseconds(500)) return;
    last_ = now;
    const double wall = std::chrono::duration<double>(now - start_).count();
    const double time = simulation.time(), limit = simulation.scene().stop.time;
    std::fprintf(stderr, "\r\033[Kt = %.4g s of %.4g s, %.0f steps/s, %.0f jumps/s, %d events", time, limit,
                 simulation.steps() / wall, simulation.jumps() / wall, simulation.eventTally().events);
    if (std::isfinite(limit) && time > 0.0) std::fprintf(stderr, ", at most %.0f s left", (limit - time) * wall / time);
    std::fflush(stderr);
    shown_ = true;
  }
  /// Erases the line, if shown.
  void clear() {
    if (shown_) std::fputs("\r\033[K", stderr);
    shown_ = false;
  }

 private:
  Clock::time_point start_ = Clock::now(), last_ = start_;
  bool shown_ = false;
};

/// Each event's line on standard output as it ends.
void printEvent(const friction::Simulation& s, const friction::SlipEvent& event) {
  std::cout << "event " << event.index << " at t = " << event.onset_time
            << " s: F_X/F_Z = " << event.onset_shear_force / event.onset_normal_force
            << ", L_p/L = " << event.rupture_length / s.scene().geometry.length << (event.global ? " (global)" : "")
            << std::endl;
}

int run(int argc, char** argv) {
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  Arguments args;
  if (const auto status = parseArguments(argc, argv, args)) return *status;
  double stability_limit = 0.0;
  friction::Scene scene = friction::loadScene(args.scene_path, args.overrides, &stability_limit);
  for (const std::string& warning : friction::sceneWarnings(scene)) std::cerr << "warning: " << warning << "\n";
  friction::LoadingProtocol protocol;
  if (!args.protocol_path.empty()) {
    protocol = friction::loadProtocol(args.protocol_path);
    scene.stop = protocol.end.stopFrom(0.0);
  }
  friction::RunOptions options;
  // A recorded time is its step's rounded to whole nanoseconds: due within half of one. A protocol's
  // times are the ones the rig compared its clock with: due exactly then.
  options.command_early = args.commands_path.empty() ? 0.0 : 0.5e-9;
  options.threads = args.threads;
  friction::RunDriver driver(scene, stability_limit, options);
  const friction::Simulation& simulation = driver.simulation();
  const std::size_t scheduled_commands = scheduleCommands(args, protocol, driver);
  const std::string out_dir = args.out_dir.empty() ? "results/" + scene.name : args.out_dir;
  std::optional<friction::ResultsFolder> results;
  try {
    results.emplace(out_dir);
  } catch (const std::runtime_error& error) {
    return refuseOutput(out_dir, error.what());
  }
  int applied_commands = 0;
  driver.onCommandDue([&](const friction::TimedCommand& command, const std::string& refusal) {
    if (refusal.empty()) {
      ++applied_commands;
    } else {
      std::cerr << "warning: command at t = " << command.time << " s refused: " << refusal << "\n";
    }
  });
  ProgressLine* progress = isatty(fileno(stderr)) ? &driver.add(std::make_unique<ProgressLine>()) : nullptr;
  results->addStreams(driver, printEvent);
  const Clock::time_point first_step = Clock::now();
  driver.run();
  if (progress) progress->clear();
  driver.finishRun();
  const double wall = std::chrono::duration<double>(Clock::now() - start).count();
  const double startup = std::chrono::duration<double>(first_step - start).count();
  const std::string& commands_source = args.commands_path.empty() ? args.protocol_path : args.commands_path;
  if (!commands_source.empty()) {
    std::cout << "commands: " << applied_commands << " of " << scheduled_commands << " applied (" << commands_source
              << ")\n";
  }
  if (scene.integrator.fast_forward) {
    std::cout << "fast-forward: " << simulation.jumps() << " jumps covering " << simulation.jumpedTime() << " s of "
              << simulation.time() << " s, brought to equilibrium by " << simulation.jumpCorrections()
              << " corrections\n";
  }
  if (!results->finish(simulation, wall, startup, std::cout)) {
    return refuseOutput(out_dir, "a result file could not be written in full");
  }
  std::cout << "results written to " << out_dir << "/\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  friction::reuseFreedMemoryOnHugePages();
  try {
    return run(argc, argv);
  } catch (const friction::ConfigError& error) {
    std::cerr << error.what() << "\n";
    return kSceneRefused;
  }
}
