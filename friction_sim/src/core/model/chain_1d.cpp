#include "friction_sim/model/chain_1d.h"

#include <algorithm>
#include <cmath>

namespace friction {

namespace {
/// N, the tension of the bond between blocks i and i + 1: spring plus pair damping.
inline double bondTension(double k, double eta, const double* x, const double* w, int i) {
  return k * (x[i + 1] - x[i]) + eta * (w[i + 1] - w[i]);
}

/// The bond forces f_i = T_i − T_{i−1} on the interior blocks [first, end). Each tension is computed for
/// both of its blocks rather than stored: one pass that vectorises, with the round-off of a stored
/// tension. A function of its own, with restrict parameters, because GCC honours restrict only on
/// parameters: without it the loop carries run-time alias checks, which at 57 blocks take about as long
/// as its arithmetic.
void bondForces(int first, int end, double k, double eta, const double* __restrict x, const double* __restrict w,
                double* __restrict f) {
  for (int i = first; i < end; ++i) f[i] = bondTension(k, eta, x, w, i) - bondTension(k, eta, x, w, i - 1);
}
}  // namespace

Chain1D::Chain1D(const Scene& scene)
    : n_(scene.chain.blocks),
      length_(scene.geometry.length),
      spacing_(n_ > 1 ? length_ / (n_ - 1) : length_),
      mass_(scene.material.density * length_ * scene.geometry.height * scene.geometry.width / n_),
      k_(n_ > 1 ? scene.material.youngs_modulus * scene.geometry.height * scene.geometry.width / spacing_ : 0.0),
      eta_(std::sqrt(scene.material.damping_coefficient * k_ * mass_)),
      area_per_block_(spacing_ * scene.geometry.width),
      top_driving_(scene.chain.driving == ChainDriving::Top),
      pusher_k_(scene.pusher.stiffness),
      pushing_height_(scene.pusher.height),
      tilt_(scene.chain.tilt),
      torque_share_(scene.chain.torque_share),
      normal_force_(scene.load.normal_force),
      xi_(Eigen::ArrayXd::Zero(n_)),
      initial_shear_(scene.chain.initial_shear),
      pusher_offset_(Vector::Zero(n_)) {
  if (n_ > 1) {
    for (int i = 0; i < n_; ++i) xi_[i] = 2.0 * i * spacing_ / length_ - 1.0;
  }
  xi_square_sum_ = xi_.square().sum();
  tilt_factor_ = 1.0 + tilt_ * xi_;
  updateDrivingStiffness();
}

void Chain1D::updateDrivingStiffness() {
  driving_stiffness_ = Eigen::ArrayXd::Zero(n_);
  if (!pusher_connected_) return;
  if (top_driving_) {
    driving_stiffness_.setConstant(pusher_k_ / n_);
  } else {
    driving_stiffness_[0] = pusher_k_;
  }
}

double Chain1D::chainLaplacianTop() const {
  const double pi = std::acos(-1.0);
  return n_ > 1 ? 2.0 * (1.0 + std::cos(pi / n_)) : 0.0;
}

double Chain1D::torqueCoefficient(double shear_force) const {
  return xi_square_sum_ > 0.0 ? 2.0 * torque_share_ * pushing_height_ * shear_force / (length_ * xi_square_sum_) : 0.0;
}

auto Chain1D::normalForceExpression(double shear_force, int first, int count) const {
  return normal_force_ / n_ * tilt_factor_.segment(first, count) +
         torqueCoefficient(shear_force) * xi_.segment(first, count);
}

void Chain1D::writeNormalForces(double shear_force, int first, int count, Vector& normal_forces) const {
  // Without tilt or torque every block carries F_Z/N: the same numbers (for a finite F_X) written as one
  // constant, because at the default 57 blocks evaluating the profile costs as much as the bond forces.
  if (torque_share_ == 0.0 && tilt_ == 0.0) {
    std::fill_n(normal_forces.data() + first, count, std::max(normal_force_ / n_, 0.0));
    return;
  }
  normal_forces.segment(first, count) = normalForceExpression(shear_force, first, count).max(0.0);
}

std::vector<double> Chain1D::normalForces(double shear_force) const {
  const Eigen::ArrayXd w = normalForceExpression(shear_force, 0, n_);
  return {w.begin(), w.end()};
}

Vector Chain1D::signedNormalForces(const Vector&, const ForceEvaluation& evaluation) const {
  return normalForceExpression(evaluation.shear_force, 0, n_).matrix();
}

void Chain1D::evaluateInto(const Vector& u, const Vector& v, double stage_position, Vector& force,
                           ForceEvaluation& out) const {
  if (top_driving_) {
    evaluateTopDriven(u, v, stage_position, force, out);
  } else {
    StripHooks none;
    evaluateSideDriven(u, v, stage_position, force, out, none, n_);
  }
}

void Chain1D::evaluateInStrips(const Vector& u, const Vector& v, double stage_position, Vector& force,
                               ForceEvaluation& out, StripHooks& hooks, int strip_nodes) const {
  if (top_driving_) {
    Model::evaluateInStrips(u, v, stage_position, force, out, hooks, strip_nodes);
  } else {
    evaluateSideDriven(u, v, stage_position, force, out, hooks, strip_nodes);
  }
}

void Chain1D::evaluateTopDriven(const Vector& u, const Vector& v, double stage_position, Vector& force,
                                ForceEvaluation& out) const {
  force.resize(n_);
  const double* x = u.data();
  const double* w = v.data();
  double* f = force.data();
  auto tension = [&](int i) { return bondTension(k_, eta_, x, w, i); };
  if (n_ == 1) {
    f[0] = 0.0;
  } else {
    f[0] = tension(0);
    bondForces(1, n_ - 1, k_, eta_, x, w, f);
    f[n_ - 1] = -tension(n_ - 2);
  }
  const auto driving = driving_stiffness_ * (stage_position + pusher_offset_.array() - u.array());
  force.array() += driving;
  const double shear = driving.sum();
  out.shear_force = shear;
  out.normal_load = normal_force_;
  out.viscous_power = eta_ * (v.tail(n_ - 1).array() - v.head(n_ - 1).array()).square().sum();
  out.normal_force.resize(n_);
  writeNormalForces(shear, 0, n_, out.normal_force);
}

void Chain1D::evaluateSideDriven(const Vector& u, const Vector& v, double stage_position, Vector& force,
                                 ForceEvaluation& out, StripHooks& hooks, int strip_nodes) const {
  force.resize(n_);
  out.normal_force.resize(n_);
  const double* x = u.data();
  const double* w = v.data();
  double* f = force.data();
  auto tension = [&](int i) { return bondTension(k_, eta_, x, w, i); };
  int prepared = 0;
  auto prepareThrough = [&](int end) {
    if (prepared >= end) return;
    const int next = std::min(n_, std::max(end, prepared + strip_nodes));
    hooks.prepare(prepared, next);
    prepared = next;
  };
  prepareThrough(1);
  const double shear = driving_stiffness_[0] * (stage_position + pusher_offset_[0] - u[0]);
  double squared_velocity_differences = 0.0;
  // The tension of the bond to the left of the strip, taken before that block was finished (its
  // velocity is then the step's end velocity, no longer the one the force must use).
  double left_tension = 0.0;
  for (int first = 0; first < n_; first += strip_nodes) {
    const int end = std::min(n_, first + strip_nodes);
    prepareThrough(std::min(n_, end + 1));        // the last block's bond reads the next strip's first block
    const int bonds_end = std::min(end, n_ - 1);  // the bonds whose left block is in the strip
    f[first] = (first < n_ - 1 ? tension(first) : 0.0) - left_tension;
    bondForces(first + 1, bonds_end, k_, eta_, x, w, f);
    if (end == n_ && first < n_ - 1) f[n_ - 1] = -tension(n_ - 2);
    if (first == 0) f[0] += shear;
    const int count = end - first;
    writeNormalForces(shear, first, count, out.normal_force);
    if (bonds_end > first) {
      squared_velocity_differences +=
          (v.segment(first + 1, bonds_end - first).array() - v.segment(first, bonds_end - first).array())
              .square()
              .sum();
    }
    if (end < n_) left_tension = tension(end - 1);
    hooks.finish(first, end);
  }
  out.shear_force = shear;
  out.normal_load = normal_force_;
  out.viscous_power = eta_ * squared_velocity_differences;
}

double Chain1D::elasticEnergy(const Vector& u, double stage_position) const {
  double energy = 0.0;
  for (int i = 0; i + 1 < n_; ++i) energy += 0.5 * k_ * std::pow(u[i + 1] - u[i], 2);
  for (int i = 0; i < n_; ++i) {
    energy += 0.5 * driving_stiffness_[i] * std::pow(stage_position + pusher_offset_[i] - u[i], 2);
  }
  return energy;
}

SparseMatrix Chain1D::stiffnessMatrix() const {
  return assembleSparse(n_, 3, [this](auto&& add) { addStiffness(add); });
}

NodeStiffness Chain1D::nodeStiffness() const {
  return collectNodeStiffness(n_, 1, [this](auto&& add) { addStiffness(add); });
}

SparseMatrix Chain1D::dampingMatrix() const {
  return assembleSparse(n_, 3, [this](auto&& add) { addNeighbourCoupling(add, eta_); });
}

std::vector<int> Chain1D::blockedDofsDuringLoading() const {
  // A prescribed shear profile is an equilibrium of the free chain held by the pusher.
  if (!initial_shear_.empty()) return {};
  return Model::blockedDofsDuringLoading();
}

Vector Chain1D::initialBodyForce() const {
  if (initial_shear_.empty()) return Vector();
  return Eigen::Map<const Vector>(initial_shear_.data(), n_);
}

void Chain1D::connectPusher(const Vector& u) {
  pusher_connected_ = true;
  pusher_offset_ = u;
  updateDrivingStiffness();
}

void Chain1D::disconnectPusher() {
  pusher_connected_ = false;
  updateDrivingStiffness();
}

void Chain1D::nodePositions(const Vector& u, std::vector<double>& x, std::vector<double>& z) const {
  x.resize(n_);
  z.assign(n_, 0.0);
  for (int i = 0; i < n_; ++i) x[i] = i * spacing_ + u[i];
}

std::vector<double> Chain1D::nodeSpeeds(const Vector& v) const {
  std::vector<double> speed(n_);
  for (int i = 0; i < n_; ++i) speed[i] = std::abs(v[i]);
  return speed;
}

GaugeStresses Chain1D::nodeStresses(const Vector&) const {
  GaugeStresses zero;
  zero.sigma_xx.assign(n_, 0.0);
  zero.sigma_zz.assign(n_, 0.0);
  zero.tau_xz.assign(n_, 0.0);
  return zero;
}

}  // namespace friction
