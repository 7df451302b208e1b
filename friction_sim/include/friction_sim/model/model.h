// The elastic slider seen by the integrators: degrees of freedom, the forces on them (everything but
// friction, which the contact interface adds), energies and linearised matrices. Implemented by the
// 2D lattice and the 1D chain.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <algorithm>
#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <vector>

#include "friction_sim/scene/scene.h"

namespace friction {

using Vector = Eigen::VectorXd;
using SparseMatrix = Eigen::SparseMatrix<double>;

/// A `size` × `size` sparse matrix summed from the entries `fill(add)` passes to add(row, col, value),
/// at most `entries_per_column` distinct ones per column. Each column's entries go into its own slots
/// of the matrix's storage in the order they come, found by a linear search; then each column is sorted
/// and moved to the front in place. coeffRef's search and shift per addition, and the copy that
/// compressing its storage makes, took a sixth of a small lattice's start-up. Every entry is summed in the
/// order of the additions, as coeffRef sums it. The storage keeps the slots' size (a 2D lattice's columns
/// fill nearly all of theirs); a triplet list of a 10⁶-node lattice would take several times as much.
template <class Fill>
SparseMatrix assembleSparse(int size, int entries_per_column, Fill&& fill) {
  SparseMatrix matrix(size, size);
  matrix.resizeNonZeros(static_cast<Eigen::Index>(size) * entries_per_column);
  int* start = matrix.outerIndexPtr();
  int* rows = matrix.innerIndexPtr();
  double* values = matrix.valuePtr();
  std::vector<int> count(size, 0);
  const auto slot = [entries_per_column](int col) { return static_cast<std::size_t>(col) * entries_per_column; };
  fill([&](int row, int col, double value) {
    int* slot_rows = rows + slot(col);
    int at = 0;
    while (at < count[col] && slot_rows[at] != row) ++at;
    if (at == count[col]) {
      if (at == entries_per_column) throw std::logic_error("assembleSparse: a column has too many entries");
      slot_rows[at] = row;
      values[slot(col) + at] = 0.0;
      ++count[col];
    }
    values[slot(col) + at] += value;
  });
  for (int col = 0; col < size; ++col) {
    // Insertion sort within the slots (a column holds a few entries), then down to the column's start,
    // never past a later column's slots: each column before it holds no more than its slots.
    const std::size_t from = slot(col);
    for (int k = 1; k < count[col]; ++k) {
      const int row = rows[from + k];
      const double value = values[from + k];
      std::size_t to = from + k;
      for (; to > from && rows[to - 1] > row; --to) {
        rows[to] = rows[to - 1];
        values[to] = values[to - 1];
      }
      rows[to] = row;
      values[to] = value;
    }
    if (static_cast<std::size_t>(start[col]) != from) {
      std::copy(rows + from, rows + from + count[col], rows + start[col]);
      std::copy(values + from, values + from + count[col], values + start[col]);
    }
    start[col + 1] = start[col] + count[col];
  }
  matrix.data().resize(start[size]);  // no reallocation: the storage keeps its capacity
  return matrix;
}

/// The diagonal block of a stiffness matrix at each node: 2 × 2 (xx, zz, xz) in 2D, 1 × 1 (xx) for the
/// chain, whose zz and xz are empty.
struct NodeStiffness {
  Vector xx, zz, xz;  ///< N/m, per node
};

/// The node blocks of the matrix that assembleSparse(nodes · components, ..., fill) would give, summed in
/// the same order, without the matrix: degree of freedom d is node d's x, nodes + d node d's z.
template <class Fill>
NodeStiffness collectNodeStiffness(int nodes, int components, Fill&& fill) {
  const int planar = components == 2 ? nodes : 0;
  NodeStiffness blocks{Vector::Zero(nodes), Vector::Zero(planar), Vector::Zero(planar)};
  fill([&blocks, nodes, planar](int row, int col, double value) {
    if (row == col) {
      (row < nodes ? blocks.xx[row] : blocks.zz[row - nodes]) += value;
    } else if (planar > 0 && col == row + nodes) {
      blocks.xz[row] += value;
    }
  });
  return blocks;
}

/// A dense change to a stiffness matrix on a few of its degrees of freedom.
struct LocalStiffness {
  std::vector<int> dofs;   ///< the model's degrees of freedom it acts on
  Eigen::MatrixXd matrix;  ///< N/m, symmetric, one row and column per entry of `dofs`
};

/// What one force evaluation produces; friction is not included.
struct ForceEvaluation {
  Vector force;                ///< N, per degree of freedom
  Vector normal_force;         ///< N, per interface node, ≥ 0 (0 = contact lost)
  double shear_force = 0.0;    ///< N, F_X, the pusher's load-cell reading
  double normal_load = 0.0;    ///< N, F_Z, the normal load cell (positive when pressing down)
  double viscous_power = 0.0;  ///< W, dissipated by the pair damping at the given velocities
};

/// Lets a caller fuse its own passes over the state into a force evaluation, strip by strip, while the
/// strip is in cache: at 10⁶ nodes separate passes are bound by memory bandwidth. Each hook gets a range
/// [first, end) of degrees of freedom; by default they do nothing. With threads (Model::setThreads) the
/// hooks are called from several threads at once, on disjoint ranges and in no set order across them: a
/// hook may touch only its own range's degrees of freedom (and the interface's, which one thread finishes).
class StripHooks {
 public:
  virtual ~StripHooks() = default;
  /// Called before the evaluation reads the state of these degrees of freedom or writes their forces:
  /// the caller may still change them here (the integrator's drift).
  virtual void prepare(int /*first*/, int /*end*/) {}
  /// Called once the forces on these degrees of freedom are final, and so are the normal forces of the
  /// interface nodes among them, and their velocities will not be read again (the closing kick).
  virtual void finish(int /*first*/, int /*end*/) {}
  /// s, the step's closing kick that finish() gives the velocities (0: none; they are final).
  virtual double closingKick() const { return 0.0; }
};

/// One force evaluation of Model::evaluateSuccessiveInStrips: the arguments of evaluateInStrips.
struct StripEvaluation {
  const Vector& u;        ///< m, displacements
  const Vector& v;        ///< m/s, velocities
  double stage_position;  ///< m
  Vector& force;          ///< N, per degree of freedom (resized)
  ForceEvaluation& out;   ///< the rest of the evaluation (its own `force` left alone)
  StripHooks& hooks;
};

/// Stress tensor components at the gauge height, at the gauge positions (tension positive).
struct GaugeStresses {
  std::vector<double> sigma_xx;  ///< Pa
  std::vector<double> sigma_zz;  ///< Pa
  std::vector<double> tau_xz;    ///< Pa
};

class Model {
 public:
  virtual ~Model() = default;

