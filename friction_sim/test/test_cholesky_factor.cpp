// The direct method's factor: its own supernodal factorisation and solve in double, and the single-precision copy
// that the modified-Newton corrections use.
#include <gtest/gtest.h>

#include <stdexcept>

#include "solvers/cholesky_factor.h"

namespace friction {
namespace {

/// The lower triangle of a symmetric matrix given by its entries on and below the diagonal.
SparseMatrix lowerOf(int size, const std::vector<Eigen::Triplet<double>>& entries) {
  SparseMatrix lower(size, size);
  lower.setFromTriplets(entries.begin(), entries.end());
  return lower;
}

/// The five-point Laplacian of an n × n grid plus `shift` on the diagonal: under AMD its factor has
/// supernodes of every width from one column to the separators' tens.
SparseMatrix gridLaplacian(int n, double shift) {
  std::vector<Eigen::Triplet<double>> entries;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const int node = j * n + i;
      entries.emplace_back(node, node, 4.0 + shift);
      if (i + 1 < n) entries.emplace_back(node + 1, node, -1.0);
      if (j + 1 < n) entries.emplace_back(node + n, node, -1.0);
    }
  }
  return lowerOf(n * n, entries);
}

/// A dense symmetric positive definite matrix: one supernode wider than a solve takes at once.
SparseMatrix denseMatrix(int n) {
  std::vector<Eigen::Triplet<double>> entries;
  for (int c = 0; c < n; ++c) {
    for (int r = c; r < n; ++r) entries.emplace_back(r, c, r == c ? 2.0 * n : 1.0 / (1.0 + r - c));
  }
  return lowerOf(n, entries);
}

/// A tridiagonal matrix: every fundamental supernode one column wide, relaxed into runs of up to 16.
SparseMatrix tridiagonal(int n) {
  std::vector<Eigen::Triplet<double>> entries;
  for (int i = 0; i < n; ++i) {
    entries.emplace_back(i, i, 2.5);
    if (i + 1 < n) entries.emplace_back(i + 1, i, -1.0);
  }
  return lowerOf(n, entries);
}

/// A random sparse pattern (about `per_column` entries below the diagonal in each column) made
/// diagonally dominant, in `components` uncoupled blocks: an elimination forest of irregular trees.
SparseMatrix randomSparse(int size, int per_column, int components) {
  std::srand(11);
  std::vector<Eigen::Triplet<double>> entries;
  const int block = size / components;
  for (int c = 0; c < size; ++c) {
    const int block_end = std::min(size, (c / block + 1) * block);
    entries.emplace_back(c, c, 2.0 * per_column + 1.0);
    for (int k = 0; k < per_column && c + 1 < block_end; ++k) {
      entries.emplace_back(c + 1 + std::rand() % (block_end - c - 1), c, -1.0 + 0.5 * (std::rand() % 3));
    }
  }
  SparseMatrix lower = lowerOf(size, entries);  // repeated entries summed; off-diagonal sums stay small
  for (int c = 0; c < size; ++c) lower.coeffRef(c, c) += lower.col(c).cwiseAbs().sum() + lower.row(c).cwiseAbs().sum();
  return lower;
}

TEST(CholeskyFactor, SinglePrecisionSolveMatchesTheDoubleSolve) {
  for (const SparseMatrix& lower :
       {gridLaplacian(70, 1e-3), denseMatrix(45), tridiagonal(500), randomSparse(900, 3, 4)}) {
    const CholeskyFactor factor(lower);
    const SparseMatrix matrix = lower.selfadjointView<Eigen::Lower>();
    std::srand(7);
    const Vector rhs = Vector::Random(lower.rows());
    const Vector exact = factor.solve(rhs);
    const Vector single = factor.solveSinglePrecision(rhs);
    EXPECT_LT((matrix * exact - rhs).norm(), 1e-12 * rhs.norm()) << lower.rows();
    // Entries rounded to float (6·10⁻⁸), sums in double: the error stays near the rounding's. Measured:
    // 5.4·10⁻⁸ (Laplacian, condition number about 1.6·10³), 8.7·10⁻¹¹ (dense), 2.5·10⁻⁸ (tridiagonal).
    EXPECT_LT((single - exact).norm(), 1e-6 * exact.norm()) << lower.rows();
    EXPECT_GT((single - exact).norm(), 0.0) << lower.rows();  // it is the single-precision copy
  }
}

TEST(CholeskyFactor, SolvingColumnsTogetherGivesEachColumnsOwnSolveToTheBit) {
  // 37 columns: sweeps of 16, 16 and 5 (8 wide); 3 columns: one sweep 4 wide.
  for (const SparseMatrix& lower :
       {gridLaplacian(70, 1e-3), denseMatrix(45), tridiagonal(500), randomSparse(900, 3, 4)}) {
    const CholeskyFactor factor(lower);
    std::srand(5);
    for (const int columns : {37, 3}) {
      const Eigen::MatrixXd rhs = Eigen::MatrixXd::Random(lower.rows(), columns);
      const Eigen::MatrixXd together = factor.solveColumns(rhs);
      const Eigen::MatrixXd together_single = factor.solveColumnsSinglePrecision(rhs);
      for (int c = 0; c < columns; ++c) {
        const Vector alone = factor.solve(rhs.col(c));
        EXPECT_EQ((together.col(c) - alone).cwiseAbs().maxCoeff(), 0.0) << lower.rows() << " column " << c;
        const Vector alone_single = factor.solveSinglePrecision(rhs.col(c));
        EXPECT_EQ((together_single.col(c) - alone_single).cwiseAbs().maxCoeff(), 0.0)
            << lower.rows() << " column " << c << " in single precision";
      }
    }
  }
}

TEST(CholeskyFactor, SolvesWithoutUnknowns) {
  // Nothing to solve for: an empty factor, not an error (AMD itself refuses empty arrays).
  const CholeskyFactor factor(SparseMatrix(0, 0));
  EXPECT_EQ(factor.solve(Vector()).size(), 0);
  EXPECT_EQ(factor.solveSinglePrecision(Vector()).size(), 0);
  EXPECT_EQ(factor.solveColumns(Eigen::MatrixXd(0, 3)).size(), 0);
  EXPECT_EQ(factor.solveColumnsSinglePrecision(Eigen::MatrixXd(0, 3)).size(), 0);
}

TEST(CholeskyFactor, RefusesASingularMatrix) {
  // A zero row and column: not positive definite.
  std::vector<Eigen::Triplet<double>> entries = {{0, 0, 1.0}, {2, 2, 1.0}};
  EXPECT_THROW(CholeskyFactor(lowerOf(3, entries)), std::runtime_error);
}

}  // namespace
}  // namespace friction
