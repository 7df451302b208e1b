// Shared pieces of the core tests.
#pragma once

#include <string>

#include "friction_sim/scene.h"
#include "friction_sim/scene_io.h"

namespace friction::testing {

inline std::string scenePath(const std::string& name) { return std::string(SCENE_DIR) + "/" + name + ".yaml"; }

/// The whole 75.6 g slider as one block on the stage spring, no damping.
inline Scene singleBlockScene(IntegratorKind scheme, double stage_speed, double time_step) {
  Scene scene = loadScene(scenePath("single_block"));
  scene.stage.max_speed = 10.0;
  scene.stage.program = {StageSegment{StageMode::Velocity, stage_speed}};
  scene.integrator.scheme = scheme;
  scene.integrator.time_step = time_step;
  scene.stop.global_events = 3;
  return scene;
}

}  // namespace friction::testing
