#include "friction_sim/model/lattice_2d.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>

namespace friction {

int nearestRow(double height, double spacing, int rows) {
  return std::clamp(static_cast<int>(std::lround(height / spacing)), 0, rows - 1);
}

std::vector<int> pushedRowsOf(const PusherSpec& pusher, double spacing, int nz) {
  std::vector<int> rows;
  if (pusher.hasBand()) {
    for (int j = 0; j < nz; ++j) {
      const double z = j * spacing;
      if (z >= pusher.band_min - 1e-9 * spacing && z <= pusher.band_max + 1e-9 * spacing) rows.push_back(j);
    }
  } else {
    rows.push_back(nearestRow(pusher.height, spacing, nz));
  }
  return rows;
}

Lattice2D::Lattice2D(const Scene& scene)
    : nx_(scene.lattice.nodes_x),
      nz_(scene.lattice.nodes_z),
      n_(nx_ * nz_),
      spacing_(scene.geometry.length / (nx_ - 1)),
      width_(scene.geometry.width),
      mass_(scene.material.density * scene.geometry.length * scene.geometry.height * scene.geometry.width / n_),
      k_(springStiffness(scene)),
      eta_(std::sqrt(scene.material.damping_coefficient * k_ * mass_)),
      kf_(scene.lattice.foundation_ratio * k_),
      geometric_(scene.lattice.spring_form == SpringForm::Geometric),
      normal_force_(scene.load.normal_force),
      mattress_(scene.load.top == TopLoadKind::SpringMattress),
      interface_free_while_loading_(scene.load.interface_while_loading == InterfaceLoading::Free),
      mattress_k_(scene.load.mattress_stiffness > 0 ? scene.load.mattress_stiffness : k_),
      mattress_kx_per_node_(scene.load.mattress_horizontal_stiffness / nx_),
      top_anchor_x_(nx_, 0.0),
      pushed_rows_(pushedRowsOf(scene.pusher, spacing_, nz_)),
      pusher_k_per_row_(scene.pusher.stiffness / pushed_rows_.size()),
      pusher_offset_(pushed_rows_.size(), 0.0) {
  const double diagonal = spacing_ * std::sqrt(2.0);
  const double c = 1.0 / std::sqrt(2.0);
  families_ = {{1, 0, k_, spacing_, 1.0, 0.0},
               {0, 1, k_, spacing_, 0.0, 1.0},
               {1, 1, 0.5 * k_, diagonal, c, c},
               {-1, 1, 0.5 * k_, diagonal, -c, c}};
  for (EvaluationSums& sums : sums_) {
    sums.band_power.assign((nz_ + kPowerBandRows - 1) / kPowerBandRows, 0.0);
    sums.pusher_force.assign(pushed_rows_.size(), 0.0);
  }
  setThreads(1);
  // Start the mattress plate where it carries F_Z with the slider undeformed.
  plate_z_ = -normal_force_ / (nx_ * mattress_k_);
}

template <class Visit>
void Lattice2D::forEachBond(const BondFamily& family, Visit&& visit) const {
  const int i_begin = std::max(0, -family.di);
  const int i_end = nx_ - std::max(0, family.di);
  const int offset = family.dj * nx_ + family.di;
  for (int j = 0; j + family.dj < nz_; ++j) {
    const int row = j * nx_;
    for (int i = i_begin; i < i_end; ++i) visit(row + i, row + i + offset);
  }
}

void Lattice2D::setThreads(int threads) {
  // No more threads than bands of rows: each block is at least a band.
  threads_ = std::clamp(threads, 1, static_cast<int>(sums_[0].band_power.size()));
  sweep_space_.resize(std::max(kSuccessiveSweeps, threads_));
  for (SweepSpace& space : sweep_space_) {
    space.horizontal_x.assign(nx_ + 2, 0.0);
    space.horizontal_z.assign(nx_ + 2, 0.0);
    space.column_power.setZero(nx_ + 2);
    space.upward.resize(nx_ + 2);
    space.below.resize(nx_ + 2);
  }
  handoffs_ = std::vector<BlockHandoff>(threads_ - 1);
}

int Lattice2D::threadedBlocks() const { return threads_ > 1 && n_ >= kThreadedNodes ? threads_ : 1; }

double Lattice2D::topSpringForce(const Vector& u, int i) const {
  return mattress_k_ * (plate_z_ - u[zDof(nodeIndex(i, nz_ - 1))]);
}

void Lattice2D::RowBonds::resize(int size) {
  for (auto* row : {&vertical_x, &vertical_z, &diagonal_x, &diagonal_z, &antidiagonal_x, &antidiagonal_z}) {
    row->assign(size, 0.0);
  }
}

void Lattice2D::RowBonds::clear() {
  for (auto* row : {&vertical_x, &vertical_z, &diagonal_x, &diagonal_z, &antidiagonal_x, &antidiagonal_z}) {
    std::fill(row->begin(), row->end(), 0.0);
  }
}

namespace {

struct NodeArrays {
  const double* ux;
  const double* uz;
  const double* vx;
  const double* vz;
};

/// Forces of `count` bonds of one family from nodes a0 + i to b0 + i (i < count): spring tension plus
/// pair damping, as the force on node a; adds η|Δv|² to `power` (W) per bond. The hot kernel: it writes
/// Lattice2D::bondTension's rule out with a square root in place of std::hypot, so that the loop
/// vectorises.
template <bool kGeometric>
void bondRow(const NodeArrays& nodes, int a0, int b0, int count, double rest_x, double rest_z, double rest_length,
             double stiffness, double eta, double* __restrict out_x, double* __restrict out_z,
             double* __restrict power) {
  const double* __restrict ux = nodes.ux;
  const double* __restrict uz = nodes.uz;
  const double* __restrict vx = nodes.vx;
  const double* __restrict vz = nodes.vz;
  const double ex = rest_x / rest_length, ez = rest_z / rest_length;
  for (int i = 0; i < count; ++i) {
    const double dux = ux[b0 + i] - ux[a0 + i], duz = uz[b0 + i] - uz[a0 + i];
    const double dvx = vx[b0 + i] - vx[a0 + i], dvz = vz[b0 + i] - vz[a0 + i];
    double force_x, force_z;
    if constexpr (kGeometric) {
      const double bond_x = rest_x + dux, bond_z = rest_z + duz;
      const double length = std::sqrt(bond_x * bond_x + bond_z * bond_z);
      const double tension_per_length = stiffness * (length - rest_length) / length;
      force_x = tension_per_length * bond_x;
      force_z = tension_per_length * bond_z;
    } else {
      const double tension = stiffness * (ex * dux + ez * duz);
      force_x = ex * tension;
      force_z = ez * tension;
    }
    out_x[i] = force_x + eta * dvx;
    out_z[i] = force_z + eta * dvz;
    power[i] += eta * (dvx * dvx + dvz * dvz);
  }
}

}  // namespace

namespace {
/// Waits for a neighbouring block's flag, or throws once another block has failed: its flags would
/// never come.
void awaitFlag(const std::atomic<bool>& flag, const std::atomic<bool>& abandoned) {
  while (!flag.load(std::memory_order_acquire)) {
    if (abandoned.load(std::memory_order_relaxed)) {
      throw std::runtime_error("Lattice2D: the sweep of a neighbouring block of rows failed");
    }
    std::this_thread::yield();
  }
}
}  // namespace

/// One force evaluation swept row by row, in strips of whole rows: first every bond of the row
/// (contiguous runs of nodes, so the loops vectorise), then each node's force gathered once from its eight
/// bonds, half of them kept from the row below, then the external forces on the row. Buffer index p
/// holds the bond whose lower-index node is at column p − 1 (p − 2 for the antidiagonal); the padding
/// entries stay zero. A row at a time, so that other sweeps can follow this one (evaluateSuccessiveInStrips).
///
/// A sweep may cover a block of rows while other threads sweep the blocks below and above it. Each node's
/// force is gathered from its own bonds in the same order whatever the blocks, and the block sweeps the
/// bonds up from the row below it again for its first row, so the forces are the same to the last bit.
/// At a seam, the upper block prepares both rows there before the lower block reads them, and it
/// finishes its first row (changes its velocities) only after the lower block has swept its last.
class Lattice2D::Sweep {
 public:
  /// Rows [first_row, end_row), and the hand-offs with the blocks below and above (none at row 0 and at
  /// the top row).
  struct Block {
    int first_row, end_row;
    BlockHandoff* lower = nullptr;
    BlockHandoff* upper = nullptr;
    const std::atomic<bool>* abandoned = nullptr;  ///< set once a block has failed
  };

