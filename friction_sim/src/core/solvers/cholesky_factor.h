// The direct method's Cholesky factor: CHOLMOD's simplicial LLᵀ for exact solves, and a single-precision
// copy of it, solved by this class's own triangular sweeps, for the modified-Newton corrections.
#pragma once

#include <Eigen/CholmodSupport>
#include <vector>

#include "friction_sim/model/model.h"

namespace friction {

class CholeskyFactor {
 public:
  /// Factors `lower`, the lower triangle of a symmetric matrix. Throws std::runtime_error if it is not
  /// positive definite.
  explicit CholeskyFactor(const SparseMatrix& lower);

  /// matrix⁻¹·rhs in double precision (CHOLMOD's solve).
  Vector solve(const Vector& rhs) const;

  /// matrix⁻¹·rhs through the factor's entries below its diagonal blocks rounded to single precision
  /// (sums in double): a relative error of about the condition number times 6·10⁻⁸. A solve streams the
  /// whole factor twice and waits on memory; 4 bytes per non-zero instead of CHOLMOD's 12 make it faster,
  /// and a modified-Newton loop, whose residual is evaluated in double, converges to the same equilibrium.
  Vector solveSinglePrecision(const Vector& rhs) const;

  /// Bytes held: CHOLMOD's factor and the single-precision copy.
  std::size_t bytes() const;

 private:
  /// Columns per supernode at most (a solve keeps one supernode's partial sums on the stack).
  static constexpr int kWidestSupernode = 32;
  /// CHOLMOD's simplicial factor rather than its supernodal one: with the reference BLAS the supernodal
  /// factor's dense blocks gain nothing, and its OpenMP regions (four threads, fixed when CHOLMOD is
  /// built) cost thread wake-ups. Simplicial factors 2.4, 2.0 and 1.2× as fast and solves 2.2, 1.3 and
  /// 1.45× as fast at 113 × 61, 225 × 121 and 449 × 241 (2026-11-27, AMD EPYC Zen 1, Debian's CHOLMOD
  /// 3.0.14). This class reaches the factor, which Eigen keeps protected.
  class Cholmod : public Eigen::CholmodSimplicialLLT<SparseMatrix> {
   public:
    explicit Cholmod(const SparseMatrix& lower) : Eigen::CholmodSimplicialLLT<SparseMatrix>(lower) {}
    const cholmod_factor& factor() const { return *m_cholmodFactor; }
  };

  Cholmod cholmod_;
  /// The factor's row k belongs to the matrix's row fill_order_[k] (CHOLMOD's fill-reducing permutation).
  std::vector<int> fill_order_;
  /// The factor in supernodes: runs of columns that share one pattern below their own diagonal block
  /// (nearly every column is in one; four columns each on average at 225 × 121), so that a solve reads
  /// one list of rows per run and touches each of those rows once per run, not once per column.
  /// Supernode s spans columns [first_column_[s], first_column_[s + 1]).
  std::vector<int> first_column_;
  /// Its diagonal block, lower triangle of a w × w column-major square from diagonal_start_[s], in double.
  std::vector<int> diagonal_start_;
  std::vector<double> diagonal_;
  /// Its rows below the diagonal block, rows_[rows_start_[s] ...], and their entries, rows × w row-major
  /// from below_start_[s], in single precision.
  std::vector<int> rows_start_;
  std::vector<int> rows_;
  std::vector<int> below_start_;
  std::vector<float> below_;
};

}  // namespace friction
