// Scene files: the shipped scenes load, every invalid case is refused with a message naming the field,
// the value and what is allowed, and a file with several problems lists them all.
#include <gtest/gtest.h>

#include <cstdlib>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include "friction_sim/run/simulation.h"
#include "friction_sim/scene/scene_io.h"
#include "friction_sim/solvers/integrator.h"
#include "test_helpers.h"

namespace friction {
namespace {

using testing::scenePath;

/// The problems and notes of the scene's refusal; none if it is accepted.
SceneReview refusalOf(const std::string& yaml) {
  try {
    parseScene(yaml);
  } catch (const SceneError& error) {
    return {error.problems(), error.notes()};
  }
  return {};
}

std::vector<std::string> problemsOf(const std::string& yaml) { return refusalOf(yaml).problems; }

bool mentions(const std::vector<std::string>& problems, const std::string& text) {
  return std::any_of(problems.begin(), problems.end(),
                     [&](const std::string& p) { return p.find(text) != std::string::npos; });
}

TEST(SceneFiles, ShippedScenesLoadWithTheirNumbers) {
  const Scene pmma = loadScene(scenePath("pmma_2d"));
  EXPECT_EQ(pmma.model, ModelKind::Lattice2D);
  EXPECT_EQ(pmma.lattice.nodes_x, 57);
  EXPECT_EQ(pmma.lattice.nodes_z, 31);
  EXPECT_DOUBLE_EQ(pmma.load.normal_force, 1920.0);
  EXPECT_DOUBLE_EQ(pmma.pusher.stiffness, 4e6);
  EXPECT_DOUBLE_EQ(pmma.pusher.height, 0.005);
  EXPECT_DOUBLE_EQ(pmma.stage.program.front().speed, 4e-4);
  EXPECT_EQ(loadScene(scenePath("pmma_1d_side")).chain.driving, ChainDriving::Side);
  EXPECT_EQ(loadScene(scenePath("pmma_1d_top")).chain.driving, ChainDriving::Top);
  EXPECT_EQ(loadScene(scenePath("single_block")).chain.blocks, 1);
  for (const char* name : {"rate_state", "pmma_2d_rate_state"}) {
    const FrictionSpec friction = loadScene(scenePath(name)).friction;
    EXPECT_EQ(friction.law, FrictionLawKind::RateState);
    EXPECT_DOUBLE_EQ(friction.rate_state.characteristic_slip, 0.5e-6);
    EXPECT_DOUBLE_EQ(friction.rate_state.initial_age, 100.0);
    // µ(0, 100 s) = f0·(1 + b·ln(1 + 100 s/φ*))
    EXPECT_NEAR(friction.initialStaticCoefficient(), 0.285 * (1.0 + 0.075 * std::log1p(100.0 / 0.33e-3)), 1e-15);
  }
}

TEST(SceneFiles, RateStateParametersAreRefusedOutsideTheirRangesAndWithRungeKutta) {
  const auto problems = problemsOf(
      "friction: {law: rate_state, characteristic_slip: 0, reference_speed: -1, initial_age: .inf, direct_effect: "
      "-0.1}\nintegrator: {scheme: rk4, time_step: 1.0e-7}");
  EXPECT_TRUE(mentions(problems, "friction.characteristic_slip: value 0 is not allowed"));
  EXPECT_TRUE(mentions(problems, "friction.reference_speed: value -1"));
  EXPECT_TRUE(mentions(problems, "friction.initial_age"));
  EXPECT_TRUE(mentions(problems, "friction.direct_effect"));
  EXPECT_TRUE(mentions(problems, "integrator.scheme: rk4 is not allowed with friction.law rate_state"));
}

TEST(SceneFiles, WrittenSceneReadsBackIdentically) {
  Scene scene = loadScene(scenePath("pmma_2d"));
  const std::string text = sceneToYaml(scene);
  EXPECT_EQ(sceneToYaml(parseScene(text)), text);
  // Also with a run end set_run_end gave (the rig records its scene so): no time limit.
  scene.stop = StopSpec{4, std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  const Scene read_back = parseScene(sceneToYaml(scene));
  EXPECT_EQ(read_back.stop.global_events, 4);
  EXPECT_TRUE(std::isinf(read_back.stop.time));
  EXPECT_TRUE(std::isinf(read_back.stop.stage_travel));
  // Every number to its last bit: an override with more digits than the ten written before, and a time
  // that is a sum of durations.
  scene.pusher.height = 0.0123456789012345;
  scene.stop.time = 0.001 + 0.019 + 0.1;
  const Scene exact = parseScene(sceneToYaml(scene));
  EXPECT_EQ(exact.pusher.height, scene.pusher.height);
  EXPECT_EQ(exact.stop.time, scene.stop.time);
  // A NaN in a field the lattice's checks leave alone (the chain's tilt) is written as YAML reads it.
  scene.chain.tilt = std::nan("");
  EXPECT_TRUE(std::isnan(parseScene(sceneToYaml(scene)).chain.tilt));
  EXPECT_EQ(exact.material.youngs_modulus, 3.0e9);
}

TEST(SceneFiles, OverridesAreParsedAndValidatedLikeTheFile) {
  const Scene base = loadScene(scenePath("pmma_2d"));
  const Scene changed = overrideScene(base, {{"pusher.height", "0.01"}, {"friction.kinetic_coefficient", "0.2"}});
  EXPECT_DOUBLE_EQ(changed.pusher.height, 0.01);
  EXPECT_DOUBLE_EQ(changed.friction.kinetic_coefficient, 0.2);
  EXPECT_THROW(overrideScene(base, {{"pusher.hieght", "0.01"}}), SceneError);
  // A list is replaced whole, which the refusal of one element says.
  try {
    overrideScene(base, {{"stage.program[0].speed", "4e-3"}});
    ADD_FAILURE() << "accepted";
  } catch (const SceneError& error) {
    EXPECT_NE(std::string(error.what()).find("give the whole list in YAML, stage.program=[...]"), std::string::npos)
        << error.what();
  }
}

struct InvalidCase {
  const char* yaml;
  const char* field;
  const char* allowed;
};

class InvalidScene : public ::testing::TestWithParam<InvalidCase> {};

TEST_P(InvalidScene, IsRefusedNamingFieldValueAndRange) {
  const auto [problems, notes] = refusalOf(GetParam().yaml);
  ASSERT_EQ(problems.size(), 1u) << (problems.empty() ? "accepted" : problems[1]);
  EXPECT_NE(problems[0].find(GetParam().field), std::string::npos) << problems[0];
  EXPECT_NE(problems[0].find(GetParam().allowed), std::string::npos) << problems[0];
  // A problem of the model's fields also notes that dt is still to be checked.
  ASSERT_LE(notes.size(), 1u);
  if (!notes.empty()) {
    EXPECT_EQ(notes[0].find("integrator.time_step: value 2e-07 not yet checked"), 0u) << notes[0];
  }
}

INSTANTIATE_TEST_SUITE_P(
    EachProblem, InvalidScene,
    ::testing::Values(
        InvalidCase{"friction: {static_coefficient: 0.3, kinetic_coefficient: 0.4}",
                    "friction.kinetic_coefficient: value 0.4", "mu_k <= mu_s"},
        InvalidCase{"pusher: {height: 0.08}", "pusher.height: value 0.08", "[0, 0.075]"},
        InvalidCase{"material: {density: -1200}", "material.density: value -1200", "> 0"},
        InvalidCase{"pusher: {stiffness: 0}", "pusher.stiffness: value 0", "> 0"},
        InvalidCase{"lattice: {nodes_x: 57, nodes_z: 30}", "lattice.nodes_x/lattice.nodes_z: values 57, 30",
                    "square lattice"},
        // Both counts named, with the sizes that fit the geometry: either may be the one to change.
        InvalidCase{"lattice: {nodes_x: 50}", "lattice.nodes_x/lattice.nodes_z: values 50, 31",
                    "sizes that fit 0.14 m x 0.075 m: nodes_x - 1 a multiple of 28, e.g. nodes_x: 57, nodes_z: 31"},
        InvalidCase{"instruments: {gauge_height: 0.1}", "instruments.gauge_height: value 0.1", "inside the slider"},
        InvalidCase{"model: chain_1d\nload: {top: spring_mattress}", "load.top: spring_mattress is not allowed",
                    "uniform (the chain has no top row)"},
        // Between the rows at 5 and 7.5 mm: the lattice's own rule (pushedRowsOf) finds none in it.
        InvalidCase{"pusher: {band_min: 0.0051, band_max: 0.0074}", "pusher.band_max: value 0.0074",
                    "contains at least one lattice row"},
        InvalidCase{"integrator: {time_step: 1.0e-5}", "integrator.time_step: value 1e-05",
                    "stability limit of this scene"},
        InvalidCase{"model: chain_1d\nchain: {tilt: -1.5}", "normal force of block", "w_i > 0"},
        InvalidCase{"model: chain_1d\nchain: {torque_share: 1.0}\npusher: {height: 0.075}", "at F_X = 768 N",
                    "w_i > 0"},
        // Holds while the stage pushes; the trailing-edge-heavy tilt lifts the leading block once it pulls.
        InvalidCase{"model: chain_1d\nchain: {tilt: -0.8, torque_share: 1.0}\npusher: {height: 0.03}",
                    "at F_X = -768 N", "F_X in [-768, 768] N, the stage pushing or pulling"},
        // µ_k = 0.17 is not blamed for a refused µ_s.
        InvalidCase{"friction: {static_coefficient: -0.4}", "friction.static_coefficient: value -0.4",
                    "a finite number >= 0"},
        InvalidCase{"frictoin: {law: amontons_coulomb}", "frictoin: unknown key", "allowed keys here"},
        InvalidCase{"friction: {mu_s: 0.4}", "friction.mu_s: unknown key", "static_coefficient"},
        // The first of two would have won without a word.
        InvalidCase{"geometry:\n  length: 0.14\n  length: 0.2", "geometry.length: given more than once",
                    "give it once"},
        InvalidCase{"friction: {law: coulomb}", "friction.law: value 'coulomb'", "amontons_coulomb | slip_weakening"},
        InvalidCase{"lattice: {nodes_x: many}", "lattice.nodes_x: value 'many'", "integer"},
        InvalidCase{"stage: {program: [{mode: velocity, speed: 5.0}]}", "stage.program[0].speed: value 5",
                    "stage.max_speed"},
        InvalidCase{"model: chain_1d\nchain: {blocks: 3, initial_shear: [1.0, 2.0]}",
                    "chain.initial_shear (length): value 2", "one force per block"},
        InvalidCase{"model: chain_1d\nchain: {blocks: 3, initial_shear: [3.0, 2.0, 1.0]}\n"
                    "friction: {interfacial_stiffness: 1.0e8}",
                    "friction.interfacial_stiffness: value 100000000", "0 (rigid sticking) with a chain.initial_shear"},
        // A segment without an end before another.
        InvalidCase{"stage: {program: [{mode: velocity, speed: 4.0e-4}, {mode: hold}]}",
                    "stage.program[0].duration: value inf", "a finite duration > 0 s: later segments would never run"},
        // 10⁶ N on pmma_2d compressed it by 40 %, folded the lattice and filled the run with NaN.
        InvalidCase{"load: {normal_force: 1.0e6}", "load.normal_force: value 1000000",
                    "at most 126000 N (a mean normal stress F_Z/(L*B) of 5 % of E"},
        // A run that would never end (found when the rig's scene with its run end had to be a scene).
        InvalidCase{"stop: {global_events: 0, time: .inf}", "stop: no condition, so the run would never end",
                    "give global_events, time or stage_travel"},
        InvalidCase{"stop: {time: 0}", "stop.time: value 0", "a time > 0 s (.inf allowed)"},
        // µ_s·F_Z/3 = 256 N per block: the first would slide at t = 0.
        InvalidCase{"model: chain_1d\nchain: {blocks: 3, initial_shear: [400.0, 0.0, 0.0]}",
                    "chain.initial_shear[0]: value 400", "|f| < mu_s * w_0 = 256 N, below the block's static"},
        // At the threshold itself round-off started block 0 sliding at t = 0, unrecorded.
        InvalidCase{"model: chain_1d\nchain: {blocks: 3, initial_shear: [256.0, 0.0, 0.0]}",
                    "chain.initial_shear[0]: value 256", "|f| < mu_s * w_0 = 256 N, below the block's static"}));

TEST(SceneFiles, AShearProfileWithinTheStaticThresholdsIsHeldAsGiven) {
  const Scene scene = parseScene(
      "model: chain_1d\nchain: {blocks: 3, initial_shear: [250.0, 0.0, -250.0]}\nstage: {program: [{mode: hold}]}");
  Simulation simulation(scene);
  simulation.advance(1e-3);
  const InterfaceFrame frame = simulation.interfaceFrame();
  const std::vector<double> expected{250.0, 0.0, -250.0};
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(frame.state[i], 0) << "block " << i;
    EXPECT_NEAR(frame.friction_force[i], expected[i], 1e-6) << "block " << i;
  }
}

TEST(InvalidScene, AYamlSyntaxErrorNamesTheFile) {
  const std::string path = (std::filesystem::temp_directory_path() / "friction_sim_broken_scene.yaml").string();
  std::ofstream(path) << "friction: {static_coefficient: 0.4\n";  // the brace is never closed
  try {
    loadScene(path);
    FAIL() << "accepted";
  } catch (const SceneError& error) {
    ASSERT_EQ(error.problems().size(), 1u);
    EXPECT_NE(error.problems()[0].find("YAML syntax error in '" + path + "'"), std::string::npos) << error.what();
  }
  std::filesystem::remove(path);
}

TEST(InvalidScene, UnstableTimeStepMessageGivesTheLimit) {
  const auto problems = problemsOf("integrator: {time_step: 1.0e-5}");
  ASSERT_EQ(problems.size(), 1u);
  const double limit = sceneStabilityLimit(loadScene(scenePath("pmma_2d")));
  std::ostringstream text;
  text.precision(4);
  text << "dt < " << limit << " s";
  EXPECT_NE(problems[0].find(text.str()), std::string::npos) << problems[0];
}

// Extreme but finite numbers found by fuzzing the shipped scenes: each hung the stability limit's
// eigenvalue computation or aborted the loading solve; each is now refused, naming the field.
TEST(InvalidScene, ExtremeStiffnessesAndMassesAreRefusedNamingTheField) {
  struct Case {
    const char* scene;
    const char* field;
    const char* value;
    const char* refused;
  };
  const Case cases[] = {
      {"single_block", "material.density", "1e-320", "integrator.time_step: value 1e-06 is not allowed; allowed: none"},
      {"pmma_2d", "material.youngs_modulus", "1e308",
       "integrator.time_step: value 2e-07 is not allowed; allowed: none"},
      {"pmma_2d", "pusher.stiffness", "1e308", "integrator.time_step: value 2e-07 is not allowed; allowed: none"},
      {"pmma_2d", "lattice.foundation_ratio", "1e300", "integrator.time_step: value 2e-07 is not allowed"},
      {"pmma_1d_top", "material.youngs_modulus", "1e300", "integrator.time_step: value 2e-07 is not allowed"},
      {"pmma_2d", "lattice.foundation_ratio", "1e-320",
       "lattice.foundation_ratio: value 9.999888672e-321 is not allowed"}};
  for (const Case& c : cases) {
    SCOPED_TRACE(std::string(c.scene) + ", " + c.field + " = " + c.value);
    try {
      loadScene(scenePath(c.scene), {{c.field, c.value}});
      FAIL() << "accepted";
    } catch (const SceneError& error) {
      EXPECT_TRUE(mentions(error.problems(), c.refused)) << error.what();
    }
  }
  // The least foundation that carries F_Z by sinking under a tenth of a spacing: 10 F_Z/(N_x k l).
  const auto problems = problemsOf("lattice: {foundation_ratio: 1.0e-3}");
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_TRUE(mentions(problems, "allowed: >= 0.0099")) << problems[0];
}

// A scene too large for the machine is refused before anything is allocated, naming the field that
// sizes it (a 10^8 x 5·10^7 lattice once grew to 19 GB before failing).
TEST(InvalidScene, AScenePastTheMemoryLimitIsRefusedBeforeItIsBuilt) {
  try {
    loadScene(scenePath("pmma_2d"), {{"lattice.nodes_x", "100000001"}, {"lattice.nodes_z", "53571429"}});
    FAIL() << "accepted";
  } catch (const SceneError& error) {
    EXPECT_TRUE(mentions(error.problems(), "lattice.nodes_x: value 100000001 is not allowed; allowed: at most"))
        << error.what();
  }
  // The limit can be set: 100 MB holds 57 x 31 (5.3 MB for its nodes) but not 449 x 241 (325 MB).
  setenv("FRICTION_MEMORY_LIMIT_MB", "100", 1);
  EXPECT_TRUE(problemsOf("lattice: {nodes_x: 57, nodes_z: 31}").empty());
  const auto problems = problemsOf("lattice: {nodes_x: 449, nodes_z: 241}\nintegrator: {time_step: 1.0e-8}");
  // A limit that is not a number is refused by name (read as 0 it would refuse every scene).
  setenv("FRICTION_MEMORY_LIMIT_MB", "2GB", 1);
  const auto unread = problemsOf("lattice: {nodes_x: 57, nodes_z: 31}");
  unsetenv("FRICTION_MEMORY_LIMIT_MB");
  EXPECT_TRUE(mentions(problems, "lattice.nodes_x: value 449 is not allowed; allowed: at most 33333 nodes"))
      << problems[0];
  ASSERT_EQ(unread.size(), 1u);
  EXPECT_EQ(unread[0],
            "FRICTION_MEMORY_LIMIT_MB (environment): value '2GB' is not allowed; allowed: a number of MB > 0");
}

TEST(InvalidScene, APusherBandOfNaNIsRefusedNotTakenForNone) {
  const auto problems = problemsOf("pusher: {band_min: .nan, band_max: .nan}");
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_EQ(problems[0].find("pusher.band_min: value nan is not allowed"), 0u) << problems[0];
  EXPECT_EQ(problems[1],
            "pusher.band_max: value nan is not allowed; allowed: [0, 0.075] (pusher.band_min..geometry.height)");
}

TEST(InvalidScene, EveryProblemOfAFileIsListedAtOnce) {
  const auto problems = problemsOf(
      "geometry: {length: -0.14}\n"
      "friction: {static_coefficient: 0.3, kinetic_coefficient: 0.5, typo: 1}\n"
      "load: {normal_force: -5}\n"
      "integrator: {scheme: euler}\n");
  EXPECT_EQ(problems.size(), 5u);
  EXPECT_TRUE(mentions(problems, "geometry.length"));
  EXPECT_TRUE(mentions(problems, "friction.kinetic_coefficient"));
  EXPECT_TRUE(mentions(problems, "friction.typo: unknown key"));
  EXPECT_TRUE(mentions(problems, "load.normal_force"));
  EXPECT_TRUE(mentions(problems, "integrator.scheme: value 'euler'"));
}

TEST(InvalidScene, ATimeStepBehindAModelProblemIsAnnouncedAndCheckedOnceTheModelIsValid) {
  const std::string yaml =
      "material: {density: -1200}\ninstruments: {loading_curve_rate: 100}\nintegrator: {time_step: 1.0e-3}\n";
  try {
    parseScene(yaml);
    FAIL() << "accepted";
  } catch (const SceneError& error) {
    // The note is listed after the problem and not counted among the problems.
    const std::string text = error.what();
    EXPECT_EQ(text.rfind("scene refused (1 problem):\n  - material.density: value -1200", 0), 0u) << text;
    EXPECT_NE(text.find("\n  note: integrator.time_step: value 0.001 not yet checked against the stability limit"),
              std::string::npos)
        << text;
    EXPECT_EQ(error.problems().size(), 1u);
  }
  const auto fixed = problemsOf("instruments: {loading_curve_rate: 100}\nintegrator: {time_step: 1.0e-3}\n");
  ASSERT_EQ(fixed.size(), 1u);
  EXPECT_NE(fixed[0].find("integrator.time_step: value 0.001 is not allowed; allowed: dt <"), std::string::npos)
      << fixed[0];
}

}  // namespace
}  // namespace friction