  Sweep(const Lattice2D& lattice, const StripEvaluation& evaluation, int strip_nodes, SweepSpace& space,
        EvaluationSums& sums, Block block)
      : lattice_(lattice),
        evaluation_(evaluation),
        space_(space),
        sums_(sums),
        block_(block),
        rows_per_strip_(std::max(1, strip_nodes / lattice.nx_)),
        prepare_end_(block.upper ? block.end_row - 1 : lattice.nz_),
        bonds_(lattice.geometric_ ? &bondRow<true> : &bondRow<false>),
        nodes_{evaluation.u.data(), evaluation.u.data() + lattice.n_, evaluation.v.data(),
               evaluation.v.data() + lattice.n_},
        row_(block.first_row),
        prepared_rows_(std::max(0, block.first_row - 1)),
        finished_rows_(block.lower ? block.first_row + 1 : block.first_row),
        next_pushed_(std::lower_bound(lattice.pushed_rows_.begin(), lattice.pushed_rows_.end(), block.first_row) -
                     lattice.pushed_rows_.begin()) {
    // Two blocks writing one band's power would go unnoticed: refused here.
    if (block.lower && block.first_row % kPowerBandRows != 0) {
      throw std::logic_error("Lattice2D::Sweep: a block must start on a band of rows");
    }
    space_.column_power.setZero();
    space_.below.clear();
  }

