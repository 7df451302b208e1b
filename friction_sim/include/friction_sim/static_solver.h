// Static equilibrium of the slider with some degrees of freedom held fixed, by modified Newton: the
// linearised stiffness of the free degrees of freedom is factored once (CHOLMOD's supernodal Cholesky) and
// corrects the residual of the full (geometric, one-sided) forces until they balance. Used for the
// loading protocol and, with the interface pinned, for the quasi-static fast-forward.
#pragma once

#include <Eigen/CholmodSupport>
#include <vector>

#include "friction_sim/model.h"

namespace friction {

class StaticSolver {
 public:
  /// Factors the stiffness of every degree of freedom not in `fixed_dofs`, as the model is now
  /// (pusher connected or not). With `balance_load`, a displacement-controlled top load (the spring
  /// mattress) is re-balanced to carry F_Z while solving, as when the load is applied. Throws
  /// std::runtime_error if that stiffness is singular.
  StaticSolver(const Model& model, const std::vector<int>& fixed_dofs, bool balance_load = false);

  /// Moves the free degrees of freedom of `u` to equilibrium with the stage at `stage_position` (m)
  /// and the extra forces `body_force` (N per dof; empty = none). The fixed ones stay as they are.
  /// Returns the number of iterations.
  int solve(Model& model, Vector& u, double stage_position, const Vector& body_force = Vector()) const;

  /// Displacement of the free degrees of freedom per unit of a force vector on them (K_ff⁻¹·f).
  Vector response(const Vector& force) const;

  const std::vector<int>& freeDofs() const { return free_dofs_; }

 private:
  std::vector<int> free_dofs_;
  Eigen::CholmodSupernodalLLT<SparseMatrix> factor_;
  double tolerance_;
  bool balance_load_;
};

}  // namespace friction
