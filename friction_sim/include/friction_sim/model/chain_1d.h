// The 1D chain of MODEL.md §3: N blocks along x joined by springs k = E·H·B/a with neighbour damping
// η, driven at the side (pusher K on block 0) or from the top (K/N on every block). The normal force
// per block is w_i = (F_Z/N)(1 + θξ_i) + c·ξ_i with ξ_i = 2X_i/L − 1 and the friction-induced torque
// c = 2·g·h·F_X/(L·Σξ²). With one block it is the single block on a spring.
#pragma once

#include <vector>

#include "friction_sim/model/model.h"

namespace friction {

class Chain1D : public Model {
 public:
  explicit Chain1D(const Scene& scene);

  double springStiffness() const { return k_; }  ///< N/m, k (0 for a single block)
  double dampingRate() const { return eta_; }    ///< kg/s, η
  double spacing() const { return spacing_; }    ///< m, a

  /// N, the normal force on every block for a given pusher force F_X.
  std::vector<double> normalForces(double shear_force) const;

  int dofCount() const override { return n_; }
  double nodeMass() const override { return mass_; }
  int interfaceNodeCount() const override { return n_; }
  int interfaceDof(int node) const override { return node; }
  double interfacePosition(int node) const override { return node * spacing_; }
  double interfaceNodeArea() const override { return area_per_block_; }

  void evaluateInto(const Vector& u, const Vector& v, double stage_position, Vector& force,
                    ForceEvaluation& out) const override;
  /// Strips of `strip_nodes` blocks when driven at the side: F_X, and with it every normal force, is
  /// known once block 0 is prepared. Top driving sums every block's driving force into F_X first, so it
  /// is evaluated in one strip.
  void evaluateInStrips(const Vector& u, const Vector& v, double stage_position, Vector& force, ForceEvaluation& out,
                        StripHooks& hooks, int strip_nodes) const override;
  /// normalForces() at the evaluation's F_X.
  Vector signedNormalForces(const Vector& u, const ForceEvaluation& evaluation) const override;
  double elasticEnergy(const Vector& u, double stage_position) const override;
  double externalWork(const Vector&, const Vector&) const override { return 0.0; }
  SparseMatrix stiffnessMatrix() const override;
  NodeStiffness nodeStiffness() const override;
  /// Nothing: a block's normal force is prescribed by the loads, not carried by a contact spring.
  void releaseContact(SparseMatrix&, int) const override {}
  SparseMatrix dampingMatrix() const override;
  Vector anchorStiffness() const override { return driving_stiffness_.matrix(); }
  /// The free chain's largest, 2k(1 + cos(π/N)) (exact), and 2η(1 + cos(π/N)).
  double bondStiffnessBound() const override { return k_ * chainLaplacianTop(); }
  double dampingBound() const override { return eta_ * chainLaplacianTop(); }
  std::vector<int> blockedDofsDuringLoading() const override;
  Vector initialBodyForce() const override;
  void disconnectPusher() override;
  void connectPusher(const Vector& u) override;
  double pushingHeight() const override { return pushing_height_; }
  void setNormalLoad(double normal_force) override { normal_force_ = normal_force; }
  GaugeStresses gaugeStresses(const Vector&, double, const std::vector<double>&) const override {
    return {};  // the chain has no vertical dimension: the interface frame is its only stress reading
  }
  void nodePositions(const Vector& u, std::vector<double>& x, std::vector<double>& z) const override;
  std::vector<double> nodeSpeeds(const Vector& v) const override;
  GaugeStresses nodeStresses(const Vector&) const override;
  std::array<int, 2> gridShape() const override { return {n_, 1}; }
  double nodeSpacing() const override { return spacing_; }

 private:
  void updateDrivingStiffness();
  /// The largest eigenvalue of the free chain's unit-coupling Laplacian.
  double chainLaplacianTop() const;
  /// Adds the stiffness matrix's entries, add(row, col, value), to a matrix being assembled.
  template <class Add>
  void addStiffness(Add&& add) const {
    addNeighbourCoupling(add, k_);
    for (int i = 0; i < n_; ++i) add(i, i, driving_stiffness_[i]);
  }
  /// Adds the coupling `coefficient` (N/m or kg/s) of every neighbour pair to a matrix being assembled.
  template <class Add>
  void addNeighbourCoupling(Add&& add, double coefficient) const {
    for (int i = 0; i + 1 < n_; ++i) {
      add(i, i, coefficient);
      add(i + 1, i + 1, coefficient);
      add(i, i + 1, -coefficient);
      add(i + 1, i, -coefficient);
    }
  }
  void evaluateTopDriven(const Vector& u, const Vector& v, double stage_position, Vector& force,
                         ForceEvaluation& out) const;
  void evaluateSideDriven(const Vector& u, const Vector& v, double stage_position, Vector& force, ForceEvaluation& out,
                          StripHooks& hooks, int strip_nodes) const;
  /// w_i (N) of blocks [first, first + count) at the given F_X (N), before clamping at 0, as an Eigen
  /// expression: no allocation for the callers that store it.
  auto normalForceExpression(double shear_force, int first, int count) const;
  /// Writes the normal forces (N), w_i clamped at 0, of blocks [first, first + count) into `normal_forces`.
  void writeNormalForces(double shear_force, int first, int count, Vector& normal_forces) const;
  /// N, c = 2·g·h·F_X/(L·Σξ²), the friction-induced torque's share of each block's normal force per ξ.
  double torqueCoefficient(double shear_force) const;

  int n_;
  double length_, spacing_, mass_, k_, eta_, area_per_block_;
  bool top_driving_;
  double pusher_k_;
  double pushing_height_;
  double tilt_, torque_share_;
  double normal_force_;
  Eigen::ArrayXd xi_;
  double xi_square_sum_;
  Eigen::ArrayXd tilt_factor_;  ///< 1 + θξ_i per block
  std::vector<double> initial_shear_;
  Vector pusher_offset_;  ///< m, u of each block when the pusher was connected
  bool pusher_connected_ = true;
  Eigen::ArrayXd driving_stiffness_;  ///< N/m per block, 0 where the pusher does not act
};

}  // namespace friction
