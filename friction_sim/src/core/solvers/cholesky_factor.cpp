#include "solvers/cholesky_factor.h"

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <type_traits>
#include <utility>

namespace friction {

namespace {
/// The widths whose loops over columns are unrolled: the narrow supernodes, which are nearly all.
constexpr int kUnrolledWidths = 8;

/// Calls `body` with std::integral_constant<int, width> for widths 1 to kUnrolledWidths, with
/// std::integral_constant<int, 0> otherwise.
template <typename Body, int... Widths>
void forEachWidth(int width, Body&& body, std::integer_sequence<int, Widths...>) {
  const bool unrolled = ((width == Widths + 1 && (body(std::integral_constant<int, Widths + 1>()), true)) || ...);
  if (!unrolled) body(std::integral_constant<int, 0>());
}

template <typename Body>
void forEachWidth(int width, Body&& body) {
  forEachWidth(width, body, std::make_integer_sequence<int, kUnrolledWidths>());
}

/// The width forEachWidth's body works with: the fixed one, or `width` where none is fixed.
template <typename FixedWidth>
int widthOf(FixedWidth, int width) {
  return FixedWidth::value > 0 ? FixedWidth::value : width;
}
}  // namespace

CholeskyFactor::CholeskyFactor(const SparseMatrix& lower) : cholmod_(lower) {
  if (cholmod_.info() != Eigen::Success) throw std::runtime_error("static solve: the stiffness matrix is singular");
  const cholmod_factor& factor = cholmod_.factor();
  if (factor.is_super || !factor.is_ll || factor.xtype != CHOLMOD_REAL || factor.itype != CHOLMOD_INT) {
    throw std::logic_error("CholeskyFactor: CHOLMOD did not give a simplicial real LLᵀ factor with int indices");
  }
  const int n = static_cast<int>(factor.n);
  const int* perm = static_cast<const int*>(factor.Perm);
  if (perm) {
    fill_order_.assign(perm, perm + n);
  } else {  // the natural ordering
    fill_order_.resize(n);
    std::iota(fill_order_.begin(), fill_order_.end(), 0);
  }
  // A simplicial factor's columns need not be packed: column j holds nz[j] entries from p[j], the
  // diagonal first, its rows ascending.
  const int* start = static_cast<const int*>(factor.p);
  const int* count = static_cast<const int*>(factor.nz);
  const int* row = static_cast<const int*>(factor.i);
  const double* value = static_cast<const double*>(factor.x);
  // Column j + 1 continues column j's supernode when its pattern below the diagonal is column j's
  // without row j + 1.
  const auto continues = [&](int j) {
    return count[j + 1] == count[j] - 1 && count[j] > 1 && row[start[j] + 1] == j + 1 &&
           std::equal(row + start[j] + 2, row + start[j] + count[j], row + start[j + 1] + 1);
  };
  first_column_ = {0};
  diagonal_start_ = {0};
  rows_start_ = {0};
  below_start_ = {0};
  for (int first = 0; first < n;) {
    int width = 1;
    while (first + width < n && width < kWidestSupernode && continues(first + width - 1)) ++width;
    const int below_count = count[first] - width;
    first += width;
    first_column_.push_back(first);
    diagonal_start_.push_back(diagonal_start_.back() + width * width);
    rows_start_.push_back(rows_start_.back() + below_count);
    below_start_.push_back(below_start_.back() + below_count * width);
  }
  // Sized at once: growing by doubling could hold twice the copy while it is made (hundreds of MB).
  diagonal_.assign(diagonal_start_.back(), 0.0);
  rows_.resize(rows_start_.back());
  below_.resize(below_start_.back());
  for (std::size_t s = 0; s + 1 < first_column_.size(); ++s) {
    const int first = first_column_[s], width = first_column_[s + 1] - first;
    for (int c = 0; c < width; ++c) {
      const int column_start = start[first + c];
      for (int r = c; r < width; ++r) diagonal_[diagonal_start_[s] + c * width + r] = value[column_start + r - c];
    }
    std::copy(row + start[first] + width, row + start[first] + count[first], rows_.begin() + rows_start_[s]);
    float* below = below_.data() + below_start_[s];
    for (int r = 0; r < rows_start_[s + 1] - rows_start_[s]; ++r) {
      for (int c = 0; c < width; ++c) *below++ = static_cast<float>(value[start[first + c] + width - c + r]);
    }
  }
}

Vector CholeskyFactor::solve(const Vector& rhs) const { return cholmod_.solve(rhs); }

std::size_t CholeskyFactor::bytes() const {
  return cholmod_.factor().nzmax * (sizeof(double) + sizeof(int)) + fill_order_.size() * sizeof(int) +
         (first_column_.size() + diagonal_start_.size() + rows_start_.size() + below_start_.size() + rows_.size()) *
             sizeof(int) +
         diagonal_.size() * sizeof(double) + below_.size() * sizeof(float);
}

Vector CholeskyFactor::solveSinglePrecision(const Vector& rhs) const {
  const int n = static_cast<int>(fill_order_.size());
  Vector y(n);
  for (int k = 0; k < n; ++k) y[k] = rhs[fill_order_[k]];
  const int supernodes = static_cast<int>(first_column_.size()) - 1;
  // One supernode's part of y, kept apart: the compiler cannot tell it from the rows below it.
  double part[kWidestSupernode];
  for (int s = 0; s < supernodes; ++s) {  // L·y = P·rhs
    const int first = first_column_[s], width = first_column_[s + 1] - first;
    const double* diagonal = diagonal_.data() + diagonal_start_[s];
    for (int c = 0; c < width; ++c) part[c] = y[first + c];
    for (int c = 0; c < width; ++c) {
      const double yc = (part[c] /= diagonal[c * width + c]);
      for (int r = c + 1; r < width; ++r) part[r] -= diagonal[c * width + r] * yc;
      y[first + c] = yc;
    }
    forEachWidth(width, [&](auto fixed_width) {
      const int w = widthOf(fixed_width, width);
      const float* below = below_.data() + below_start_[s];
      for (int r = rows_start_[s]; r < rows_start_[s + 1]; ++r, below += w) {
        double sum = 0.0;
        for (int c = 0; c < w; ++c) sum += below[c] * part[c];
        y[rows_[r]] -= sum;
      }
    });
  }
  for (int s = supernodes - 1; s >= 0; --s) {  // Lᵀ·z = y
    const int first = first_column_[s], width = first_column_[s + 1] - first;
    for (int c = 0; c < width; ++c) part[c] = y[first + c];
    forEachWidth(width, [&](auto fixed_width) {
      const int w = widthOf(fixed_width, width);
      const float* below = below_.data() + below_start_[s];
      for (int r = rows_start_[s]; r < rows_start_[s + 1]; ++r, below += w) {
        const double yr = y[rows_[r]];
        for (int c = 0; c < w; ++c) part[c] -= below[c] * yr;
      }
    });
    const double* diagonal = diagonal_.data() + diagonal_start_[s];
    for (int c = width - 1; c >= 0; --c) {
      for (int r = c + 1; r < width; ++r) part[c] -= diagonal[c * width + r] * part[r];
      y[first + c] = part[c] /= diagonal[c * width + c];
    }
  }
  Vector solution(n);
  for (int k = 0; k < n; ++k) solution[fill_order_[k]] = y[k];
  return solution;
}

}  // namespace friction
