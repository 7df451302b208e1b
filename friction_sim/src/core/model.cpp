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
