#include "solvers/grid_multigrid.h"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>
#include <utility>

#include "solvers/cholesky_factor.h"

namespace friction {

namespace {
/// Up to this many degrees of freedom a level is factored instead of coarsened further.
constexpr int kCoarsestDofs = 1000;
constexpr int kMaxIterations = 500;

/// Interpolation along one axis from every other node (plus the last) to all `fine` nodes: for each
/// fine node, up to two (coarse node, weight) pairs. Axes of one or two nodes are kept as they are.
struct AxisCoarsening {
  int coarse = 0;
  std::vector<std::array<std::pair<int, double>, 2>> weights;
  std::vector<int> place;  ///< the fine node at each coarse node's place

  explicit AxisCoarsening(int fine) : weights(fine) {
    coarse = fine <= 2 ? fine : fine / 2 + 1;
    for (int node = 0; node < coarse; ++node) place.push_back(fine <= 2 ? node : std::min(2 * node, fine - 1));
    for (int i = 0; i < fine; ++i) {
      if (coarse == fine) {
        weights[i] = {{{i, 1.0}, {i, 0.0}}};
        continue;
      }
      const int left = std::min(i / 2, coarse - 2);
      const double along = double(i - place[left]) / (place[left + 1] - place[left]);
      weights[i] = {{{left, 1.0 - along}, {left + 1, along}}};
    }
  }
};

/// Restriction (transpose of the bilinear prolongation) from the grid dofs `free_dofs` of `layout`
/// to the coarse grid, built column by column (≤ 4 entries each, rows ascending). A coarse dof is
/// kept only where the fine dof at its place is free (`coarse_dofs` lists them): that fine dof
/// interpolates from it alone, so the rows of R are independent and R·A·Rᵀ stays positive definite
/// whatever is fixed.
SparseMatrix restriction(const std::vector<int>& free_dofs, const GridLayout& layout, GridLayout& coarse,
                         std::vector<int>& coarse_dofs) {
  const AxisCoarsening along_x(layout.nodes_x), along_z(layout.nodes_z);
  coarse = {along_x.coarse, along_z.coarse, layout.components};
  const int nodes = layout.nodes_x * layout.nodes_z;
  const int coarse_nodes = coarse.nodes_x * coarse.nodes_z;
  std::vector<char> free(nodes * layout.components, 0);
  for (int dof : free_dofs) free[dof] = 1;
  std::vector<int> coarse_index(coarse_nodes * coarse.components, -1);
  coarse_dofs.clear();
  for (int component = 0; component < coarse.components; ++component) {
    for (int j = 0; j < coarse.nodes_z; ++j) {
      const int fine_row = along_z.place[j];
      for (int i = 0; i < coarse.nodes_x; ++i) {
        if (!free[component * nodes + fine_row * layout.nodes_x + along_x.place[i]]) continue;
        const int dof = component * coarse_nodes + j * coarse.nodes_x + i;
        coarse_index[dof] = static_cast<int>(coarse_dofs.size());
        coarse_dofs.push_back(dof);
      }
    }
  }
  SparseMatrix out(static_cast<int>(coarse_dofs.size()), static_cast<int>(free_dofs.size()));
  out.reserve(4 * free_dofs.size());
  for (std::size_t column = 0; column < free_dofs.size(); ++column) {
    const int component = free_dofs[column] / nodes;
    const int node = free_dofs[column] % nodes;
    out.startVec(static_cast<int>(column));
    for (const auto& [j, weight_z] : along_z.weights[node / layout.nodes_x]) {
      if (weight_z == 0.0) continue;
      for (const auto& [i, weight_x] : along_x.weights[node % layout.nodes_x]) {
        const int row = coarse_index[component * coarse_nodes + j * coarse.nodes_x + i];
        if (weight_x == 0.0 || row < 0) continue;
        out.insertBack(row, static_cast<int>(column)) = weight_x * weight_z;
      }
    }
  }
  out.finalize();
  return out;
}

/// The Galerkin coarse matrix R·A·Rᵀ (symmetric positive definite whenever A is), column by column
/// with dense work vectors: Eigen's sparse product would hold A·Rᵀ and a re-sorted copy of it, each
/// larger than the coarse matrix, which at 10⁶ nodes decides the memory peak.
SparseMatrix galerkinProduct(const SparseMatrix& matrix, const SparseMatrix& restriction) {
  const SparseMatrix prolongation = restriction.transpose();
  const int coarse = static_cast<int>(restriction.rows());
  Vector fine_sum = Vector::Zero(matrix.rows());
  Vector coarse_sum = Vector::Zero(coarse);
  std::vector<char> fine_used(matrix.rows(), 0), coarse_used(coarse, 0);
  std::vector<int> fine_rows, coarse_rows;
  SparseMatrix out(coarse, coarse);
  // Bilinear interpolation keeps a nine-node stencil nine nodes wide: about A's density.
  out.reserve(matrix.nonZeros() / std::max<Eigen::Index>(matrix.cols(), 1) * coarse);
  for (int column = 0; column < coarse; ++column) {
    for (SparseMatrix::InnerIterator p(prolongation, column); p; ++p) {
      for (SparseMatrix::InnerIterator a(matrix, p.row()); a; ++a) {
        if (!fine_used[a.row()]) fine_rows.push_back(static_cast<int>(a.row()));
        fine_used[a.row()] = 1;
        fine_sum[a.row()] += a.value() * p.value();
      }
    }
    for (int row : fine_rows) {
      for (SparseMatrix::InnerIterator r(restriction, row); r; ++r) {
        if (!coarse_used[r.row()]) coarse_rows.push_back(static_cast<int>(r.row()));
        coarse_used[r.row()] = 1;
        coarse_sum[r.row()] += r.value() * fine_sum[row];
      }
      fine_sum[row] = 0.0;
      fine_used[row] = 0;
    }
    fine_rows.clear();
    std::sort(coarse_rows.begin(), coarse_rows.end());
    out.startVec(column);
    for (int row : coarse_rows) {
      out.insertBack(row, column) = coarse_sum[row];
      coarse_sum[row] = 0.0;
      coarse_used[row] = 0;
    }
    coarse_rows.clear();
  }
  out.finalize();
  return out;
}

/// One Gauss–Seidel sweep over a symmetric matrix stored by columns (column i = row i), forward or
/// backward: a forward pre-sweep and a backward post-sweep keep the V-cycle symmetric, as CG needs.
void gaussSeidel(const SparseMatrix& matrix, const Vector& inverse_diagonal, const Vector& rhs, Vector& x,
                 bool forward) {
  const int n = static_cast<int>(rhs.size());
  for (int k = 0; k < n; ++k) {
    const int i = forward ? k : n - 1 - k;
    double residual = rhs[i];
    for (SparseMatrix::InnerIterator it(matrix, i); it; ++it) residual -= it.value() * x[it.row()];
    x[i] += residual * inverse_diagonal[i];
  }
}
}  // namespace

GridMultigrid::GridMultigrid(SparseMatrix matrix, const std::vector<int>& free_dofs, const GridLayout& layout) {
  std::vector<int> dofs = free_dofs;
  GridLayout grid = layout;
  // Each level halves the nodes along an axis, so there are fewer than 64. Eigen 3.4's sparse
  // matrices have no move constructor: they are swapped into place, and the vector is reserved so
  // that growing it never copies them.
  levels_.reserve(64);
  std::vector<int> coarse_dofs;
  while (matrix.rows() > kCoarsestDofs) {
    GridLayout coarse;
    SparseMatrix restrict_to_coarse = restriction(dofs, grid, coarse, coarse_dofs);
    if (restrict_to_coarse.rows() >= matrix.rows()) break;
    SparseMatrix coarse_matrix = galerkinProduct(matrix, restrict_to_coarse);
    Level& level = levels_.emplace_back();
    level.inverse_diagonal = matrix.diagonal().cwiseInverse();
    level.matrix.swap(matrix);
    level.restriction.swap(restrict_to_coarse);
    matrix.swap(coarse_matrix);
    dofs.swap(coarse_dofs);
    grid = coarse;
  }
  try {
    coarsest_ = std::make_unique<CholeskyFactor>(SparseMatrix(matrix.triangularView<Eigen::Lower>()));
  } catch (const std::runtime_error&) {
    throw std::runtime_error("multigrid: the coarsest matrix is singular");
  }
}

GridMultigrid::~GridMultigrid() = default;

Vector GridMultigrid::cycle(std::size_t level, const Vector& rhs) const {
  if (level == levels_.size()) return coarsest_->solve(rhs);
  const Level& here = levels_[level];
  Vector x = Vector::Zero(rhs.size());
  gaussSeidel(here.matrix, here.inverse_diagonal, rhs, x, true);
  const Vector coarse_rhs = here.restriction * (rhs - here.matrix * x);
  x += here.restriction.transpose() * cycle(level + 1, coarse_rhs);
  gaussSeidel(here.matrix, here.inverse_diagonal, rhs, x, false);
  return x;
}

Vector GridMultigrid::solve(const Vector& rhs, double relative_tolerance) const {
  last_iterations_ = 0;
  Vector x = Vector::Zero(rhs.size());
  const double target = relative_tolerance * rhs.norm();
  if (target == 0.0) return x;
  if (levels_.empty()) return coarsest_->solve(rhs);
  const SparseMatrix& matrix = levels_.front().matrix;
  Vector residual = rhs;
  Vector preconditioned = cycle(0, residual);
  Vector direction = preconditioned;
  double along = residual.dot(preconditioned);
  Vector image(rhs.size());
  for (int iteration = 1; iteration <= kMaxIterations; ++iteration) {
    image.noalias() = matrix * direction;
    const double step = along / direction.dot(image);
    x += step * direction;
    residual -= step * image;
    if (residual.norm() <= target) {
      last_iterations_ = iteration;
      return x;
    }
    preconditioned = cycle(0, residual);
    const double next_along = residual.dot(preconditioned);
    direction = preconditioned + (next_along / along) * direction;
    along = next_along;
  }
  throw std::runtime_error("multigrid: conjugate gradients did not converge in " + std::to_string(kMaxIterations) +
                           " iterations");
}

}  // namespace friction