  /// Sizes an evaluation's outputs, before any sweep of it writes them.
  static void sizeOutputs(const Lattice2D& lattice, const StripEvaluation& evaluation) {
    evaluation.force.resize(2 * lattice.n_);
    evaluation.out.normal_force.resize(lattice.nx_);
  }

  bool done() const { return row_ == block_.end_row; }
  ForceEvaluation& output() const { return evaluation_.out; }
  /// Rows [0, finishedRows()) are finished: their forces final, their finish hooks called, their state
  /// no longer read. For a sweep of the whole lattice (evaluateSuccessiveInStrips); a block above another
  /// finishes its first row last.
  int finishedRows() const { return finished_rows_; }
  /// Rows [0, preparedRowsForNextRow()) are prepared once the next row is swept: the bonds of row j
  /// read rows j and j + 1, and rows are prepared a strip at a time. Of a block below another, the rows
  /// from its last on are the upper block's to prepare.
  int preparedRowsForNextRow() const {
    const int rows_needed = std::min(lattice_.nz_, row_ + 2);
    if (prepared_rows_ >= rows_needed) return prepared_rows_;
    return std::min(prepare_end_, std::max(rows_needed, prepared_rows_ + rows_per_strip_));
  }

  /// The hot kernel, kept whole (over the project's 60 lines): it runs for every row of every step, and
  /// its bonds, gathers and external forces share the row's pointers.
  void sweepRow() {  // NOLINT(readability-function-size): the hot kernel, kept whole (above)
    const Lattice2D& l = lattice_;
    const int nx = l.nx_, nz = l.nz_, n = l.n_, j = row_;
    const int prepared_end = preparedRowsForNextRow();
    if (prepared_end > prepared_rows_) {
      forBothComponents(prepared_rows_, prepared_end, &StripHooks::prepare);
      prepared_rows_ = prepared_end;
    }
    if (block_.lower && j == block_.first_row) {
      // The bonds up from the row below, which the lower block sweeps too; their power is counted there.
      upwardBonds(j - 1, space_.below);
      space_.column_power.setZero();
      block_.lower->seam_prepared.store(true, std::memory_order_release);
    }
    if (block_.upper && j + 2 > prepare_end_) awaitFlag(block_.upper->seam_prepared, *block_.abandoned);
    double* fx = evaluation_.force.data();
    double* fz = evaluation_.force.data() + n;
    const double* ux = evaluation_.u.data();
    const double* uz = evaluation_.u.data() + n;
    RowBonds& upward = space_.upward;
    const RowBonds& below = space_.below;
    const int row = j * nx;
    run(l.families_[0], row, row + 1, nx - 1, space_.horizontal_x.data() + 1, space_.horizontal_z.data() + 1);
    if (j + 1 < nz) {
      upwardBonds(j, upward);
    } else {
      upward.clear();
    }
    if (block_.upper && j + 1 == block_.end_row) block_.upper->lower_swept.store(true, std::memory_order_release);
    if ((j + 1) % kPowerBandRows == 0 || j + 1 == nz) {
      sums_.band_power[j / kPowerBandRows] = space_.column_power.sum();
      space_.column_power.setZero();
    }
    auto gather = [nx](const double* __restrict h, const double* __restrict vu, const double* __restrict du,
                       const double* __restrict au, const double* __restrict vb, const double* __restrict db,
                       const double* __restrict ab, double* __restrict f) {
      for (int i = 0; i < nx; ++i) {
        f[i] = ((h[i + 1] - h[i]) + (vu[i] - vb[i])) + ((du[i + 1] - db[i]) + (au[i + 1] - ab[i + 2]));
      }
    };
    gather(space_.horizontal_x.data(), upward.vertical_x.data(), upward.diagonal_x.data(), upward.antidiagonal_x.data(),
           below.vertical_x.data(), below.diagonal_x.data(), below.antidiagonal_x.data(), fx + row);
    gather(space_.horizontal_z.data(), upward.vertical_z.data(), upward.diagonal_z.data(), upward.antidiagonal_z.data(),
           below.vertical_z.data(), below.diagonal_z.data(), below.antidiagonal_z.data(), fz + row);
    std::swap(space_.upward, space_.below);
    if (j == 0) {
      for (int i = 0; i < nx; ++i) {
        const double normal = l.kf_ * std::max(0.0, -uz[i]);
        evaluation_.out.normal_force[i] = normal;
        fz[i] += normal;
      }
    }
    if (j == nz - 1) {
      double top_normal = 0.0;
      for (int i = 0; i < nx; ++i) {
        const int top = l.nodeIndex(i, j);
        if (l.mattress_) {
          const double spring = l.topSpringForce(evaluation_.u, i);
          fz[top] += spring;
          fx[top] += l.mattress_kx_per_node_ * (l.top_anchor_x_[i] - ux[top]);
          top_normal -= spring;
        } else {
          fz[top] -= l.normal_force_ / nx;
        }
      }
      sums_.top_normal = top_normal;
    }
    for (; l.pusher_connected_ && next_pushed_ < l.pushed_rows_.size() && l.pushed_rows_[next_pushed_] == j;
         ++next_pushed_) {
      const int node = l.nodeIndex(0, j);
      const double pusher_force =
          l.pusher_k_per_row_ * (evaluation_.stage_position + l.pusher_offset_[next_pushed_] - ux[node]);
      fx[node] += pusher_force;
      sums_.pusher_force[next_pushed_] = pusher_force;
    }
    if (j + 1 - finished_rows_ >= rows_per_strip_ || j + 1 == block_.end_row) {
      if (finished_rows_ < j + 1) forBothComponents(finished_rows_, j + 1, &StripHooks::finish);
      finished_rows_ = j + 1;
    }
    ++row_;
    if (done() && block_.lower) {
      awaitFlag(block_.lower->lower_swept, *block_.abandoned);
      forBothComponents(block_.first_row, block_.first_row + 1, &StripHooks::finish);
    }
  }

