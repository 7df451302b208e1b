#include "friction_sim/model.h"

#include "friction_sim/chain_1d.h"
#include "friction_sim/lattice_2d.h"

namespace friction {

void Model::evaluateInStrips(const Vector& u, const Vector& v, double stage_position, Vector& force,
                             ForceEvaluation& out, StripHooks& hooks, int /*strip_nodes*/) const {
  hooks.prepare(0, dofCount());
  evaluateInto(u, v, stage_position, force, out);
  hooks.finish(0, dofCount());
}

bool Model::evaluateTwoInStrips(const StripEvaluation& first, const StripEvaluation& second, int strip_nodes,
                                const std::function<bool()>& between) const {
  evaluateInStrips(first.u, first.v, first.stage_position, first.force, first.out, first.hooks, strip_nodes);
  if (!between()) return false;
  evaluateInStrips(second.u, second.v, second.stage_position, second.force, second.out, second.hooks, strip_nodes);
  return true;
}

std::vector<int> Model::blockedDofsDuringLoading() const {
  std::vector<int> dofs;
  for (int node = 0; node < interfaceNodeCount(); ++node) dofs.push_back(interfaceDof(node));
  return dofs;
}

std::unique_ptr<Model> buildModel(const Scene& scene) {
  if (scene.model == ModelKind::Lattice2D) return std::make_unique<Lattice2D>(scene);
  return std::make_unique<Chain1D>(scene);
}

}  // namespace friction
