#include "friction_sim/solvers/static_solver.h"

#include "solvers/cholesky_factor.h"
#include "solvers/grid_multigrid.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace friction {

namespace {
/// Relative residual at which a multigrid solve stops; the modified-Newton loop corrects the rest.
constexpr double kMultigridTolerance = 1e-10;

/// The stiffness of the free degrees of freedom (`position_in_free` is −1 for a fixed one). The
/// model's matrix is compacted in place (entries only move towards the front) rather than copied into
/// a second matrix: a 10⁶-node lattice's stiffness takes 450 MB. Trimming the storage to its new size
/// still reallocates once. `lower_only` keeps the lower triangle, all the factorisation reads.
SparseMatrix freeStiffness(const Model& model, const std::vector<int>& lifted_nodes,
                           const std::vector<int>& position_in_free, int free_count, bool lower_only) {
  SparseMatrix stiffness = model.stiffnessMatrix();
  for (int node : lifted_nodes) model.releaseContact(stiffness, node);
  stiffness.makeCompressed();
  int* outer = stiffness.outerIndexPtr();
  int* inner = stiffness.innerIndexPtr();
  double* value = stiffness.valuePtr();
  int written = 0;
  int column_start = outer[0];
  for (int column = 0; column < stiffness.outerSize(); ++column) {
    const int column_end = outer[column + 1];
    const int col = position_in_free[column];
    if (col >= 0) {
      outer[col] = written;  // col ≤ column: that start has been read already
      for (int k = column_start; k < column_end; ++k) {
        const int row = position_in_free[inner[k]];
        if (row < (lower_only ? col : 0)) continue;
        inner[written] = row;
        value[written++] = value[k];
      }
    }
    column_start = column_end;
  }
  outer[free_count] = written;
  stiffness.data().resize(written);
  stiffness.conservativeResize(free_count, free_count);
  stiffness.makeCompressed();
  if (lower_only) stiffness.data().squeeze();
  return stiffness;
}

/// `vector`'s entries at `indices`, in their order.
Vector entriesAt(const Eigen::Ref<const Vector>& vector, const std::vector<int>& indices) {
  Vector out(indices.size());
  for (std::size_t i = 0; i < indices.size(); ++i) out[i] = vector[indices[i]];
  return out;
}

/// `matrix`'s rows at `indices`, in their order.
Eigen::MatrixXd rowsAt(const Eigen::MatrixXd& matrix, const std::vector<int>& indices) {
  Eigen::MatrixXd out(indices.size(), matrix.cols());
  for (std::size_t r = 0; r < indices.size(); ++r) out.row(r) = matrix.row(indices[r]);
  return out;
}

/// The model's dofs as a grid of nodes (every model is one: the chain's is n × 1).
GridLayout gridLayoutOf(const Model& model) {
  const auto shape = model.gridShape();
  return {shape[0], shape[1], model.componentsPerNode()};
}
}  // namespace

StaticSolver::StaticSolver(const Model& model, const std::vector<int>& fixed_dofs, bool balance_load,
                           StaticMethod method, const std::vector<int>& lifted_nodes)
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
  const int free_count = static_cast<int>(free_dofs_.size());
  const GridLayout layout = gridLayoutOf(model);
  if (method == StaticMethod::kAuto) {
    // A chain's factor has no fill-in: only a 2D grid gains from multigrid.
    const bool grid_2d = layout.nodes_x > 2 && layout.nodes_z > 2;
    method = free_count > kDirectSolveDofs && grid_2d ? StaticMethod::kMultigrid : StaticMethod::kDirect;
  }
  if (method == StaticMethod::kMultigrid) {
    // Not make_unique: it would pass the matrix on by reference, and Eigen 3.4's sparse matrices,
    // having no move constructor, would be copied (360 MB at 10⁶ nodes).
    multigrid_.reset(
        new GridMultigrid(freeStiffness(model, lifted_nodes, position_in_free, free_count, false), free_dofs_, layout));
    return;
  }
  const SparseMatrix reduced = freeStiffness(model, lifted_nodes, position_in_free, free_count, true);
  factor_ = std::make_unique<CholeskyFactor>(reduced);
}

Vector StaticSolver::response(const Vector& force) const { return response(force, false); }