  /// The evaluation's sums, in the order of the rows, once every row of every block is swept.
  static void complete(const Lattice2D& lattice, const EvaluationSums& sums, ForceEvaluation& out) {
    double power = 0.0;
    for (double band : sums.band_power) power += band;
    double shear = 0.0;
    if (lattice.pusher_connected_) {
      for (double force : sums.pusher_force) shear += force;
    }
    out.viscous_power = power;
    out.normal_load = lattice.mattress_ ? sums.top_normal : lattice.normal_force_;
    out.shear_force = shear;
  }

 private:
  /// Calls `hook` on rows [first_row, end_row): their x, then their z degrees of freedom.
  void forBothComponents(int first_row, int end_row, void (StripHooks::*hook)(int, int)) {
    const int nx = lattice_.nx_, n = lattice_.n_;
    (evaluation_.hooks.*hook)(first_row * nx, end_row * nx);
    (evaluation_.hooks.*hook)(n + first_row * nx, n + end_row * nx);
  }

  /// The bonds from row j up to row j + 1.
  void upwardBonds(int j, RowBonds& into) {
    const Lattice2D& l = lattice_;
    const int row = j * l.nx_, next = row + l.nx_;
    run(l.families_[1], row, next, l.nx_, into.vertical_x.data(), into.vertical_z.data());
    run(l.families_[2], row, next + 1, l.nx_ - 1, into.diagonal_x.data() + 1, into.diagonal_z.data() + 1);
    run(l.families_[3], row + 1, next, l.nx_ - 1, into.antidiagonal_x.data() + 2, into.antidiagonal_z.data() + 2);
  }

  void run(const BondFamily& family, int a0, int b0, int count, double* out_x, double* out_z) {
    bonds_(nodes_, a0, b0, count, family.ex * family.rest_length, family.ez * family.rest_length, family.rest_length,
           family.stiffness, lattice_.eta_, out_x, out_z, space_.column_power.data());
  }

