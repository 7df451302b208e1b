// Shared pieces of the core tests.
#pragma once

#include <string>

#include "friction_sim/integrator.h"
#include "friction_sim/model.h"
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

/// A coarse 2D slider (29 × 16 nodes, l = 5 mm) driven ten times faster than the default, so that a
/// whole run to the first global event takes about a second.
inline Scene coarseSliderScene(bool fast_forward = false) {
  Scene scene = loadScene(scenePath("pmma_2d"));
  scene.lattice.nodes_x = 29;
  scene.lattice.nodes_z = 16;
  scene.stage.program = {StageSegment{StageMode::Velocity, 4e-3}};
  scene.integrator.time_step = 4e-7;
  scene.integrator.fast_forward = fast_forward;
  return scene;
}

/// A frictionless, unpushed elastic body integrated directly: u'' = F(u, u')/m.
class FreeBody : public Dynamics {
 public:
  explicit FreeBody(Model& model) : model_(model) { model_.disconnectPusher(); }
  double acceleration(const Vector& u, const Vector& v, double, Vector& a) override {
    model_.evaluate(u, v, 0.0, evaluation_);
    a = evaluation_.force / model_.nodeMass();
    return evaluation_.viscous_power;
  }
  double energy(const Vector& u, const Vector& v) const {
    return model_.elasticEnergy(u, 0.0) + 0.5 * model_.nodeMass() * v.squaredNorm();
  }

 private:
  Model& model_;
  ForceEvaluation evaluation_;
};

}  // namespace friction::testing
