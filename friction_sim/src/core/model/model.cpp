#include "friction_sim/model/model.h"

#include "friction_sim/model/chain_1d.h"
#include "friction_sim/model/lattice_2d.h"

#include <stdexcept>

namespace friction {

void Model::evaluateInStrips(const Vector& u, const Vector& v, double stage_position, Vector& force,
                             ForceEvaluation& out, StripHooks& hooks, int /*strip_nodes*/) const {
  hooks.prepare(0, dofCount());
  evaluateInto(u, v, stage_position, force, out);
  hooks.finish(0, dofCount());
}

int Model::evaluateSuccessiveInStrips(int strip_nodes,
                                      const std::function<std::optional<StripEvaluation>(int)>& next) const {
  for (int count = 0;; ++count) {
    const std::optional<StripEvaluation> evaluation = next(count);
    if (!evaluation) return count;
    if (count == successiveEvaluations()) {
      throw std::logic_error(
          "Model::evaluateSuccessiveInStrips: asked for more evaluations than successiveEvaluations()");
    }
    evaluateInStrips(evaluation->u, evaluation->v, evaluation->stage_position, evaluation->force, evaluation->out,
                     evaluation->hooks, strip_nodes);
  }
}

std::vector<double> Model::interfacePositions() const {
  std::vector<double> positions(interfaceNodeCount());
  for (int node = 0; node < interfaceNodeCount(); ++node) positions[node] = interfacePosition(node);
  return positions;
}

std::vector<int> Model::blockedDofsDuringLoading() const {
  std::vector<int> dofs(interfaceNodeCount());
  for (int node = 0; node < interfaceNodeCount(); ++node) dofs[node] = interfaceDof(node);
  return dofs;
}

std::unique_ptr<Model> buildModel(const Scene& scene) {
  if (scene.model == ModelKind::Lattice2D) return std::make_unique<Lattice2D>(scene);
  return std::make_unique<Chain1D>(scene);
}

}  // namespace friction
