#include "solvers/cholesky_factor.h"

#include <amd.h>

#include <Eigen/Dense>
#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <type_traits>
#include <utility>

namespace friction {

namespace {
/// The widths whose loops over columns are unrolled: the narrow blocks, which are nearly all.
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

/// A pattern by columns: column k's rows are rows[start[k] ... start[k + 1]).
struct Pattern {
  std::vector<int> start, rows;
  int size() const { return static_cast<int>(start.size()) - 1; }
};

/// A triangle of P·A·Pᵀ (A = `lower`'s symmetric matrix, P an ordering) by columns, with its values
/// (none for the upper triangle's shape: see Triangle).
struct PermutedTriangle : Pattern {
  std::vector<double> values;
};

/// Each index's position in `order`.
std::vector<int> positionsIn(const std::vector<int>& order) {
  std::vector<int> position(order.size());
  for (std::size_t k = 0; k < order.size(); ++k) position[order[k]] = static_cast<int>(k);
  return position;
}

/// Which triangle of an ordered matrix permute() gives.
enum class Triangle {
  kLower,       ///< each column's rows at or below it, with their values
  kUpperShape,  ///< each column's rows above it, without values: the elimination tree and the column
                ///< counts need neither values nor an order within a column
};

/// `lower`'s symmetric matrix ordered by `order` (row k of the result is the matrix's row order[k]), by
/// columns of `triangle`.
PermutedTriangle permute(const SparseMatrix& lower, const std::vector<int>& order, Triangle triangle) {
  const int n = static_cast<int>(order.size());
  const std::vector<int> position = positionsIn(order);
  const bool upper = triangle == Triangle::kUpperShape;
  // visit(column, row, value) for each entry of the triangle, the matrix's columns in turn.
  const auto forEachEntry = [&](auto&& visit) {
    for (int j = 0; j < n; ++j) {
      for (SparseMatrix::InnerIterator it(lower, j); it; ++it) {
        const int a = position[it.row()], b = position[j];
        if (upper && a == b) continue;
        visit(upper ? std::max(a, b) : std::min(a, b), upper ? std::min(a, b) : std::max(a, b), it.value());
      }
    }
  };
  PermutedTriangle permuted;
  permuted.start.assign(n + 1, 0);
  forEachEntry([&](int column, int, double) { ++permuted.start[column + 1]; });
  for (int k = 0; k < n; ++k) permuted.start[k + 1] += permuted.start[k];
  std::vector<int> next(permuted.start.begin(), permuted.start.end() - 1);
  permuted.rows.resize(permuted.start[n]);
  if (!upper) permuted.values.resize(permuted.start[n]);
  forEachEntry([&](int column, int row, double value) {
    const int at = next[column]++;
    permuted.rows[at] = row;
    if (!upper) permuted.values[at] = value;
  });
  return permuted;
}

/// The elimination tree: parent[j] is the first row below j in column j of the factor (−1 at a root).
std::vector<int> eliminationTree(const Pattern& above) {
  const int n = above.size();
  std::vector<int> parent(n, -1), ancestor(n, -1);
  for (int k = 0; k < n; ++k) {
    for (int at = above.start[k]; at < above.start[k + 1]; ++at) {
      int i = above.rows[at];
      // Up from i to the root of its subtree so far, compressing the path to k on the way.
      while (i != -1 && i < k) {
        const int up = ancestor[i];
        ancestor[i] = k;
        if (up == -1) parent[i] = k;
        i = up;
      }
    }
  }
  return parent;
}

/// Each column's count of entries in the factor: row k has an entry in every column on the tree's
/// paths from the columns of its entries left of the diagonal up to k.
std::vector<int> columnCounts(const Pattern& above, const std::vector<int>& parent) {
  const int n = above.size();
  std::vector<int> count(n, 1), mark(n, -1);
  for (int k = 0; k < n; ++k) {
    mark[k] = k;
    for (int at = above.start[k]; at < above.start[k + 1]; ++at) {
      for (int j = above.rows[at]; mark[j] != k; j = parent[j]) {
        mark[j] = k;
        ++count[j];
      }
    }
  }
  return count;
}

/// The tree's nodes in postorder (every subtree's nodes consecutive), each node's children by
/// ascending `weight`: the heaviest child comes last, next to its parent, where the two can share a
/// supernode.
std::vector<int> postorder(const std::vector<int>& parent, const std::vector<int>& weight) {
  const int n = static_cast<int>(parent.size());
  std::vector<int> by_weight(n);
  std::iota(by_weight.begin(), by_weight.end(), 0);
  std::sort(by_weight.begin(), by_weight.end(),
            [&](int a, int b) { return weight[a] != weight[b] ? weight[a] > weight[b] : a > b; });
  std::vector<int> first_child(n, -1), next_sibling(n, -1), order, stack;
  for (int j : by_weight) {
    if (parent[j] == -1) continue;
    next_sibling[j] = first_child[parent[j]];
    first_child[parent[j]] = j;
  }
  order.reserve(n);
  for (int root = 0; root < n; ++root) {
    if (parent[root] != -1) continue;
    stack.push_back(root);
    while (!stack.empty()) {
      const int top = stack.back();
      const int child = first_child[top];
      if (child == -1) {
        order.push_back(top);
        stack.pop_back();
      } else {
        first_child[top] = next_sibling[child];  // visited: the next child comes next time
        stack.push_back(child);
      }
    }
  }
  return order;
}

/// What the numeric factorisation needs: the fill-reducing ordering (SuiteSparse's AMD, then the
/// elimination tree's postorder), the matrix in that order, and the factor's supernodes, runs of
/// columns stored together as one dense column-major panel. Relaxed as CHOLMOD relaxes them: a few
/// explicit zeros buy wider panels, whose updates are dense matrix products. Every solve reads the zeros
/// too (at 57 × 31 the panels hold 16 % more entries than the fundamental supernodes would), but solves
/// swept over the fundamental supernodes left a 225 × 121 run to the first global event as fast (9.04
/// against 9.05 s, 4 interleaved rounds, 2026-11-27, AMD EPYC family 25).
struct Analysis {
  std::vector<int> fill_order;    ///< the factor's row k is the matrix's row fill_order[k]
  PermutedTriangle matrix;        ///< the lower triangle in that order
  std::vector<int> first_column;  ///< supernode s spans columns [first_column[s], first_column[s + 1])
  std::vector<int> supernode_of;  ///< each column's supernode
  std::vector<int> rows_start;    ///< its rows rows[rows_start[s] ...], its own columns first
  std::vector<int> rows;
  std::vector<std::size_t> panel_start;  ///< its panel, rows × columns, from panel_start[s]

