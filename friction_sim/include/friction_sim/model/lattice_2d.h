// The 2D ("1+1D") slider of MODEL.md §2: a square lattice of N_x × N_z nodes in the x–z plane with
// neighbour springs k, diagonal springs k/2, pair damping η, a one-sided foundation k_f under the
// bottom row, a top load (uniform or spring mattress) and the pusher K on the trailing edge.
//
// Degrees of freedom: u = [u_x of every node, u_z of every node], node (i, j) has index j·N_x + i.
#pragma once

#include <array>
#include <atomic>
#include <vector>

#include "friction_sim/model/model.h"

namespace friction {

/// The row a pusher at `height` (m) above the interface acts on: the nearest of `rows` rows `spacing`
/// (m) apart.
int nearestRow(double height, double spacing, int rows);
/// The rows of `rows` rows `spacing` (m) apart that the pusher acts on: those within its band, or the
/// row nearest its height (nearestRow). Empty for a band that holds no row, which a valid scene has not.
std::vector<int> pushedRowsOf(const PusherSpec& pusher, double spacing, int rows);

class Lattice2D : public Model {
 public:
  explicit Lattice2D(const Scene& scene);

  int nodesX() const { return nx_; }
  int nodesZ() const { return nz_; }
  double spacing() const { return spacing_; }    ///< m, l
  double springStiffness() const { return k_; }  ///< N/m, k
  /// N/m, k = (3/4)·B·E: the horizontal and vertical bonds' stiffness that gives the scene's E (MODEL.md §2).
  static double springStiffness(const Scene& scene) {
    return 0.75 * scene.geometry.width * scene.material.youngs_modulus;
  }
  /// Pa, the lattice's shear modulus G = 3E/8 (ν = 1/3, MODEL.md §7.3).
  static double shearModulus(const Scene& scene) { return 3.0 / 8.0 * scene.material.youngs_modulus; }
  double dampingRate() const { return eta_; }  ///< kg/s, η
  int nodeIndex(int i, int j) const { return j * nx_ + i; }
  int xDof(int node) const { return node; }
  int zDof(int node) const { return n_ + node; }
  const std::vector<int>& pushedRows() const { return pushed_rows_; }

  int dofCount() const override { return 2 * n_; }
  double nodeMass() const override { return mass_; }
  int interfaceNodeCount() const override { return nx_; }
  int interfaceDof(int node) const override { return xDof(node); }
  double interfacePosition(int node) const override { return node * spacing_; }
  double interfaceNodeArea() const override { return spacing_ * width_; }

