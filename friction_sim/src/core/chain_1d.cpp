#include "friction_sim/chain_1d.h"

#include <cmath>

namespace friction {

Chain1D::Chain1D(const Scene& scene)
    : n_(scene.chain.blocks),
      length_(scene.geometry.length),
      spacing_(n_ > 1 ? length_ / (n_ - 1) : length_),
      mass_(scene.material.density * length_ * scene.geometry.height * scene.geometry.width / n_),
      k_(n_ > 1 ? scene.material.youngs_modulus * scene.geometry.height * scene.geometry.width / spacing_
                : 0.0),
      eta_(std::sqrt(scene.material.damping_coefficient * k_ * mass_)),
      area_per_block_(spacing_ * scene.geometry.width),
      top_driving_(scene.chain.driving == ChainDriving::Top),
      pusher_k_(scene.pusher.stiffness),
      pushing_height_(scene.pusher.height),
      tilt_(scene.chain.tilt),
      torque_share_(scene.chain.torque_share),
      normal_force_(scene.load.normal_force),
      xi_(n_, 0.0),
      xi_square_sum_(0.0),
      initial_shear_(scene.chain.initial_shear),
      pusher_offset_(n_, 0.0) {
  if (n_ > 1) {
    for (int i = 0; i < n_; ++i) {
      xi_[i] = 2.0 * i * spacing_ / length_ - 1.0;
      xi_square_sum_ += xi_[i] * xi_[i];
    }
  }
}

double Chain1D::torqueCoefficient(double shear_force) const {
  return xi_square_sum_ > 0.0 ? 2.0 * torque_share_ * pushing_height_ * shear_force / (length_ * xi_square_sum_) : 0.0;
}

std::vector<double> Chain1D::normalForces(double shear_force) const {
  const double torque = torqueCoefficient(shear_force);
  std::vector<double> w(n_);
  for (int i = 0; i < n_; ++i) w[i] = normal_force_ / n_ * (1.0 + tilt_ * xi_[i]) + torque * xi_[i];
  return w;
}

double Chain1D::drivingStiffness(int block) const {
  if (!pusher_connected_) return 0.0;
  if (top_driving_) return pusher_k_ / n_;
  return block == 0 ? pusher_k_ : 0.0;
}

void Chain1D::evaluate(const Vector& u, const Vector& v, double stage_position, ForceEvaluation& out) const {
  out.force.setZero(n_);
  double viscous_power = 0.0;
  for (int i = 0; i + 1 < n_; ++i) {
    const double dv = v[i + 1] - v[i];
    const double bond = k_ * (u[i + 1] - u[i]) + eta_ * dv;
    viscous_power += eta_ * dv * dv;
    out.force[i] += bond;
    out.force[i + 1] -= bond;
  }
  double shear = 0.0;
  for (int i = 0; i < n_; ++i) {
    const double stiffness = drivingStiffness(i);
    if (stiffness == 0.0) continue;
    const double force = stiffness * (stage_position + pusher_offset_[i] - u[i]);
    out.force[i] += force;
    shear += force;
  }
  out.shear_force = shear;
  out.normal_load = normal_force_;
  out.viscous_power = viscous_power;
  out.normal_force.resize(n_);
  const double torque = torqueCoefficient(shear);
  for (int i = 0; i < n_; ++i) {
    out.normal_force[i] = std::max(0.0, normal_force_ / n_ * (1.0 + tilt_ * xi_[i]) + torque * xi_[i]);
  }
}

double Chain1D::elasticEnergy(const Vector& u, double stage_position) const {
  double energy = 0.0;
  for (int i = 0; i + 1 < n_; ++i) energy += 0.5 * k_ * std::pow(u[i + 1] - u[i], 2);
  for (int i = 0; i < n_; ++i) {
    energy += 0.5 * drivingStiffness(i) * std::pow(stage_position + pusher_offset_[i] - u[i], 2);
  }
  return energy;
}

SparseMatrix Chain1D::stiffnessMatrix() const {
  std::vector<Eigen::Triplet<double>> entries;
  for (int i = 0; i + 1 < n_; ++i) {
    entries.emplace_back(i, i, k_);
    entries.emplace_back(i + 1, i + 1, k_);
    entries.emplace_back(i, i + 1, -k_);
    entries.emplace_back(i + 1, i, -k_);
  }
  for (int i = 0; i < n_; ++i) entries.emplace_back(i, i, drivingStiffness(i));
  SparseMatrix matrix(n_, n_);
  matrix.setFromTriplets(entries.begin(), entries.end());
  return matrix;
}

SparseMatrix Chain1D::dampingMatrix() const {
  std::vector<Eigen::Triplet<double>> entries;
  for (int i = 0; i + 1 < n_; ++i) {
    entries.emplace_back(i, i, eta_);
    entries.emplace_back(i + 1, i + 1, eta_);
    entries.emplace_back(i, i + 1, -eta_);
    entries.emplace_back(i + 1, i, -eta_);
  }
  SparseMatrix matrix(n_, n_);
  matrix.setFromTriplets(entries.begin(), entries.end());
  return matrix;
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
  for (int i = 0; i < n_; ++i) pusher_offset_[i] = u[i];
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
