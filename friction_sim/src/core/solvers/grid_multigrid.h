// Conjugate gradients preconditioned by a geometric multigrid V-cycle, for the stiffness of a
// structured grid of nodes: the static solve of a lattice too large for a direct factor (a 2D
// factor grows as n log n: 2.2 GB for 10⁶ nodes, against a few matrix copies here).
#pragma once

#include <memory>
#include <vector>

#include "friction_sim/model/model.h"

namespace friction {

class CholeskyFactor;

/// Layout of a structured grid's degrees of freedom: component c of node (i, j) is dof
/// c·nodes_x·nodes_z + j·nodes_x + i (the lattice: u_x of every node, then u_z; the chain: one row).
struct GridLayout {
  int nodes_x = 1;     ///< nodes along x
  int nodes_z = 1;     ///< nodes along z
  int components = 1;  ///< degrees of freedom per node
};

class GridMultigrid {
 public:
  /// `matrix`: symmetric positive definite, both triangles stored, over the degrees of freedom
  /// `free_dofs` (row r is grid dof free_dofs[r]; the others are fixed and absent). Coarse levels
  /// take every other node along each axis (plus the last), with bilinear interpolation and Galerkin
  /// coarse matrices, down to about a thousand degrees of freedom, which are factored.
  GridMultigrid(SparseMatrix matrix, const std::vector<int>& free_dofs, const GridLayout& layout);
  ~GridMultigrid();

  /// Solves matrix·x = rhs until ‖rhs − matrix·x‖ ≤ relative_tolerance·‖rhs‖. Throws
  /// std::runtime_error if conjugate gradients do not reach it.
  Vector solve(const Vector& rhs, double relative_tolerance) const;
  /// Conjugate-gradient iterations of the last solve.
  int lastIterations() const { return last_iterations_; }

 private:
  struct Level {
    SparseMatrix matrix;       ///< both triangles
    Vector inverse_diagonal;   ///< for the Gauss–Seidel sweeps
    SparseMatrix restriction;  ///< to the next coarser level (its transpose interpolates back)
  };
  Vector cycle(std::size_t level, const Vector& rhs) const;

  std::vector<Level> levels_;  ///< finest first; the coarsest matrix is in coarsest_
  std::unique_ptr<CholeskyFactor> coarsest_;
  mutable int last_iterations_ = 0;
};

}  // namespace friction
