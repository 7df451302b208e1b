// Static equilibrium of the slider with some degrees of freedom held fixed, by modified Newton: the
// linearised stiffness of the free degrees of freedom is factored once (a supernodal Cholesky factor) and
// corrects the residual of the full (geometric, one-sided) forces until they balance (through the factor
// rounded to single precision: the residual, in double, sets the equilibrium), with the springs around
// the pusher's point load at their tangent. Used for the
// loading protocol and, with the interface pinned, for the quasi-static fast-forward. A lattice too
// large for the factor's memory is solved by multigrid-preconditioned conjugate gradients instead.
#pragma once

#include <Eigen/Cholesky>
#include <memory>
#include <vector>

#include "friction_sim/model/model.h"

namespace friction {

class CholeskyFactor;
class GridMultigrid;

/// How the linearised stiffness is inverted.
enum class StaticMethod {
  kAuto,       ///< direct up to kDirectSolveDofs free degrees of freedom, multigrid above
  kDirect,     ///< a sparse Cholesky factor (CholeskyFactor)
  kMultigrid,  ///< conjugate gradients with a geometric multigrid V-cycle (grid models only)
};

/// Free degrees of freedom up to which kAuto factors: a 2D factor takes about 110 non-zeros per
/// degree of freedom at 10⁶ nodes (2.2 GB), multigrid about 30 (a few matrix copies).
constexpr int kDirectSolveDofs = 400000;

class StaticSolver {
 public:
  /// Factors the stiffness of every degree of freedom not in `fixed_dofs`, as the model is now
  /// (pusher connected or not), without the contact stiffness of the interface nodes in `lifted_nodes`.
  /// With `balance_load`, a displacement-controlled top load (the spring mattress) is re-balanced to carry
  /// F_Z while solving, as when the load is applied. Throws std::runtime_error if that stiffness is singular.
  StaticSolver(const Model& model, const std::vector<int>& fixed_dofs, bool balance_load = false,
               StaticMethod method = StaticMethod::kAuto, const std::vector<int>& lifted_nodes = {});
  ~StaticSolver();

  /// `base` turned into the solver of the same free degrees of freedom with springs added to some of them
  /// (`added_stiffness`, N/m per dof of the model, 0 where none), by Woodbury's identity: one solve of
  /// `base` per added spring instead of a factorisation. The result does not re-balance a top load.
  /// Null, `base` spent, where a factorisation is the better way: `base` is not a direct factor (a
  /// multigrid solve per spring, and a dense column of every dof per spring, at 10⁶ nodes), more than
  /// kMostAddedSprings are added, or `base` has springs added already.
  static std::unique_ptr<StaticSolver> withAddedSprings(std::unique_ptr<StaticSolver> base,
                                                        const Vector& added_stiffness);
  /// Added springs up to which withAddedSprings corrects rather than factors again.
  static constexpr int kMostAddedSprings = 16;

  /// Modified-Newton iterations after which solve() gives up.
  static constexpr int kMaxIterations = 500;
  /// The ratio of successive corrections below which solve() trusts its estimate of what is left.
  static constexpr double kLargestTrustedRatio = 0.5;

  /// Moves the free degrees of freedom of `u` to equilibrium with the stage at `stage_position` (m)
  /// and the extra forces `body_force` (N per dof; empty = none). The fixed ones stay as they are.
  /// It stops once what is left, estimated from the last two corrections, is below tolerance(): 10⁻¹⁴ of
  /// as many node spacings as the model has nodes along x (about the slider's length). Returns the number
  /// of iterations, kMaxIterations + 1 if it did not converge.
  int solve(Model& model, Vector& u, double stage_position, const Vector& body_force = Vector()) const;

  /// One iteration of solve(), without re-balancing a top load: for a state already near equilibrium,
  /// whose residual it reduces by the factor's error (10⁻² or less on the 2D lattice, measured at 113 × 61
  /// with the double factor; the single-precision copy adds about 10⁻⁸ at 225 × 121). With a direct
  /// factor, the stiffness it inverts is the factored one plus the model's stiffnessChangeAtPusher() at
  /// `u`, by Woodbury's identity: the springs around a point load are where most of that error comes
  /// from. Returns the largest displacement it corrected (m).
  double correct(const Model& model, Vector& u, double stage_position, const Vector& body_force = Vector()) const;

  /// Displacement of the free degrees of freedom per unit of a force vector on them (K_ff⁻¹·f).
  Vector response(const Vector& force) const;
  /// response() of each column of `forces`, to the same bits. The direct method solves the columns
  /// together, several per sweep of its factor.
  Eigen::MatrixXd responses(const Eigen::MatrixXd& forces) const;

  const std::vector<int>& freeDofs() const { return free_dofs_; }
  /// m, what solve() may leave of a free degree of freedom's displacement.
  double tolerance() const { return tolerance_; }
  /// Conjugate-gradient iterations of the last multigrid solve (0 with the direct method).
  int multigridIterations() const;
  /// Bytes the direct method's factor holds; 0 with multigrid.
  std::size_t directFactorBytes() const;

 private:
  /// response() on the free degrees of freedom alone; `single_precision` solves through the factor
  /// rounded to single precision (the direct method only; see CholeskyFactor).
  Vector reducedResponse(const Vector& reduced, bool single_precision = false) const;
  /// response(), through the single-precision factor if `single_precision`.
  Vector response(const Vector& force, bool single_precision) const;
  /// Turns the factored stiffness's response on the free degrees of freedom into that of the stiffness
  /// with the springs of withAddedSprings (none: unchanged).
  void addSpringsTo(Eigen::Ref<Vector> solution) const;
  /// The responses (free dofs) to a unit force at each free position in `positions`, one column each.
  /// Needs the direct method's factor (its callers check for one).
  Eigen::MatrixXd unitResponses(const std::vector<int>& positions, bool single_precision) const;
  /// Turns `solution`, the factored stiffness's response on the free degrees of freedom, into that of the
  /// stiffness changed by `change` (those of its dofs that are free), by Woodbury's identity.
  void addLocalChange(const LocalStiffness& change, Vector& solution) const;
  /// correct(), through the single-precision factor if `single_precision`.
  double correct(const Model& model, Vector& u, double stage_position, const Vector& body_force,
                 bool single_precision) const;

  std::vector<int> free_dofs_;
  std::unique_ptr<CholeskyFactor> factor_;    ///< the direct method's
  std::unique_ptr<GridMultigrid> multigrid_;  ///< or the iterative one's
  /// Springs added by withAddedSprings: their positions among the free degrees of freedom, the factored
  /// matrix's response to a unit force at each (one column each), and the Cholesky factor of the
  /// capacitance matrix diag(1/k) + (those responses at those positions).
  std::vector<int> spring_positions_;
  Eigen::MatrixXd spring_response_;
  Eigen::LLT<Eigen::MatrixXd> capacitance_;
  /// For addLocalChange: the free positions of the dofs of the last change, the response to a unit
  /// force at each (one column each, with any added springs) and its rows at them. Made on first use
  /// (so correct() is not for several threads at once): a solver may never need them (a loading without
  /// the pusher), and they cost a single-precision solve per dof.
  mutable std::vector<int> change_positions_;
  mutable Eigen::MatrixXd change_response_;
  mutable Eigen::MatrixXd change_response_at_;
  double tolerance_;
  bool balance_load_;
};

}  // namespace friction
