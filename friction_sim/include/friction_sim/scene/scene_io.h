// Reading scenes from YAML and checking them. A scene is refused before a run starts, with every
// problem listed at once: unknown keys (typos must not fall back to defaults), wrong types, values out
// of range and cross-field constraints (µ_k ≤ µ_s, h inside the slider, dt stable, ...).
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "friction_sim/scene/config_error.h"
#include "friction_sim/scene/scene.h"

namespace friction {

/// Thrown when a scene is refused; `problems()` holds one message per problem, each naming the
/// field, the value and what is allowed; `notes()` what they kept from being checked.
class SceneError : public ConfigError {
 public:
  explicit SceneError(std::vector<std::string> problems, std::vector<std::string> notes = {})
      : ConfigError("scene", std::move(problems), std::move(notes)) {}
};

/// Parses a scene from YAML text; fields absent from the text keep the defaults of `base`.
/// Throws SceneError listing every problem (parse and validation). The validation computes the scene's
/// stability limit (s); given `stability_limit`, it is kept there for Simulation(scene, limit), so that
/// a large lattice's spectrum is not estimated twice.
Scene parseScene(const std::string& yaml_text, const Scene& base = Scene{}, double* stability_limit = nullptr);

/// Reads and parses a scene file (see parseScene), with `overrides` (as for overrideScene) applied
/// before the one validation.
Scene loadScene(const std::string& path, const std::vector<std::pair<std::string, std::string>>& overrides = {},
                double* stability_limit = nullptr);

/// The scene with fields replaced: each override is a dotted key ("pusher.height") and a YAML value
/// ("0.01"). The result is parsed and validated like a file (see parseScene). Throws SceneError.
Scene overrideScene(const Scene& base, const std::vector<std::pair<std::string, std::string>>& overrides,
                    double* stability_limit = nullptr);

/// What a scene's check found.
struct SceneReview {
  std::vector<std::string> problems;  ///< each refuses the scene; none when it is valid
  /// The checks the problems kept from running (dt's stability needs a valid model), so that mending
  /// the problems does not meet a new refusal unannounced.
  std::vector<std::string> notes;
};

/// Every problem of a scene: ranges, cross-field constraints, dt stability. When the model's own
/// fields are valid and `stability_limit` is given, it receives the scene's stability limit (s), which
/// the check computes anyway.
SceneReview validateScene(const Scene& scene, double* stability_limit = nullptr);

/// N, the largest F_Z the scene takes: a mean normal stress F_Z/(L·B) of 5 % of E. Beyond it the
/// slider's compression is no small strain, which its linear elasticity assumes (F_Z = 10⁶ N, 40 % of E
/// on pmma_2d, folded the lattice and filled the run with NaN).
double largestNormalForce(const Scene& scene);

/// What is allowed but probably not meant (e.g. a slip-weakening length shorter than one lattice
/// spacing, which the lattice cannot resolve); printed by the runner and the simulator node.
std::vector<std::string> sceneWarnings(const Scene& scene);

/// Throws SceneError if validateScene finds a problem; returns the scene's stability limit (s).
double requireValidScene(const Scene& scene);

/// The scene as YAML text that parseScene reads back to the same scene.
std::string sceneToYaml(const Scene& scene);

}  // namespace friction
