// Pinned determinism: every shipped scene, run to its stop condition, ends in the state whose hash is
// pinned here and with the events pinned in test/pinned/<scene>.events.csv, on any machine and build.
// A change that alters results must update both deliberately, and its commit says why: run the test
// with FRICTION_UPDATE_PINS=1 to rewrite the events files, and copy the hashes it prints.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "friction_sim/instruments/results_io.h"
#include "friction_sim/run/run_driver.h"
#include "test_helpers.h"

namespace friction::testing {
namespace {

struct Pin {
  const char* scene;
  std::uint64_t state_hash;  ///< Simulation::stateHash() at the end of the run
};

constexpr Pin kPins[] = {
    {"single_block", 0x33ff500570b44db8ULL}, {"pmma_1d_side", 0xefe502c3334be423ULL},
    {"pmma_1d_top", 0x40584551a61e4f73ULL},  {"pmma_2d", 0x1259b0dd968c1da4ULL},
    {"rate_state", 0x3c10ba457087f355ULL},
};

void PrintTo(const Pin& pin, std::ostream* out) { *out << pin.scene; }

std::string pinnedEventsPath(const std::string& scene) { return std::string(PINNED_DIR) + "/" + scene + ".events.csv"; }

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

class PinnedScene : public ::testing::TestWithParam<Pin> {};

TEST_P(PinnedScene, EndsInThePinnedStateWithThePinnedEvents) {
  const Pin pin = GetParam();
  double stability_limit = 0.0;
  const Scene scene = loadScene(scenePath(pin.scene), {}, &stability_limit);
  RunDriver driver(scene, stability_limit);
  driver.run();
  const Simulation& simulation = driver.simulation();
  std::ostringstream events;
  writeEventsCsv(events, simulation.events(), scene);
  if (std::getenv("FRICTION_UPDATE_PINS") != nullptr) {
    std::ofstream(pinnedEventsPath(pin.scene)) << events.str();
  }
  EXPECT_GT(simulation.events().size(), 0U);
  EXPECT_EQ(events.str(), readFile(pinnedEventsPath(pin.scene)));
  EXPECT_EQ(simulation.stateHash(), pin.state_hash)
      << pin.scene << ": state hash 0x" << std::hex << simulation.stateHash() << " after " << std::dec
      << simulation.steps() << " steps and " << simulation.jumps() << " jumps to t = " << simulation.time() << " s";
}

INSTANTIATE_TEST_SUITE_P(ShippedScenes, PinnedScene, ::testing::ValuesIn(kPins),
                         [](const ::testing::TestParamInfo<Pin>& info) { return std::string(info.param.scene); });

}  // namespace
}  // namespace friction::testing