  void evaluateInto(const Vector& u, const Vector& v, double stage_position, Vector& force,
                    ForceEvaluation& out) const override;
  /// Strips of whole rows; the external forces on a row are added before it is finished.
  void evaluateInStrips(const Vector& u, const Vector& v, double stage_position, Vector& force, ForceEvaluation& out,
                        StripHooks& hooks, int strip_nodes) const override;
  /// Each evaluation sweeps a strip or two behind the one before, through that one's finished rows.
  int evaluateSuccessiveInStrips(int strip_nodes,
                                 const std::function<std::optional<StripEvaluation>(int)>& next) const override;
  /// 1 while threads sweep each evaluation (setThreads): the steps are then taken one at a time.
  int successiveEvaluations() const override { return threadedBlocks() > 1 ? 1 : kSuccessiveSweeps; }
  /// Threads for lattices of kThreadedNodes nodes or more: each sweeps a block of whole bands of rows.
  void setThreads(int threads) override;
  /// The row blocks an evaluation is split into, one per thread (1: no threads).
  int threadedBlocks() const;
  /// The first row of block `block` of `blocks` (nodesZ() for block == blocks): whole bands of rows.
  int firstRowOfBlock(int block, int blocks) const;
  /// Rows over which the viscous power is summed column by column before the bands are added up in
  /// order: a thread's block is whole bands, so the sum is the same whatever the blocks.
  static constexpr int kPowerBandRows = 8;
  static_assert(kPowerBandRows >= 3, "a block reads two rows beyond its first before its seam's wait");
  /// Below this many nodes a second thread gains little. A step on two threads against one (ns per
  /// node-step, medians of 5 interleaved, AMD EPYC Zen 1, 2026-11-26/27): 29 × 16 about 1.1×, 33 × 31
  /// 1.16×, 57 × 31 1.56×, 113 × 61 1.55×, 225 × 121 1.70×, 449 × 241 1.87×.
  static constexpr int kThreadedNodes = 1000;
  /// The foundation's force k_f·(−u_z) on each bottom node.
  Vector signedNormalForces(const Vector& u, const ForceEvaluation& evaluation) const override;
  double elasticEnergy(const Vector& u, double stage_position) const override;
  double externalWork(const Vector& u_from, const Vector& u_to) const override;
  SparseMatrix stiffnessMatrix() const override;
  NodeStiffness nodeStiffness() const override;
  /// The foundation's k_f on the node's u_z.
  void releaseContact(SparseMatrix& stiffness, int node) const override;
  /// Up to kMostRowsForLocalTangent pushed rows; a band pushed wider spreads its load.
  LocalStiffness stiffnessChangeAtPusher(const Vector& u) const override;
  static constexpr int kMostRowsForLocalTangent = 2;
  SparseMatrix dampingMatrix() const override;
  Vector anchorStiffness() const override;
  /// 6k: the infinite lattice's largest, at the wave vector (π/l, 0).
  double bondStiffnessBound() const override { return 6.0 * k_; }
  /// 12η: the infinite lattice's largest, at the wave vector (π/l, 0).
  double dampingBound() const override { return 12.0 * eta_; }
  bool rebalanceLoad(const Vector& u) override;
  /// Every bottom node's x (InterfaceLoading::Stuck), or only the middle one's, which takes out the
  /// free slider's rigid translation and carries no force (InterfaceLoading::Free).
  std::vector<int> blockedDofsDuringLoading() const override;
  void disconnectPusher() override { pusher_connected_ = false; }
  void connectPusher(const Vector& u) override;
  double pushingHeight() const override;
  void setNormalLoad(double normal_force) override { normal_force_ = normal_force; }
  /// Not with the spring mattress: its plate is placed once, when F_Z is applied. Moving it by
  /// ΔF_Z/(N_x·k_m) would not do: the slider yields under it, and the springs end up carrying a fraction
  /// of the change (in a 29 × 16 slider, 49 N of 580 N asked).
  bool takesNormalLoadChanges() const override { return !mattress_; }
  GaugeStresses gaugeStresses(const Vector& u, double height, const std::vector<double>& positions) const override;
  void nodePositions(const Vector& u, std::vector<double>& x, std::vector<double>& z) const override;
  std::vector<double> nodeSpeeds(const Vector& v) const override;
  GaugeStresses nodeStresses(const Vector& u) const override;
  std::array<int, 2> gridShape() const override { return {nx_, nz_}; }
  double nodeSpacing() const override { return spacing_; }

  /// Pa, cell-average (virial) stress of cell (i, j) spanning nodes i..i+1, j..j+1, from the spring
  /// forces: σ = (1/(l²B)) Σ w·T·r̂⊗r, edges weighted ½ (shared with the neighbour cell), diagonals 1.
  std::array<double, 3> cellStress(const Vector& u, int i, int j) const;

 private:
  /// Adds the stiffness matrix's entries, add(row, col, value), to a matrix being assembled.
  template <class Add>
  void addStiffness(Add&& add) const;
  /// One family of bonds: all springs from node (i, j) to (i + di, j + dj).
  struct BondFamily {
    int di, dj;
    double stiffness;    ///< N/m
    double rest_length;  ///< m
    double ex, ez;       ///< rest unit vector
  };

  /// The tension rule of a bond of `family` whose vector is now (rx, rz) (m), its far node displaced by
  /// (dux, duz) (m) relative to its near one: the geometric spring acts along the bond as it is, the
  /// linearised one along its rest direction. The force sweep writes the rule out inline, where it
  /// vectorises (bondRow).
  struct BondTension {
    double stretch;             ///< m, length − rest length (linearised: along the rest direction)
    double tension_per_length;  ///< N/m
  };
  BondTension bondTension(const BondFamily& family, double rx, double rz, double dux, double duz) const;

