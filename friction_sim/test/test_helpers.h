// Shared pieces of the core tests.
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "friction_sim/model/model.h"
#include "friction_sim/scene/loading_protocol.h"
#include "friction_sim/scene/scene.h"
#include "friction_sim/scene/scene_io.h"
#include "friction_sim/solvers/integrator.h"

namespace friction::testing {

inline std::string scenePath(const std::string& name) { return std::string(SCENE_DIR) + "/" + name + ".yaml"; }

/// The whole 75.6 g slider as one block on the stage spring, no damping.
inline Scene singleBlockScene(IntegratorKind scheme, double stage_speed, double time_step) {
  Scene scene = loadScene(scenePath("single_block"));
  scene.stage.max_speed = 10.0;
  scene.stage.program = {StageSegment{StageMode::Velocity, stage_speed}};
  scene.integrator.scheme = scheme;
  scene.integrator.time_step = time_step;
  scene.stop.global_events = 3;
  return scene;
}

/// The default slider (pmma_2d) at nodes_x × nodes_z nodes: the same physical slider at another spacing.
inline Scene pmmaScene(int nodes_x, int nodes_z) {
  Scene scene = loadScene(scenePath("pmma_2d"));
  scene.lattice.nodes_x = nodes_x;
  scene.lattice.nodes_z = nodes_z;
  return scene;
}

/// A coarse 2D slider (29 × 16 nodes, l = 5 mm) driven ten times faster than the default, so that a
/// whole run to the first global event takes about a second.
inline Scene coarseSliderScene(bool fast_forward = false) {
  Scene scene = pmmaScene(29, 16);
  scene.stage.program = {StageSegment{StageMode::Velocity, 4e-3}};
  scene.integrator.time_step = 4e-7;
  scene.integrator.fast_forward = fast_forward;
  return scene;
}

/// pmma_1d_side stepped as it was before its default became converged: velocity Verlet at 0.2 µs, full
/// dynamics. Its first 28 precursor onsets are within 1e-3 of the converged ones
/// (docs/benchmarks/chain_time_step.md), and it runs fast enough to be stepped one step at a time: for
/// the tests of the instruments and of the force balance, whose tolerances were measured on it.
inline Scene coarseSideChainScene() {
  Scene scene = loadScene(scenePath("pmma_1d_side"));
  scene.integrator.scheme = IntegratorKind::VelocityVerlet;
  scene.integrator.time_step = 2e-7;
  scene.integrator.fast_forward = false;
  return scene;
}

/// A chain of `blocks` blocks driven at the side 5 mm up with the whole torque term, so that every
/// normal force depends on F_X.
inline Scene torqueChainScene(int blocks) {
  Scene scene;
  scene.model = ModelKind::Chain1D;
  scene.chain.blocks = blocks;
  scene.chain.torque_share = 1.0;
  scene.pusher.height = 0.005;
  return scene;
}

/// A frictionless, unpushed elastic body integrated directly: u'' = F(u, u')/m.
class FreeBody : public Dynamics {
 public:
  explicit FreeBody(Model& model) : model_(model) { model_.disconnectPusher(); }
  double acceleration(const Vector& u, const Vector& v, double, Vector& a) override {
    model_.evaluate(u, v, 0.0, evaluation_);
    a = evaluation_.force / model_.nodeMass();
    return evaluation_.viscous_power;
  }
  double energy(const Vector& u, const Vector& v) const {
    return model_.elasticEnergy(u, 0.0) + 0.5 * model_.nodeMass() * v.squaredNorm();
  }