  const Lattice2D& lattice_;
  const StripEvaluation evaluation_;  ///< a copy (of references): the caller's may be a temporary
  SweepSpace& space_;
  EvaluationSums& sums_;
  const Block block_;
  const int rows_per_strip_;
  /// Rows [0, prepare_end_) are this sweep's or the blocks' below it to prepare.
  const int prepare_end_;
  decltype(&bondRow<true>) bonds_;
  /// Built once: rebuilt for each run of bonds, it made a 32 × 32 lattice's step about 10 % slower.
  const NodeArrays nodes_;
  int row_, prepared_rows_, finished_rows_;
  std::size_t next_pushed_;  ///< the next pushed row, in pushed_rows_
};

void Lattice2D::evaluateInto(const Vector& u, const Vector& v, double stage_position, Vector& force,
                             ForceEvaluation& out) const {
  StripHooks none;
  evaluateInStrips(u, v, stage_position, force, out, none, n_);
}

void Lattice2D::evaluateInStrips(const Vector& u, const Vector& v, double stage_position, Vector& force,
                                 ForceEvaluation& out, StripHooks& hooks, int strip_nodes) const {
  const StripEvaluation evaluation{u, v, stage_position, force, out, hooks};
  Sweep::sizeOutputs(*this, evaluation);
  const int blocks = threadedBlocks();
  if (blocks == 1) {
    Sweep sweep(*this, evaluation, strip_nodes, sweep_space_[0], sums_[0], {0, nz_});
    while (!sweep.done()) sweep.sweepRow();
  } else {
    sweepInBlocks(evaluation, strip_nodes, blocks);
  }
  Sweep::complete(*this, sums_[0], out);
}

void Lattice2D::sweepInBlocks(const StripEvaluation& evaluation, int strip_nodes, int blocks) const {
  for (int k = 0; k + 1 < blocks; ++k) {
    handoffs_[k].seam_prepared.store(false, std::memory_order_relaxed);
    handoffs_[k].lower_swept.store(false, std::memory_order_relaxed);
  }
  std::atomic<bool> abandoned{false};
  std::exception_ptr error;
  std::mutex error_mutex;
#pragma omp parallel num_threads(blocks)
  {
    // As many blocks as threads came (OpenMP may give fewer).
    const int team = omp_get_num_threads(), k = omp_get_thread_num();
    const Sweep::Block block{firstRowOfBlock(k, team), firstRowOfBlock(k + 1, team),
                             k > 0 ? &handoffs_[k - 1] : nullptr, k + 1 < team ? &handoffs_[k] : nullptr, &abandoned};
    try {
      Sweep sweep(*this, evaluation, strip_nodes, sweep_space_[k], sums_[0], block);
      while (!sweep.done()) sweep.sweepRow();
    } catch (...) {
      // The error first: a neighbour that sees `abandoned` throws one of its own, which must not win.
      {
        const std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
      }
      abandoned.store(true);
    }
  }
  if (error) std::rethrow_exception(error);
}

int Lattice2D::firstRowOfBlock(int block, int blocks) const {
  if (block == blocks) return nz_;
  // Whole bands, each block's share of the rows rounded to the nearest band, and at least a band each.
  const int bands = static_cast<int>(sums_[0].band_power.size());
  int band = 0;
  for (int b = 1; b <= block; ++b) {
    const int nearest = (2 * nz_ * b + blocks * kPowerBandRows) / (2 * blocks * kPowerBandRows);
    band = std::max(band + 1, std::min(nearest, bands - blocks + b));
  }
  return band * kPowerBandRows;
}

int Lattice2D::evaluateSuccessiveInStrips(int strip_nodes,
                                          const std::function<std::optional<StripEvaluation>(int)>& next) const {
  std::array<std::optional<Sweep>, kSuccessiveSweeps> sweeps;
  const std::optional<StripEvaluation> first = next(0);
  if (!first) return 0;
  Sweep::sizeOutputs(*this, *first);
  sweeps[0].emplace(*this, *first, strip_nodes, sweep_space_[0], sums_[0], Sweep::Block{0, nz_});
  int started = 1;
  bool asking = true;
  for (;;) {
    const Sweep& hindmost = *sweeps[started - 1];
    // The interface is the bottom row: final once a sweep's first strip is finished.
    if (asking && hindmost.finishedRows() > 0) {
      const std::optional<StripEvaluation> evaluation = next(started);
      asking = evaluation.has_value();
      if (asking) {
        if (started == kSuccessiveSweeps) {
          throw std::logic_error("Lattice2D::evaluateSuccessiveInStrips: asked for more than " +
                                 std::to_string(kSuccessiveSweeps) + " evaluations");
        }
        Sweep::sizeOutputs(*this, *evaluation);
        sweeps[started].emplace(*this, *evaluation, strip_nodes, sweep_space_[started], sums_[started],
                                Sweep::Block{0, nz_});
        ++started;
      }
      continue;
    }
    // A sweep is done only once the one ahead of it is.
    if (hindmost.done()) break;
    // The hindmost sweep that may go on, keeping them close: each prepares (changes) only rows that the
    // one ahead of it has finished, and so have all the others ahead.
    int k = started - 1;
    while (k > 0 && sweeps[k]->preparedRowsForNextRow() > sweeps[k - 1]->finishedRows()) --k;
    sweeps[k]->sweepRow();
  }
  for (int k = 0; k < started; ++k) Sweep::complete(*this, sums_[k], sweeps[k]->output());
  return started;
}

Vector Lattice2D::signedNormalForces(const Vector& u, const ForceEvaluation&) const {
  return -kf_ * u.segment(zDof(nodeIndex(0, 0)), nx_);
}

double Lattice2D::elasticEnergy(const Vector& u, double stage_position) const {
  const double* ux = u.data();
  const double* uz = u.data() + n_;
  double energy = 0.0;
  for (const BondFamily& family : families_) {
    forEachBond(family, [&](int a, int b) {
      const double dux = ux[b] - ux[a], duz = uz[b] - uz[a];
      const double rx = family.ex * family.rest_length + dux, rz = family.ez * family.rest_length + duz;
      const double stretch = bondTension(family, rx, rz, dux, duz).stretch;
      energy += 0.5 * family.stiffness * stretch * stretch;
    });
  }
  for (int i = 0; i < nx_; ++i) {
    const double penetration = std::max(0.0, -uz[i]);
    energy += 0.5 * kf_ * penetration * penetration;
    if (mattress_) {
      const int top = nodeIndex(i, nz_ - 1);
      const double dz = plate_z_ - uz[top];
      const double dx = top_anchor_x_[i] - ux[top];
      energy += 0.5 * mattress_k_ * dz * dz + 0.5 * mattress_kx_per_node_ * dx * dx;
    }
  }
  if (pusher_connected_) {
    for (std::size_t r = 0; r < pushed_rows_.size(); ++r) {
      const double stretch = stage_position + pusher_offset_[r] - ux[nodeIndex(0, pushed_rows_[r])];
      energy += 0.5 * pusher_k_per_row_ * stretch * stretch;
    }
  }
  return energy;
}

double Lattice2D::externalWork(const Vector& u_from, const Vector& u_to) const {
  if (mattress_) return 0.0;
  double sum = 0.0;
  for (int i = 0; i < nx_; ++i) {
    const int dof = zDof(nodeIndex(i, nz_ - 1));
    sum += u_to[dof] - u_from[dof];
  }
  return -normal_force_ / nx_ * sum;
}

template <class Add>
void Lattice2D::addStiffness(Add&& add) const {
  const Vector anchors = anchorStiffness();
  for (const BondFamily& family : families_) {
    const double e[2] = {family.ex, family.ez};
    forEachBond(family, [&](int a, int b) {
      const int dofs_a[2] = {xDof(a), zDof(a)};
      const int dofs_b[2] = {xDof(b), zDof(b)};
      for (int p = 0; p < 2; ++p) {
        for (int q = 0; q < 2; ++q) {
          const double kpq = family.stiffness * e[p] * e[q];
          add(dofs_a[p], dofs_a[q], kpq);
          add(dofs_b[p], dofs_b[q], kpq);
          add(dofs_a[p], dofs_b[q], -kpq);
          add(dofs_b[p], dofs_a[q], -kpq);
        }
      }
    });
  }
  for (int dof = 0; dof < 2 * n_; ++dof) {
    if (anchors[dof] != 0.0) add(dof, dof, anchors[dof]);
  }
}

SparseMatrix Lattice2D::stiffnessMatrix() const {
  // A node and its eight neighbours, two components each.
  return assembleSparse(2 * n_, 18, [this](auto&& add) { addStiffness(add); });
}

NodeStiffness Lattice2D::nodeStiffness() const {
  return collectNodeStiffness(n_, 2, [this](auto&& add) { addStiffness(add); });
}

Vector Lattice2D::anchorStiffness() const {
  Vector anchors = Vector::Zero(2 * n_);
  for (int i = 0; i < nx_; ++i) {
    anchors[zDof(i)] += kf_;
    if (mattress_) {
      const int top = nodeIndex(i, nz_ - 1);
      anchors[zDof(top)] += mattress_k_;
      anchors[xDof(top)] += mattress_kx_per_node_;
    }
  }
  if (pusher_connected_) {
    for (int row : pushed_rows_) anchors[xDof(nodeIndex(0, row))] += pusher_k_per_row_;
  }
  return anchors;
}

void Lattice2D::releaseContact(SparseMatrix& stiffness, int node) const {
  stiffness.coeffRef(zDof(nodeIndex(node, 0)), zDof(nodeIndex(node, 0))) -= kf_;
}

LocalStiffness Lattice2D::stiffnessChangeAtPusher(const Vector& u) const {
  LocalStiffness change;
  if (!geometric_ || !pusher_connected_ || pushed_rows_.size() > kMostRowsForLocalTangent) return change;
  // The pushed nodes, at the trailing edge, and their neighbours: measured at 113 × 61, the springs among
  // them give 16 of the 25 corrections a jump's tangent stiffness spares; out to four nodes, 17.
  std::vector<int> nodes;
  for (int row : pushed_rows_) {
    for (int j = std::max(row - 1, 0); j <= std::min(row + 1, nz_ - 1); ++j) {
      for (int i = 0; i <= std::min(1, nx_ - 1); ++i) nodes.push_back(nodeIndex(i, j));
    }
  }
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  const int count = static_cast<int>(nodes.size());
  for (int node : nodes) change.dofs.push_back(xDof(node));
  for (int node : nodes) change.dofs.push_back(zDof(node));
  change.matrix = Eigen::MatrixXd::Zero(2 * count, 2 * count);
  const auto local = [&](int node) {
    const auto at = std::lower_bound(nodes.begin(), nodes.end(), node);
    return at != nodes.end() && *at == node ? static_cast<int>(at - nodes.begin()) : -1;
  };
  for (const BondFamily& family : families_) {
    for (int a = 0; a < count; ++a) {
      const int i = nodes[a] % nx_ + family.di, j = nodes[a] / nx_ + family.dj;
      if (i < 0 || i >= nx_ || j < 0 || j >= nz_) continue;
      const int b = local(nodeIndex(i, j));
      if (b < 0) continue;
      // A geometric spring's tangent: k·n·nᵀ along the bond as it is, plus its tension per length across
      // it; the matrix has k·e·eᵀ along the rest direction.
      const double rx = family.ex * family.rest_length + u[xDof(nodes[b])] - u[xDof(nodes[a])];
      const double rz = family.ez * family.rest_length + u[zDof(nodes[b])] - u[zDof(nodes[a])];
      const double length = std::hypot(rx, rz);
      const double n[2] = {rx / length, rz / length};
      const double e[2] = {family.ex, family.ez};
      const double tension_per_length = family.stiffness * (length - family.rest_length) / length;
      for (int p = 0; p < 2; ++p) {
        for (int q = 0; q < 2; ++q) {
          const double change_pq = family.stiffness * (n[p] * n[q] - e[p] * e[q]) +
                                   tension_per_length * ((p == q ? 1.0 : 0.0) - n[p] * n[q]);
          const int row_a = a + p * count, row_b = b + p * count, col_a = a + q * count, col_b = b + q * count;
          change.matrix(row_a, col_a) += change_pq;
          change.matrix(row_b, col_b) += change_pq;
          change.matrix(row_a, col_b) -= change_pq;
          change.matrix(row_b, col_a) -= change_pq;
        }
      }
    }
  }
  return change;
}

SparseMatrix Lattice2D::dampingMatrix() const {
  // The pair damping acts on each component separately: a node and its eight neighbours.
  return assembleSparse(2 * n_, 9, [this](auto&& add) {
    for (const BondFamily& family : families_) {
      forEachBond(family, [&](int a, int b) {
        for (int dof_shift : {0, n_}) {
          add(a + dof_shift, a + dof_shift, eta_);
          add(b + dof_shift, b + dof_shift, eta_);
          add(a + dof_shift, b + dof_shift, -eta_);
          add(b + dof_shift, a + dof_shift, -eta_);
        }
      });
    }
  });
}

bool Lattice2D::rebalanceLoad(const Vector& u) {
  if (!mattress_) return false;
  double carried = 0.0;
  for (int i = 0; i < nx_; ++i) carried -= topSpringForce(u, i);
  const double excess = carried - normal_force_;
  // The plate's springs alone would move the plate as if the slider stayed put; it follows the plate
  // (at 57 × 31 by 31 parts in 32), so that correction would close 1/32 of the excess per solve, and 500
  // solves would not reach the tolerance. The stiffness the last move met, the plate's and the slider's
  // in series, brings the load to F_Z once the slider has answered it.
  double stiffness = nx_ * mattress_k_;
  if (last_plate_move_ != 0.0) {
    const double met = (last_excess_ - excess) / last_plate_move_;
    if (met > 0.0 && met < stiffness) stiffness = met;
  }
  const double correction = excess / stiffness;
  last_excess_ = excess;
  last_plate_move_ = correction;
  plate_z_ += correction;
  for (int i = 0; i < nx_; ++i) top_anchor_x_[i] = u[xDof(nodeIndex(i, nz_ - 1))];
  return std::abs(correction) > 1e-15 * spacing_;
}

std::vector<int> Lattice2D::blockedDofsDuringLoading() const {
  if (interface_free_while_loading_) return {interfaceDof(nx_ / 2)};
  return Model::blockedDofsDuringLoading();
}

double Lattice2D::pushingHeight() const {
  double rows = 0.0;
  for (int row : pushed_rows_) rows += row;
  return rows / pushed_rows_.size() * spacing_;
}

void Lattice2D::connectPusher(const Vector& u) {
  pusher_connected_ = true;
  for (std::size_t r = 0; r < pushed_rows_.size(); ++r) {
    pusher_offset_[r] = u[xDof(nodeIndex(0, pushed_rows_[r]))];
  }
}

Lattice2D::BondTension Lattice2D::bondTension(const BondFamily& family, double rx, double rz, double dux,
                                              double duz) const {
  if (geometric_) {
    const double length = std::hypot(rx, rz);
    const double stretch = length - family.rest_length;
    return {stretch, family.stiffness * stretch / length};
  }
  const double stretch = family.ex * dux + family.ez * duz;
  return {stretch, family.stiffness * stretch / family.rest_length};
}

std::array<double, 3> Lattice2D::cellStress(const Vector& u, int i, int j) const {
  struct CellBond {
    int ia, ja, ib, jb;
    double weight;
    const BondFamily* family;
  };
  const CellBond bonds[6] = {{i, j, i + 1, j, 0.5, &families_[0]},     {i, j + 1, i + 1, j + 1, 0.5, &families_[0]},
                             {i, j, i, j + 1, 0.5, &families_[1]},     {i + 1, j, i + 1, j + 1, 0.5, &families_[1]},
                             {i, j, i + 1, j + 1, 1.0, &families_[2]}, {i + 1, j, i, j + 1, 1.0, &families_[3]}};
  std::array<double, 3> stress{0.0, 0.0, 0.0};  // σ_xx, σ_zz, τ_xz
  for (const CellBond& bond : bonds) {
    const int a = nodeIndex(bond.ia, bond.ja);
    const int b = nodeIndex(bond.ib, bond.jb);
    const BondFamily& family = *bond.family;
    const double rx = family.ex * family.rest_length + u[xDof(b)] - u[xDof(a)];
    const double rz = family.ez * family.rest_length + u[zDof(b)] - u[zDof(a)];
    const double tension =
        bondTension(family, rx, rz, u[xDof(b)] - u[xDof(a)], u[zDof(b)] - u[zDof(a)]).tension_per_length;
    stress[0] += bond.weight * tension * rx * rx;
    stress[1] += bond.weight * tension * rz * rz;
    stress[2] += bond.weight * tension * rx * rz;
  }
  const double volume = spacing_ * spacing_ * width_;
  for (double& component : stress) component /= volume;
  return stress;
}

GaugeStresses Lattice2D::gaugeStresses(const Vector& u, double height, const std::vector<double>& positions) const {
  GaugeStresses out;
  // Cell centres sit at ((i + ½)l, (j + ½)l); interpolate bilinearly between them, clamped at the edges.
  auto bracket = [](double coordinate, int cells, int& low, double& fraction) {
    const double s = std::clamp(coordinate - 0.5, 0.0, static_cast<double>(cells - 1));
    low = std::min(static_cast<int>(s), std::max(cells - 2, 0));
    fraction = cells > 1 ? s - low : 0.0;
  };
  int j0;
  double fz;
  bracket(height / spacing_, nz_ - 1, j0, fz);
  const int j1 = std::min(j0 + 1, nz_ - 2);
  for (double x : positions) {
    int i0;
    double fx;
    bracket(x / spacing_, nx_ - 1, i0, fx);
    const int i1 = std::min(i0 + 1, nx_ - 2);
    const auto s00 = cellStress(u, i0, j0), s10 = cellStress(u, i1, j0);
    const auto s01 = cellStress(u, i0, j1), s11 = cellStress(u, i1, j1);
    double value[3];
    for (int c = 0; c < 3; ++c) {
      value[c] = (1 - fx) * (1 - fz) * s00[c] + fx * (1 - fz) * s10[c] + (1 - fx) * fz * s01[c] + fx * fz * s11[c];
    }
    out.sigma_xx.push_back(value[0]);
    out.sigma_zz.push_back(value[1]);
    out.tau_xz.push_back(value[2]);
  }
  return out;
}

void Lattice2D::nodePositions(const Vector& u, std::vector<double>& x, std::vector<double>& z) const {
  x.resize(n_);
  z.resize(n_);
  for (int j = 0; j < nz_; ++j) {
    for (int i = 0; i < nx_; ++i) {
      const int node = nodeIndex(i, j);
      x[node] = i * spacing_ + u[xDof(node)];
      z[node] = j * spacing_ + u[zDof(node)];
    }
  }
}

std::vector<double> Lattice2D::nodeSpeeds(const Vector& v) const {
  std::vector<double> speed(n_);
  for (int node = 0; node < n_; ++node) speed[node] = std::hypot(v[xDof(node)], v[zDof(node)]);
  return speed;
}

GaugeStresses Lattice2D::nodeStresses(const Vector& u) const {
  GaugeStresses out;
  out.sigma_xx.assign(n_, 0.0);
  out.sigma_zz.assign(n_, 0.0);
  out.tau_xz.assign(n_, 0.0);
  std::vector<int> cells(n_, 0);
  for (int j = 0; j + 1 < nz_; ++j) {
    for (int i = 0; i + 1 < nx_; ++i) {
      const auto stress = cellStress(u, i, j);
      for (int node : {nodeIndex(i, j), nodeIndex(i + 1, j), nodeIndex(i, j + 1), nodeIndex(i + 1, j + 1)}) {
        out.sigma_xx[node] += stress[0];
        out.sigma_zz[node] += stress[1];
        out.tau_xz[node] += stress[2];
        ++cells[node];
      }
    }
  }
  for (int node = 0; node < n_; ++node) {
    out.sigma_xx[node] /= cells[node];
    out.sigma_zz[node] /= cells[node];
    out.tau_xz[node] /= cells[node];
  }
  return out;
}

}  // namespace friction