  template <class Visit>
  void forEachBond(const BondFamily& family, Visit&& visit) const;
  double topSpringForce(const Vector& u, int i) const;

  int nx_, nz_, n_;
  double spacing_, width_, mass_, k_, eta_, kf_;
  bool geometric_;
  std::vector<BondFamily> families_;
  double normal_force_;
  bool mattress_;
  bool interface_free_while_loading_;
  double mattress_k_, mattress_kx_per_node_;
  double plate_z_ = 0.0;              ///< m, displacement of the mattress plate
  double last_plate_move_ = 0.0;      ///< m, rebalanceLoad's last move of the plate (0: none yet)
  double last_excess_ = 0.0;          ///< N, the load carried beyond F_Z before that move
  std::vector<double> top_anchor_x_;  ///< m, where the mattress holds each top node in x
  std::vector<int> pushed_rows_;
  double pusher_k_per_row_;
  std::vector<double> pusher_offset_;  ///< m, u_x of each pushed node when the pusher was connected
  bool pusher_connected_ = true;
  /// The bond forces (N, on the bond's lower-index node) from a row up to the next, zero-padded so that
  /// the node loop needs no edge cases.
  struct RowBonds {
    std::vector<double> vertical_x, vertical_z, diagonal_x, diagonal_z, antidiagonal_x, antidiagonal_z;
    void resize(int size);
    void clear();
  };
  /// Work space of one force sweep: the bond forces along the row being swept (padded the same way), the
  /// upward bond forces of the current row and of the row below, and the viscous power (W) summed per
  /// column over the current band of rows. Eigen's storage for the power: Eigen sums aligned packets and
  /// adds the unaligned ends apart, so in a buffer of std::vector's alignment the total's last bits
  /// would depend on where the heap put it.
  struct SweepSpace {
    std::vector<double> horizontal_x, horizontal_z;
    RowBonds upward, below;
    Eigen::ArrayXd column_power;
  };
  /// What one evaluation adds up once its rows are swept, in the order of the rows: each band's viscous
  /// power (W) and each pushed row's pusher force (N).
  struct EvaluationSums {
    std::vector<double> band_power, pusher_force;
    double top_normal = 0.0;  ///< N, the mattress's springs on the top row
  };
  /// What the sweeps of two neighbouring row blocks tell each other: the upper one has prepared the rows
  /// at the seam and read their state, and the lower one has swept its last row (read the upper one's
  /// first row for the last time).
  struct alignas(64) BlockHandoff {  // a cache line each: the threads poll them
    std::atomic<bool> seam_prepared{false}, lower_swept{false};
  };
  /// One force evaluation, row by row (lattice_2d.cpp).
  class Sweep;
  /// One evaluation swept by `blocks` threads, each a block of rows.
  void sweepInBlocks(const StripEvaluation& evaluation, int strip_nodes, int blocks) const;
  /// Sweeps that run at once (evaluateSuccessiveInStrips), each a strip or two behind the one before. At
  /// 10⁶ nodes, interleaved in one process (fastest of 15–25 rounds, 2026-11-24): 2 sweeps 4.91 ns per
  /// node-step, 3 4.70, 4 4.66, 6 4.88 (strips of 1024 nodes), 8 5.12; 4 cost a 1001 × 61 lattice 4 % more
  /// than 2 (likely their row buffers, 100 kB a sweep at that width, crowding the L2 cache), 3 the same.
  static constexpr int kSuccessiveSweeps = 3;
  int threads_ = 1;
  /// Each successive sweep's or each thread's own work space, and each successive evaluation's sums.
  mutable std::vector<SweepSpace> sweep_space_;
  mutable std::array<EvaluationSums, kSuccessiveSweeps> sums_;
  /// Between thread k's block and thread k + 1's.
  mutable std::vector<BlockHandoff> handoffs_;
};

}  // namespace friction