  virtual int dofCount() const = 0;
  virtual double nodeMass() const = 0;  ///< kg, the same for every node or block
  virtual int interfaceNodeCount() const = 0;
  /// Index of the tangential (x) degree of freedom of interface node `node`.
  virtual int interfaceDof(int node) const = 0;
  /// m, rest x position of interface node `node`.
  virtual double interfacePosition(int node) const = 0;
  /// m, rest x position of every interface node.
  std::vector<double> interfacePositions() const;
  /// m², the interface area one node stands for (l·B or a·B), for σ = N/area and τ = f/area.
  virtual double interfaceNodeArea() const = 0;

  /// Forces at displacements u and velocities v with the stage at `stage_position` (m), written to
  /// `force` (N, per degree of freedom; resized), the rest of the evaluation to `out` (whose own `force`
  /// is left alone). The integrators' hot loop passes its acceleration vector as `force`.
  virtual void evaluateInto(const Vector& u, const Vector& v, double stage_position, Vector& force,
                            ForceEvaluation& out) const = 0;
  /// evaluateInto() with `hooks` called on strips of about `strip_nodes` nodes; every degree of freedom is
  /// prepared once and finished once. By default one strip: everything prepared, evaluated, finished.
  virtual void evaluateInStrips(const Vector& u, const Vector& v, double stage_position, Vector& force,
                                ForceEvaluation& out, StripHooks& hooks, int strip_nodes) const;
  /// Force evaluations of successive steps. `next(k)` gives evaluation k: first for k = 0, then for k ≥ 1
  /// once evaluation k − 1's interface forces and friction are final (its strips finished); an empty answer
  /// ends the series, and for k = successiveEvaluations() `next` must give none (it is still called, to
  /// say that the last interface is final). Evaluation k may read the state only as evaluation k − 1's
  /// finish hooks leave it; the sums of every evaluation (shear force, viscous power) are final only once
  /// this returns. `next` may run no force evaluation: the sweeps are under way in the model's work space.
  /// A model may sweep each evaluation a few strips behind the one before, so that a large state crosses
  /// the memory bus once for all of them. Returns how many were evaluated. By default one, as
  /// evaluateInStrips.
  virtual int evaluateSuccessiveInStrips(int strip_nodes,
                                         const std::function<std::optional<StripEvaluation>(int)>& next) const;
  /// The most evaluations evaluateSuccessiveInStrips sweeps the state once for; 1 where sweeping several
  /// together would gain nothing (the chain's state stays in the cache).
  virtual int successiveEvaluations() const { return 1; }
  /// Threads a force evaluation may use (1: the calling thread alone). A model uses them only where they
  /// pay, and its results are the same to the last bit for any count.
  virtual void setThreads(int /*threads*/) {}
  /// The same, with the forces in `out.force`.
  void evaluate(const Vector& u, const Vector& v, double stage_position, ForceEvaluation& out) const {
    evaluateInto(u, v, stage_position, out.force, out);
  }
  /// N, every interface node's normal force before contact clamps it at zero: negative while the node
  /// is off the track. Fast-forward follows it to where a lifted node lands. `evaluation` is that of u.
  virtual Vector signedNormalForces(const Vector& u, const ForceEvaluation& evaluation) const = 0;
  /// J, energy stored in the springs (lattice, foundation, pusher, top load springs).
  virtual double elasticEnergy(const Vector& u, double stage_position) const = 0;
  /// J, work done by the constant external forces (the uniform top load) between two states.
  virtual double externalWork(const Vector& u_from, const Vector& u_to) const = 0;