Vector StaticSolver::response(const Vector& force, bool single_precision) const {
  const Vector solution = reducedResponse(entriesAt(force, free_dofs_), single_precision);
  Vector out = Vector::Zero(force.size());
  for (std::size_t i = 0; i < free_dofs_.size(); ++i) out[free_dofs_[i]] = solution[i];
  return out;
}

Vector StaticSolver::reducedResponse(const Vector& reduced, bool single_precision) const {
  Vector solution;
  if (multigrid_) {
    solution = multigrid_->solve(reduced, kMultigridTolerance);
  } else if (factor_) {
    solution = single_precision ? factor_->solveSinglePrecision(reduced) : factor_->solve(reduced);
  } else {
    solution = reduced;  // no free degree of freedom
  }
  addSpringsTo(solution);
  return solution;
}

void StaticSolver::addSpringsTo(Eigen::Ref<Vector> solution) const {
  if (spring_positions_.empty()) return;
  // (K + U·D·Uᵀ)⁻¹·f = x − W·(D⁻¹ + Uᵀ·W)⁻¹·Uᵀ·x with x = K⁻¹·f and W = K⁻¹·U.
  const Eigen::VectorXd at_springs = entriesAt(solution, spring_positions_);
  solution -= spring_response_ * capacitance_.solve(at_springs);
}

Eigen::MatrixXd StaticSolver::responses(const Eigen::MatrixXd& forces) const {
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(forces.rows(), forces.cols());
  if (!factor_) {
    for (Eigen::Index c = 0; c < forces.cols(); ++c) out.col(c) = response(forces.col(c));
    return out;
  }
  Eigen::MatrixXd solved = factor_->solveColumns(rowsAt(forces, free_dofs_));
  for (Eigen::Index c = 0; c < forces.cols(); ++c) {
    addSpringsTo(solved.col(c));
    for (std::size_t i = 0; i < free_dofs_.size(); ++i) out(free_dofs_[i], c) = solved(i, c);
  }
  return out;
}

Eigen::MatrixXd StaticSolver::unitResponses(const std::vector<int>& positions, bool single_precision) const {
  Eigen::MatrixXd units = Eigen::MatrixXd::Zero(free_dofs_.size(), positions.size());
  for (std::size_t c = 0; c < positions.size(); ++c) units(positions[c], c) = 1.0;
  Eigen::MatrixXd responses =
      single_precision ? factor_->solveColumnsSinglePrecision(units) : factor_->solveColumns(units);
  for (Eigen::Index c = 0; c < responses.cols(); ++c) addSpringsTo(responses.col(c));
  return responses;
}

void StaticSolver::addLocalChange(const LocalStiffness& change, Vector& solution) const {
  std::vector<int> positions, rows;  // the free ones among the change's dofs, and their rows in it
  for (std::size_t r = 0; r < change.dofs.size(); ++r) {
    const auto at = std::lower_bound(free_dofs_.begin(), free_dofs_.end(), change.dofs[r]);
    if (at == free_dofs_.end() || *at != change.dofs[r]) continue;
    positions.push_back(static_cast<int>(at - free_dofs_.begin()));
    rows.push_back(static_cast<int>(r));
  }
  if (positions.empty()) return;
  const int count = static_cast<int>(positions.size());
  if (positions != change_positions_) {
    change_positions_ = positions;
    // Through the single-precision factor: an error in W, its condition number times about 6·10⁻⁸, only
    // slows the corrections by that times the change (about 1 % of the springs' stiffness) and leaves
    // their fixed point alone.
    change_response_ = unitResponses(positions, true);
    change_response_at_ = rowsAt(change_response_, positions);
  }
  // (K + U·M·Uᵀ)⁻¹·f = x − W·(I + M·Uᵀ·W)⁻¹·M·Uᵀ·x with x = K⁻¹·f and W = K⁻¹·U; M need not be definite.
  Eigen::MatrixXd change_here(count, count);
  for (int r = 0; r < count; ++r) {
    for (int c = 0; c < count; ++c) change_here(r, c) = change.matrix(rows[r], rows[c]);
  }
  const Eigen::VectorXd at_change = entriesAt(solution, positions);
  const Eigen::MatrixXd capacitance = Eigen::MatrixXd::Identity(count, count) + change_here * change_response_at_;
  const Eigen::VectorXd at_response = capacitance.partialPivLu().solve(change_here * at_change);
  // A singular capacitance (a tangent that lost its definiteness) leaves the factored stiffness alone.
  if (!at_response.allFinite()) return;
  solution.noalias() -= change_response_ * at_response;
}