  int supernodes() const { return static_cast<int>(first_column.size()) - 1; }
  int width(int s) const { return first_column[s + 1] - first_column[s]; }
  int height(int s) const { return rows_start[s + 1] - rows_start[s]; }
};

/// Whether a supernode of `columns` columns with `zeros` of its `entries` explicit is worth its zeros
/// (CHOLMOD's default relaxation).
bool relaxedEnough(int columns, double zeros, double entries) {
  const double fraction = zeros / entries;
  return columns <= 4 || (columns <= 16 && fraction < 0.8) || (columns <= 48 && fraction < 0.1) || fraction < 0.05;
}

Analysis analyse(const SparseMatrix& lower) {
  const int n = static_cast<int>(lower.rows());
  Analysis analysis;
  analysis.first_column = {0};
  analysis.rows_start = {0};
  analysis.panel_start = {0};
  if (n == 0) return analysis;  // amd_order refuses empty arrays
  std::vector<int> minimum_degree(n);
  {
    const SparseMatrix compressed = lower.isCompressed() ? SparseMatrix() : SparseMatrix(lower);
    const SparseMatrix& matrix = lower.isCompressed() ? lower : compressed;
    double control[AMD_CONTROL], info[AMD_INFO];
    amd_defaults(control);
    const int status =
        amd_order(n, matrix.outerIndexPtr(), matrix.innerIndexPtr(), minimum_degree.data(), control, info);
    if (status != AMD_OK && status != AMD_OK_BUT_JUMBLED) {
      throw std::runtime_error("static solve: AMD could not order the stiffness matrix");
    }
  }
  const PermutedTriangle above_in_amd_order = permute(lower, minimum_degree, Triangle::kUpperShape);
  const std::vector<int> tree_parent = eliminationTree(above_in_amd_order);
  const std::vector<int> tree_count = columnCounts(above_in_amd_order, tree_parent);
  const std::vector<int> post = postorder(tree_parent, tree_count);
  const std::vector<int> position = positionsIn(post);
  std::vector<int> parent(n), count(n), children(n, 0);
  analysis.fill_order.resize(n);
  for (int k = 0; k < n; ++k) {
    analysis.fill_order[k] = minimum_degree[post[k]];
    parent[k] = tree_parent[post[k]] == -1 ? -1 : position[tree_parent[post[k]]];
    count[k] = tree_count[post[k]];
    if (parent[k] != -1) ++children[parent[k]];
  }
  analysis.matrix = permute(lower, analysis.fill_order, Triangle::kLower);
  // Fundamental supernodes: a column continues the one before when that column is its only child and
  // its pattern is the child's without it.
  struct Run {
    int first, columns;
    int height;    ///< rows of its first column, its own columns included
    double zeros;  ///< explicit zeros
  };
  std::vector<Run> fundamental;
  for (int first = 0; first < n;) {
    int end = first + 1;
    while (end < n && parent[end - 1] == end && children[end] == 1 && count[end] == count[end - 1] - 1) ++end;
    fundamental.push_back({first, end - first, count[first], 0.0});
    first = end;
  }
  // Relaxed from the root down: a fundamental supernode whose last column's parent is the next column
  // (it is its parent's last child) joins the supernode that parent is in while relaxedEnough. The
  // child's rows below its columns lie in its parent's pattern, so the merged first column's rows are
  // the child's columns and the parent supernode's first column's rows.
  const auto entries = [](int columns, int height) {
    return static_cast<double>(columns) * height - 0.5 * static_cast<double>(columns) * (columns - 1);
  };
  std::vector<Run> relaxed;  // from the root down
  for (auto child = fundamental.rbegin(); child != fundamental.rend(); ++child) {
    const int last = child->first + child->columns - 1;
    if (!relaxed.empty() && parent[last] == last + 1) {
      Run& parent_run = relaxed.back();
      const Run merged{child->first, child->columns + parent_run.columns, child->columns + parent_run.height,
                       parent_run.zeros +
                           entries(child->columns + parent_run.columns, child->columns + parent_run.height) -
                           entries(child->columns, child->height) - entries(parent_run.columns, parent_run.height)};
      if (relaxedEnough(merged.columns, merged.zeros, entries(merged.columns, merged.height))) {
        parent_run = merged;
        continue;
      }
    }
    relaxed.push_back(*child);
  }
  analysis.supernode_of.resize(n);
  for (auto run = relaxed.rbegin(); run != relaxed.rend(); ++run) {
    std::fill(analysis.supernode_of.begin() + run->first, analysis.supernode_of.begin() + run->first + run->columns,
              analysis.supernodes());
    analysis.first_column.push_back(run->first + run->columns);
  }
  // A supernode's rows below its columns are those of its matrix columns and of its children's
  // patterns (the children listed from first_child through next_child).
  const int supernodes = analysis.supernodes();
  std::vector<int> first_child(supernodes, -1), next_child(supernodes, -1), mark(n, -1), below;
  for (int s = 0; s < supernodes; ++s) {
    const int first = analysis.first_column[s], end = analysis.first_column[s + 1];
    below.clear();
    const auto add = [&](int row) {
      if (row >= end && mark[row] != s) {
        mark[row] = s;
        below.push_back(row);
      }
    };
    for (int at = analysis.matrix.start[first]; at < analysis.matrix.start[end]; ++at) add(analysis.matrix.rows[at]);
    for (int child = first_child[s]; child != -1; child = next_child[child]) {
      for (int at = analysis.rows_start[child]; at < analysis.rows_start[child + 1]; ++at) add(analysis.rows[at]);
    }
    std::sort(below.begin(), below.end());
    for (int k = first; k < end; ++k) analysis.rows.push_back(k);
    analysis.rows.insert(analysis.rows.end(), below.begin(), below.end());
    analysis.rows_start.push_back(static_cast<int>(analysis.rows.size()));
    analysis.panel_start.push_back(analysis.panel_start.back() +
                                   static_cast<std::size_t>(analysis.height(s)) * analysis.width(s));
    if (parent[end - 1] != -1) {
      const int parent_supernode = analysis.supernode_of[parent[end - 1]];
      next_child[s] = first_child[parent_supernode];
      first_child[parent_supernode] = s;
    }
  }
  return analysis;
}

using Panel = Eigen::Map<Eigen::MatrixXd>;

/// Eigen cuts a dense product's sums into blocks sized from the L1 cache it reads off the CPU, so the
/// factor's round-off, and every result after it, would depend on the machine (32 and 48 KiB L1 give
/// different bits). The sizes of a common x86 core make them the same everywhere. Eigen keeps them for
/// the whole process; the core's other dense work does not block by cache.
void useMachineIndependentBlocking() {
  static const bool set = (Eigen::setCpuCacheSizes(32 * 1024, 512 * 1024, 32 * 1024 * 1024), true);
  static_cast<void>(set);
}

/// The numeric factorisation, left-looking by supernodes: each supernode's panel gathers the matrix's
/// columns, subtracts the updates of the supernodes below it in the elimination tree that reach its
/// columns (one dense product each), then factors its diagonal block and solves the rows below it.
/// Returns the panels.
std::vector<double> factorise(const Analysis& analysis) {
  const int n = static_cast<int>(analysis.fill_order.size()), supernodes = analysis.supernodes();
  const PermutedTriangle& matrix = analysis.matrix;
  std::vector<double> panels(analysis.panel_start[supernodes], 0.0);
  // Supernodes waiting to update supernode s: a list from pending[s] through next_pending; each knows
  // where its rows reach s's columns (reached[d]).
  std::vector<int> pending(supernodes, -1), next_pending(supernodes, -1), reached(supernodes, 0);
  const auto enqueue = [&](int d, int row_position) {
    reached[d] = row_position;
    if (row_position == analysis.height(d)) return;
    const int target = analysis.supernode_of[analysis.rows[analysis.rows_start[d] + row_position]];
    next_pending[d] = pending[target];
    pending[target] = d;
  };
  std::vector<int> row_in_panel(n), target_rows;
  Eigen::MatrixXd update;
  for (int s = 0; s < supernodes; ++s) {
    const int first = analysis.first_column[s], end = analysis.first_column[s + 1], width = end - first;
    const int height = analysis.height(s);
    const int* rows = analysis.rows.data() + analysis.rows_start[s];
    Panel panel(panels.data() + analysis.panel_start[s], height, width);
    for (int r = 0; r < height; ++r) row_in_panel[rows[r]] = r;
    for (int k = first; k < end; ++k) {
      for (int at = matrix.start[k]; at < matrix.start[k + 1]; ++at) {
        panel(row_in_panel[matrix.rows[at]], k - first) = matrix.values[at];
      }
    }
    for (int d = pending[s]; d != -1;) {
      const int after = next_pending[d];
      const int d_height = analysis.height(d);
      const int* d_rows = analysis.rows.data() + analysis.rows_start[d];
      const int top = reached[d];
      int inside = top;
      while (inside < d_height && d_rows[inside] < end) ++inside;
      const Panel d_panel(panels.data() + analysis.panel_start[d], d_height, analysis.width(d));
      const int below = d_height - top, across = inside - top;
      update.noalias() = d_panel.middleRows(top, below) * d_panel.middleRows(top, across).transpose();
      target_rows.resize(below);
      for (int i = 0; i < below; ++i) target_rows[i] = row_in_panel[d_rows[top + i]];
      for (int j = 0; j < across; ++j) {
        double* column = &panel(0, d_rows[top + j] - first);
        for (int i = j; i < below; ++i) column[target_rows[i]] -= update(i, j);
      }
      enqueue(d, inside);
      d = after;
    }
    Eigen::Ref<Eigen::MatrixXd> diagonal_block = panel.topRows(width);
    const Eigen::LLT<Eigen::Ref<Eigen::MatrixXd>> in_place(diagonal_block);
    if (in_place.info() != Eigen::Success || !diagonal_block.diagonal().allFinite()) {
      throw std::runtime_error("static solve: the stiffness matrix is singular");
    }
    diagonal_block.triangularView<Eigen::Lower>().transpose().solveInPlace<Eigen::OnTheRight>(
        panel.bottomRows(height - width));
    enqueue(s, width);
  }
  return panels;
}
}  // namespace

CholeskyFactor::CholeskyFactor(const SparseMatrix& lower) {
  useMachineIndependentBlocking();
  Analysis analysis = analyse(lower);
  entries_ = factorise(analysis);
  analysis.matrix = PermutedTriangle();  // freed before the single-precision copy is made
  fill_order_ = analysis.fill_order;
  // Each supernode in blocks of at most kWidestBlock columns; a block's rows below its diagonal block
  // are the rest of its supernode's columns and the supernode's rows below them.
  first_column_ = {0};
  rows_start_ = {0};
  std::size_t written = 0, written_single = 0;
  for (int s = 0; s < analysis.supernodes(); ++s) {
    const int first = analysis.first_column[s], end = analysis.first_column[s + 1];
    for (int block_first = first; block_first < end; block_first += kWidestBlock) {
      const int block_end = std::min(block_first + kWidestBlock, end), width = block_end - block_first;
      const std::size_t below_count = analysis.height(s) - (block_end - first);
      first_column_.push_back(block_end);
      rows_start_.push_back(rows_start_.back() + static_cast<int>(below_count));
      diagonal_start_.push_back(written);
      below_start_.push_back(written + static_cast<std::size_t>(width) * width);
      written = below_start_.back() + below_count * width;
      below_single_start_.push_back(written_single);
      written_single += below_count * width;
    }
  }
  // The blocks are written over the panels: a supernode's blocks take no more room than its panel (each
  // block leaves out the rows above its own columns), so they end before its panel ends, and they read
  // nothing but that panel, copied aside first. The rows and the single-precision copy are sized at
  // once: growing by doubling could hold twice them while they are filled (hundreds of MB).
  rows_.resize(rows_start_.back());
  below_single_.resize(written_single);
  std::vector<double> panel;
  std::size_t block = 0;
  for (int s = 0; s < analysis.supernodes(); ++s) {
    const int first = analysis.first_column[s], height = analysis.height(s);
    const int* rows = analysis.rows.data() + analysis.rows_start[s];
    const auto panel_begin = entries_.begin() + static_cast<std::ptrdiff_t>(analysis.panel_start[s]);
    panel.assign(panel_begin, panel_begin + static_cast<std::ptrdiff_t>(height) * analysis.width(s));
    for (; block + 1 < first_column_.size() && first_column_[block] < analysis.first_column[s + 1]; ++block) {
      const int offset = first_column_[block] - first, width = first_column_[block + 1] - first_column_[block];
      double* diagonal = entries_.data() + diagonal_start_[block];
      for (int c = 0; c < width; ++c) {
        for (int r = 0; r < width; ++r)
          diagonal[c * width + r] = r < c ? 0.0 : panel[(offset + c) * height + offset + r];
      }
      std::copy(rows + offset + width, rows + height, rows_.begin() + rows_start_[block]);
      double* below = entries_.data() + below_start_[block];
      float* below_single = below_single_.data() + below_single_start_[block];
      for (int r = offset + width; r < height; ++r) {
        for (int c = 0; c < width; ++c)
          *below_single++ = static_cast<float>(*below++ = panel[(offset + c) * height + r]);
      }
    }
  }
  entries_.resize(written);
}

namespace {
/// A lane's zero: one right-hand side's value (double) or several side by side (an Eigen array).
double zeroLane(double) { return 0.0; }
template <int Width>
Eigen::Array<double, Width, 1> zeroLane(const Eigen::Array<double, Width, 1>&) {
  return Eigen::Array<double, Width, 1>::Zero();
}
/// Rows whose sums the forward sweep adds up together: four scalar chains; a lane of several right-hand
/// sides is already several chains, and more of them would not fit the vector registers.
template <typename Lane>
constexpr int kRowsAtOnce = std::is_same_v<Lane, double> ? 4 : 1;

/// Subtracts from y, at rows[0 ... Rows), each row's sum over the block's w columns of its entries in
/// `below` (row-major) times part[]: each row's terms added in column order, the Rows chains side by side.
template <int Rows, typename Entry, typename Lane>
void subtractRowSums(const Entry* below, int w, const Lane* part, const int* rows, Lane* y) {
  Lane sum[Rows];
  for (Lane& each : sum) each = zeroLane(part[0]);
  for (int c = 0; c < w; ++c) {
    for (int k = 0; k < Rows; ++k) sum[k] += static_cast<double>(below[k * w + c]) * part[c];
  }
  for (int k = 0; k < Rows; ++k) y[rows[k]] -= sum[k];
}
}  // namespace

template <typename Entry, typename Lane>
void CholeskyFactor::sweepInPlace(const std::vector<Entry>& below_entries, const std::vector<std::size_t>& below_start,
                                  Lane* y) const {
  // Every operation is on whole lanes: each right-hand side in a lane of several sees the operations, in
  // the order, that it sees alone (the core is built with -ffp-contract=off, so none is fused either).
  const int blocks = static_cast<int>(first_column_.size()) - 1;
  // One block's part of y, kept apart: the compiler cannot tell it from the rows below it.
  Lane part[kWidestBlock];
  for (int b = 0; b < blocks; ++b) {  // L·y = P·rhs
    const int first = first_column_[b], width = first_column_[b + 1] - first;
    const double* diagonal = entries_.data() + diagonal_start_[b];
    for (int c = 0; c < width; ++c) part[c] = y[first + c];
    for (int c = 0; c < width; ++c) {
      const Lane yc = (part[c] /= diagonal[c * width + c]);
      for (int r = c + 1; r < width; ++r) part[r] -= diagonal[c * width + r] * yc;
      y[first + c] = yc;
    }
    forEachWidth(width, [&](auto fixed_width) {
      const int w = widthOf(fixed_width, width);
      const Entry* below = below_entries.data() + below_start[b];
      // A row's sum is a chain of dependent additions; several rows at a time keep several chains in
      // flight. Each still adds its terms in column order.
      int r = rows_start_[b];
      const int end = rows_start_[b + 1];
      for (; r + kRowsAtOnce<Lane> <= end; r += kRowsAtOnce<Lane>, below += kRowsAtOnce<Lane> * w) {
        subtractRowSums<kRowsAtOnce<Lane>>(below, w, part, rows_.data() + r, y);
      }
      for (; r < end; ++r, below += w) subtractRowSums<1>(below, w, part, rows_.data() + r, y);
    });
  }
  for (int b = blocks - 1; b >= 0; --b) {  // Lᵀ·z = y
    const int first = first_column_[b], width = first_column_[b + 1] - first;
    for (int c = 0; c < width; ++c) part[c] = y[first + c];
    forEachWidth(width, [&](auto fixed_width) {
      const int w = widthOf(fixed_width, width);
      const Entry* below = below_entries.data() + below_start[b];
      for (int r = rows_start_[b]; r < rows_start_[b + 1]; ++r, below += w) {
        const Lane yr = y[rows_[r]];
        for (int c = 0; c < w; ++c) part[c] -= static_cast<double>(below[c]) * yr;
      }
    });
    const double* diagonal = entries_.data() + diagonal_start_[b];
    for (int c = width - 1; c >= 0; --c) {
      // Summed apart from part[]: the compiler would otherwise store part[c] at every term.
      Lane value = part[c];
      for (int r = c + 1; r < width; ++r) value -= diagonal[c * width + r] * part[r];
      y[first + c] = part[c] = value / diagonal[c * width + c];
    }
  }
}

template <typename Entry>
Vector CholeskyFactor::sweep(const std::vector<Entry>& below_entries, const std::vector<std::size_t>& below_start,
                             const Vector& rhs) const {
  const int n = static_cast<int>(fill_order_.size());
  Vector y(n);
  for (int k = 0; k < n; ++k) y[k] = rhs[fill_order_[k]];
  sweepInPlace(below_entries, below_start, y.data());
  Vector solution(n);
  for (int k = 0; k < n; ++k) solution[fill_order_[k]] = y[k];
  return solution;
}

Vector CholeskyFactor::solve(const Vector& rhs) const { return sweep(entries_, below_start_, rhs); }

Eigen::MatrixXd CholeskyFactor::solveColumns(const Eigen::MatrixXd& rhs) const {
  return sweepAllColumns(entries_, below_start_, rhs);
}

Vector CholeskyFactor::solveSinglePrecision(const Vector& rhs) const {
  return sweep(below_single_, below_single_start_, rhs);
}

Eigen::MatrixXd CholeskyFactor::solveColumnsSinglePrecision(const Eigen::MatrixXd& rhs) const {
  return sweepAllColumns(below_single_, below_single_start_, rhs);
}

template <typename Entry>
Eigen::MatrixXd CholeskyFactor::sweepAllColumns(const std::vector<Entry>& below_entries,
                                                const std::vector<std::size_t>& below_start,
                                                const Eigen::MatrixXd& rhs) const {
  Eigen::MatrixXd solution(rhs.rows(), rhs.cols());
  const int columns = static_cast<int>(rhs.cols());
  for (int first = 0; first < columns; first += kColumnsPerSweep) {
    const int count = std::min(kColumnsPerSweep, columns - first);
    if (count <= 4) {
      sweepColumns<4>(below_entries, below_start, rhs, first, count, solution);
    } else if (count <= 8) {
      sweepColumns<8>(below_entries, below_start, rhs, first, count, solution);
    } else {
      sweepColumns<kColumnsPerSweep>(below_entries, below_start, rhs, first, count, solution);
    }
  }
  return solution;
}

template <int Width, typename Entry>
void CholeskyFactor::sweepColumns(const std::vector<Entry>& below_entries, const std::vector<std::size_t>& below_start,
                                  const Eigen::MatrixXd& rhs, int first, int count, Eigen::MatrixXd& solution) const {
  // A row's values side by side, so that every operation runs across the columns (vector instructions).
  using Lane = Eigen::Array<double, Width, 1>;
  const int n = static_cast<int>(fill_order_.size());
  std::vector<Lane> y(n, Lane::Zero());
  for (int k = 0; k < n; ++k) y[k].head(count) = rhs.row(fill_order_[k]).segment(first, count).transpose();
  sweepInPlace(below_entries, below_start, y.data());
  for (int k = 0; k < n; ++k) solution.row(fill_order_[k]).segment(first, count) = y[k].head(count).transpose();
}

std::size_t CholeskyFactor::bytes() const {
  return (fill_order_.size() + first_column_.size() + rows_start_.size() + rows_.size()) * sizeof(int) +
         (diagonal_start_.size() + below_start_.size() + below_single_start_.size()) * sizeof(std::size_t) +
         entries_.capacity() * sizeof(double) + below_single_.size() * sizeof(float);
}

}  // namespace friction