  /// Stiffness matrix linearised about the rest state, including foundation, pusher and top springs.
  virtual SparseMatrix stiffnessMatrix() const = 0;
  /// The node blocks of stiffnessMatrix(), equal to its entries, without assembling it (the stability
  /// bound reads no more).
  virtual NodeStiffness nodeStiffness() const = 0;
  /// The tangent stiffness at displacements `u` minus stiffnessMatrix(), on the springs among the pushed
  /// nodes and their nearest neighbours: there the pusher's point load strains the springs most, and
  /// their geometry departs most from the matrix linearised at rest. Empty where the springs are
  /// linear, or no pusher is connected.
  virtual LocalStiffness stiffnessChangeAtPusher(const Vector& /*u*/) const { return {}; }
  /// Takes out of `stiffness` (the matrix above) the contact stiffness of interface node `node`, for an
  /// equilibrium in which that node is off the track.
  virtual void releaseContact(SparseMatrix& stiffness, int node) const = 0;
  /// Damping matrix of the pair damping (force = −C·v).
  virtual SparseMatrix dampingMatrix() const = 0;
  /// N/m per degree of freedom: the springs that tie single degrees of freedom to the ground (foundation,
  /// pusher, top springs), the diagonal part of stiffnessMatrix() that no bond between nodes gives.
  virtual Vector anchorStiffness() const = 0;
  /// Upper bounds on the largest eigenvalues of the bonds' part of stiffnessMatrix() (N/m) and of
  /// dampingMatrix() (kg/s), in closed form: with modeBounds' node-by-node bound they set the stability
  /// limit without an eigenvalue solve. A finite lattice is the infinite one with bonds taken away, and
  /// taking a bond away lowers the quadratic form uᵀKu, so its largest eigenvalue is at most the
  /// infinite lattice's: the top of the symbol Σ_bonds k_b (2 − 2cos q·d_b) e_b e_bᵀ over the wave
  /// vectors q.
  virtual double bondStiffnessBound() const = 0;
  virtual double dampingBound() const = 0;

  /// Degrees of freedom held fixed while F_Z is applied (the interface's tangential motion).
  virtual std::vector<int> blockedDofsDuringLoading() const;
  /// External forces (N, per dof) applied during the static loading solve in addition to the model's
  /// own loads, such as a prescribed initial friction profile. Empty = none.
  virtual Vector initialBodyForce() const { return Vector(); }
  /// Lets a displacement-controlled load (the spring mattress) re-balance itself during the static
  /// solve; returns true if it changed.
  virtual bool rebalanceLoad(const Vector& /*u*/) { return false; }

  /// Pusher connection: while disconnected, the pusher carries no force. `connectPusher` attaches it
  /// unstretched to the current displacements with the stage at position 0.
  virtual void disconnectPusher() = 0;
  virtual void connectPusher(const Vector& u) = 0;
  /// m, rest height above the interface of the pushed nodes: the pushed row's (the lattice's nearest to
  /// the scene's h), a band's mean row height (near where the resultant acts: its rows' springs stretch
  /// a little unequally), or h where the model places it as given (the chain's torque term).
  virtual double pushingHeight() const = 0;

  /// N, sets the normal load F_Z.
  virtual void setNormalLoad(double normal_force) = 0;
  /// Whether F_Z may change during a run (setNormalLoad then acts at once).
  virtual bool takesNormalLoadChanges() const { return true; }

  /// Strain-gauge stresses at height z (m) above the interface at positions x (m).
  virtual GaugeStresses gaugeStresses(const Vector& u, double height, const std::vector<double>& positions) const = 0;

  /// Node positions (rest + displacement) for visualisation: x then z per node.
  virtual void nodePositions(const Vector& u, std::vector<double>& x, std::vector<double>& z) const = 0;
  /// m/s, speed of every node.
  virtual std::vector<double> nodeSpeeds(const Vector& v) const = 0;
  /// Stress at every node (mean of the cells around it; zero for the chain, which has no cells).
  virtual GaugeStresses nodeStresses(const Vector& u) const = 0;
  /// Nodes along x and along z (the chain: N × 1).
  virtual std::array<int, 2> gridShape() const = 0;
  /// Degrees of freedom per node (x, and z in 2D): component c of node i is degree of freedom c·N + i
  /// of the N nodes of the grid.
  int componentsPerNode() const {
    const auto shape = gridShape();
    return dofCount() / (shape[0] * shape[1]);
  }
  /// m, rest spacing of the nodes (l or a).
  virtual double nodeSpacing() const = 0;
  /// m, the displacement of the forces' finite differences (fast-forward's path, the creep's
  /// linearisation): a millionth of a spacing, far above round-off and far below the springs' curvature.
  double probeLength() const { return 1e-6 * nodeSpacing(); }
};

std::unique_ptr<Model> buildModel(const Scene& scene);

}  // namespace friction
