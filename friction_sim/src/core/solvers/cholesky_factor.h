// The direct method's Cholesky factor: SuiteSparse's AMD ordering, the core's own supernodal analysis and
// numeric factorisation (dense blocks by Eigen), and triangular sweeps in double for exact solves and
// through a single-precision copy for the modified-Newton corrections.
#pragma once

#include <vector>

#include "friction_sim/model/model.h"

namespace friction {

class CholeskyFactor {
 public:
  /// Factors `lower`, the lower triangle of a symmetric matrix. Throws std::runtime_error if it is not
  /// positive definite.
  explicit CholeskyFactor(const SparseMatrix& lower);

  /// matrix⁻¹·rhs in double precision.
  Vector solve(const Vector& rhs) const;

  /// solve() of each column of `rhs`, to the same bits: up to kColumnsPerSweep columns per sweep of the
  /// factor, each with the same operations in the same order as solve() gives it.
  Eigen::MatrixXd solveColumns(const Eigen::MatrixXd& rhs) const;
  /// Columns that solveColumns carries through one sweep at most: right-hand sides that stay in cache at
  /// the sizes that factor (0.5 MB at 57 × 31, 7 MB at 225 × 121).
  static constexpr int kColumnsPerSweep = 16;

  /// matrix⁻¹·rhs through the factor's entries below its diagonal blocks rounded to single precision
  /// (sums in double): a relative error of about the condition number times 6·10⁻⁸. A solve streams the
  /// whole factor twice and waits on memory; 4 bytes per entry instead of 8 make it faster, and a
  /// modified-Newton loop, whose residual is evaluated in double, converges to the same equilibrium.
  Vector solveSinglePrecision(const Vector& rhs) const;
  /// solveSinglePrecision() of each column of `rhs`, to the same bits, as solveColumns() does solve().
  Eigen::MatrixXd solveColumnsSinglePrecision(const Eigen::MatrixXd& rhs) const;

  /// Bytes held: the factor in double and its single-precision copy.
  std::size_t bytes() const;

 private:
  /// Columns per block of a solve at most (a solve keeps one block's partial sums on the stack).
  static constexpr int kWidestBlock = 32;

  /// L·Lᵀ·x = P·rhs solved with the entries below block b's diagonal block read from below_entries from
  /// below_start[b].
  template <typename Entry>
  Vector sweep(const std::vector<Entry>& below_entries, const std::vector<std::size_t>& below_start,
               const Vector& rhs) const;
  /// sweep() on y = P·rhs in place, whose rows are lanes: a double, or an Eigen array of several
  /// right-hand sides' values.
  template <typename Entry, typename Lane>
  void sweepInPlace(const std::vector<Entry>& below_entries, const std::vector<std::size_t>& below_start,
                    Lane* y) const;

  /// sweep() of each column of `rhs`, up to kColumnsPerSweep columns per sweep.
  template <typename Entry>
  Eigen::MatrixXd sweepAllColumns(const std::vector<Entry>& below_entries, const std::vector<std::size_t>& below_start,
                                  const Eigen::MatrixXd& rhs) const;
  /// sweep() of `count` ≤ Width columns of `rhs` from `first`, into the same of `solution`: one sweep of
  /// Width columns, those past `count` zero. With Width fixed, a row's sums stay in vector registers.
  template <int Width, typename Entry>
  void sweepColumns(const std::vector<Entry>& below_entries, const std::vector<std::size_t>& below_start,
                    const Eigen::MatrixXd& rhs, int first, int count, Eigen::MatrixXd& solution) const;

  /// The factor's row k belongs to the matrix's row fill_order_[k] (the fill-reducing ordering).
  std::vector<int> fill_order_;
  /// The factor in blocks of columns that share one pattern below their own diagonal block (the
  /// supernodes, cut to kWidestBlock columns), so that a solve reads one list of rows per block and
  /// touches each of those rows once per block, not once per column. Block b spans columns
  /// [first_column_[b], first_column_[b + 1]); its rows below the diagonal block are
  /// rows_[rows_start_[b] ... rows_start_[b + 1]). These two hold one entry more than there are blocks;
  /// the entries' starts below hold one per block.
  std::vector<int> first_column_;
  std::vector<int> rows_start_;
  std::vector<int> rows_;
  /// In entries_, block b's diagonal block (lower triangle of a w × w column-major square) from
  /// diagonal_start_[b] and its entries below it (rows × w row-major) from below_start_[b], in double.
  /// entries_ is the numeric factorisation's storage, its blocks written over its panels: it keeps the
  /// panels' capacity, a little more than the blocks take (bytes() counts it).
  std::vector<double> entries_;
  std::vector<std::size_t> diagonal_start_;
  std::vector<std::size_t> below_start_;
  /// The entries below the diagonal blocks in single precision, block b's from below_single_start_[b].
  std::vector<float> below_single_;
  std::vector<std::size_t> below_single_start_;
};

}  // namespace friction