 private:
  Model& model_;
  ForceEvaluation evaluation_;
};

/// Records what the evaluation asks of its hooks: each range is displaced when prepared (so a read
/// before preparation would change the forces), and its forces are copied when finished.
class RecordingHooks : public StripHooks {  // each dof's records are its own: threads may share it
 public:
  RecordingHooks(Vector& u, const Vector& shift, const Vector& force)
      : u_(u),
        shift_(shift),
        force_(force),
        prepared_(u.size(), 0),
        finished_(u.size(), 0),
        forces_at_finish_(Vector::Constant(u.size(), std::nan(""))),
        normal_forces_at_finish_(Vector::Constant(u.size(), std::nan(""))) {}
  /// Also kicks `v` by `kick` when a dof is finished, as the closing kick does: a force that read a
  /// finished dof's velocity would change.
  void kickAtFinish(Vector& v, const Vector& kick) {
    v_ = &v;
    kick_ = &kick;
  }
  /// Also records, at finish, the normal force of each interface node (`normal_force`, per node) whose
  /// dof (from `first_interface_dof` on, contiguous) is finished.
  void recordNormalForces(const Vector& normal_force, int first_interface_dof) {
    normal_force_ = &normal_force;
    first_interface_dof_ = first_interface_dof;
  }
  /// Also stalls 5 ms before preparing a strip that starts at the row before a seam between two blocks of
  /// a threaded sweep (`seam_rows`: each upper block's first row; the upper block prepares from there), and
  /// after finishing a strip that ends there (the lower block, before its last row): a sweep that read the
  /// seam's rows before they were prepared, or changed the upper block's first row before the lower block
  /// had swept its last, would then give other forces. The lattice is `nodes_x` wide, of `nodes` nodes.
  void stallAtSeams(const std::vector<int>& seam_rows, int nodes_x, int nodes) {
    seam_rows_ = seam_rows;
    nodes_x_ = nodes_x;
    nodes_ = nodes;
  }
  /// The threads that called the hooks.
  std::size_t threads() const {
    const std::lock_guard<std::mutex> lock(threads_mutex_);
    return threads_.size();
  }
  void prepare(int first, int end) override {
    noteThread();
    if (atSeam(first)) std::this_thread::sleep_for(kSeamStall);
    for (int i = first; i < end; ++i) {
      ++prepared_[i];
      if (!std::isnan(force_[i])) untouched_force_at_prepare_ = false;
      u_[i] += shift_[i];
    }
  }
  void finish(int first, int end) override {
    noteThread();
    for (int i = first; i < end; ++i) {
      ++finished_[i];
      forces_at_finish_[i] = force_[i];
      if (v_) (*v_)[i] += (*kick_)[i];
      const int node = i - first_interface_dof_;
      if (normal_force_ && node >= 0 && node < normal_force_->size())
        normal_forces_at_finish_[i] = (*normal_force_)[node];
    }
    if (atSeam(end)) std::this_thread::sleep_for(kSeamStall);
  }
  bool eachOnce() const {
    return std::all_of(prepared_.begin(), prepared_.end(), [](int n) { return n == 1; }) &&
           std::all_of(finished_.begin(), finished_.end(), [](int n) { return n == 1; });
  }
  bool untouchedForceAtPrepare() const { return untouched_force_at_prepare_; }
  const Vector& forcesAtFinish() const { return forces_at_finish_; }
  /// Per dof; NaN where the dof is not an interface node's.
  const Vector& normalForcesAtFinish() const { return normal_forces_at_finish_; }

 private:
  Vector& u_;
  const Vector& shift_;
  const Vector& force_;
  Vector* v_ = nullptr;
  const Vector* kick_ = nullptr;
  const Vector* normal_force_ = nullptr;
  int first_interface_dof_ = 0;
  std::vector<int> prepared_, finished_;
  Vector forces_at_finish_, normal_forces_at_finish_;
  std::atomic<bool> untouched_force_at_prepare_{true};  ///< threads may prepare strips at once
  static constexpr std::chrono::milliseconds kSeamStall{5};
  std::vector<int> seam_rows_;
  int nodes_x_ = 1, nodes_ = 0;
  mutable std::mutex threads_mutex_;
  std::set<std::thread::id> threads_;

  /// Whether `dof` is the x component of the first node of the row before a seam.
  bool atSeam(int dof) const {
    return dof < nodes_ && dof % nodes_x_ == 0 &&
           std::find(seam_rows_.begin(), seam_rows_.end(), dof / nodes_x_ + 1) != seam_rows_.end();
  }
  void noteThread() {
    const std::lock_guard<std::mutex> lock(threads_mutex_);
    threads_.insert(std::this_thread::get_id());
  }
};

/// A CSV table: its header's column names, then one row of cells per line.
struct CsvTable {
  explicit CsvTable(const std::string& text) {
    std::istringstream lines(text);
    std::string line;
    std::getline(lines, line);
    columns = splitCsvLine(line);
    while (std::getline(lines, line)) rows.push_back(splitCsvLine(line));
  }
  bool has(const std::string& column) const {
    return std::find(columns.begin(), columns.end(), column) != columns.end();
  }
  double number(std::size_t row, const std::string& column) const {
    return std::stod(rows[row][std::find(columns.begin(), columns.end(), column) - columns.begin()]);
  }
  std::vector<std::string> columns;
  std::vector<std::vector<std::string>> rows;
};

}  // namespace friction::testing