std::unique_ptr<StaticSolver> StaticSolver::withAddedSprings(std::unique_ptr<StaticSolver> base,
                                                             const Vector& added_stiffness) {
  std::vector<int> positions;
  std::vector<double> stiffness;
  for (std::size_t i = 0; i < base->free_dofs_.size(); ++i) {
    const double k = added_stiffness[base->free_dofs_[i]];
    if (k == 0.0) continue;
    positions.push_back(static_cast<int>(i));
    stiffness.push_back(k);
  }
  if (!base->factor_ || positions.size() > static_cast<std::size_t>(kMostAddedSprings) ||
      !base->spring_positions_.empty()) {
    return nullptr;
  }
  base->balance_load_ = false;
  if (positions.empty()) return base;
  Eigen::MatrixXd response = base->unitResponses(positions, false);
  Eigen::MatrixXd capacitance = rowsAt(response, positions);
  for (std::size_t r = 0; r < positions.size(); ++r) capacitance(r, r) += 1.0 / stiffness[r];
  base->capacitance_.compute(capacitance);
  if (base->capacitance_.info() != Eigen::Success) return nullptr;
  base->spring_positions_ = std::move(positions);
  base->spring_response_ = std::move(response);
  base->change_positions_.clear();  // their responses were the base's alone
  return base;
}

double StaticSolver::correct(const Model& model, Vector& u, double stage_position, const Vector& body_force) const {
  return correct(model, u, stage_position, body_force, true);
}

double StaticSolver::correct(const Model& model, Vector& u, double stage_position, const Vector& body_force,
                             bool single_precision) const {
  if (free_dofs_.empty()) return 0.0;
  ForceEvaluation evaluation;
  model.evaluate(u, Vector::Zero(u.size()), stage_position, evaluation);
  if (body_force.size() > 0) evaluation.force += body_force;
  Vector correction = reducedResponse(entriesAt(evaluation.force, free_dofs_), single_precision);
  if (factor_) addLocalChange(model.stiffnessChangeAtPusher(u), correction);
  for (std::size_t i = 0; i < free_dofs_.size(); ++i) u[free_dofs_[i]] += correction[i];
  return correction.lpNorm<Eigen::Infinity>();
}

int StaticSolver::solve(Model& model, Vector& u, double stage_position, const Vector& body_force) const {
  if (free_dofs_.empty()) return 0;
  // Modified Newton converges linearly: each correction about `ratio` times the last, so about
  // correction·ratio/(1 − ratio) is left after this one. Stopping on that estimate spares the solve
  // whose only use would be to show a correction below the tolerance. The ratio is the larger of the
  // last two, and none is taken across a change of the top load (another problem).
  double last_correction = 0.0, last_ratio = kLargestTrustedRatio;
  bool single_precision = true;
  for (int iteration = 1; iteration <= kMaxIterations; ++iteration) {
    const double correction = correct(model, u, stage_position, body_force, single_precision);
    if (!std::isfinite(correction)) return kMaxIterations + 1;  // no later correction would be finite
    const bool load_changed = balance_load_ && model.rebalanceLoad(u);
    const bool measured = last_correction > 0.0 && std::isfinite(last_correction);
    const double ratio = measured ? correction / last_correction : kLargestTrustedRatio;
    // The single-precision factor's error (its condition number times about 6·10⁻⁸) would bound the
    // contraction of an ill-conditioned stiffness: corrections that stop halving go on in double.
    if (measured && ratio > kLargestTrustedRatio) single_precision = false;
    const double trusted = std::max(ratio, last_ratio);
    const double left = trusted < kLargestTrustedRatio ? correction * trusted / (1.0 - trusted) : correction;
    if (!load_changed && left < tolerance_) return iteration;
    last_correction = load_changed ? 0.0 : correction;
    last_ratio = load_changed ? kLargestTrustedRatio : ratio;
  }
  return kMaxIterations + 1;
}

StaticSolver::~StaticSolver() = default;

int StaticSolver::multigridIterations() const { return multigrid_ ? multigrid_->lastIterations() : 0; }

std::size_t StaticSolver::directFactorBytes() const { return factor_ ? factor_->bytes() : 0; }

}  // namespace friction
