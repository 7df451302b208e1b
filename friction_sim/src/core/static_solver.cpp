#include "friction_sim/static_solver.h"

#include <stdexcept>

namespace friction {

namespace {
/// The lower triangle (all the factorisation reads) of the stiffness of the free degrees of freedom
/// (`position_in_free` is −1 for a fixed one), copied column by column: the free dofs keep their
/// order, so no triplet list is needed.
SparseMatrix freeStiffness(const Model& model, const std::vector<int>& position_in_free, int free_count) {
  const SparseMatrix stiffness = model.stiffnessMatrix();
  SparseMatrix reduced(free_count, free_count);
  reduced.reserve(stiffness.nonZeros() / 2 + free_count);
  for (int column = 0; column < stiffness.outerSize(); ++column) {
    const int col = position_in_free[column];
    if (col < 0) continue;
    reduced.startVec(col);
    for (SparseMatrix::InnerIterator it(stiffness, column); it; ++it) {
      const int row = position_in_free[it.row()];
      if (row >= col) reduced.insertBack(row, col) = it.value();
    }
  }
  reduced.finalize();
  return reduced;
}
}  // namespace

StaticSolver::StaticSolver(const Model& model, const std::vector<int>& fixed_dofs, bool balance_load)
    : balance_load_(balance_load) {
  const int n = model.dofCount();
  std::vector<char> fixed(n, 0);
  for (int dof : fixed_dofs) fixed[dof] = 1;
  std::vector<int> position_in_free(n, -1);
  for (int dof = 0; dof < n; ++dof) {
    if (fixed[dof]) continue;
    position_in_free[dof] = static_cast<int>(free_dofs_.size());
    free_dofs_.push_back(dof);
  }
  tolerance_ = 1e-14 * model.nodeSpacing() * std::max(model.gridShape()[0], 1);
  if (free_dofs_.empty()) return;
  // Built in a function of its own so that the full matrix is freed before the factorisation, the
  // memory peak of a large lattice.
  const SparseMatrix reduced = freeStiffness(model, position_in_free, static_cast<int>(free_dofs_.size()));
  factor_.compute(reduced);
  if (factor_.info() != Eigen::Success) throw std::runtime_error("static solve: the stiffness matrix is singular");
}

Vector StaticSolver::response(const Vector& force) const {
  Vector reduced(free_dofs_.size());
  for (std::size_t i = 0; i < free_dofs_.size(); ++i) reduced[i] = force[free_dofs_[i]];
  const Vector solution = free_dofs_.empty() ? reduced : Vector(factor_.solve(reduced));
  Vector out = Vector::Zero(force.size());
  for (std::size_t i = 0; i < free_dofs_.size(); ++i) out[free_dofs_[i]] = solution[i];
  return out;
}

int StaticSolver::solve(Model& model, Vector& u, double stage_position, const Vector& body_force) const {
  if (free_dofs_.empty()) return 0;
  ForceEvaluation evaluation;
  const Vector at_rest = Vector::Zero(u.size());
  for (int iteration = 1; iteration <= 500; ++iteration) {
    model.evaluate(u, at_rest, stage_position, evaluation);
    if (body_force.size() > 0) evaluation.force += body_force;
    const Vector correction = response(evaluation.force);
    u += correction;
    const bool load_changed = balance_load_ && model.rebalanceLoad(u);
    if (!load_changed && correction.lpNorm<Eigen::Infinity>() < tolerance_) return iteration;
  }
  return 500;
}

}  // namespace friction
