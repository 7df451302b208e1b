#include "friction_sim/solvers/integrator.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <vector>

#include "friction_sim/model/model.h"

namespace friction {

double Dynamics::accelerationInStrips(const Vector& u, const Vector& v, double t, Vector& a, StripHooks& hooks) {
  const int size = static_cast<int>(u.size());
  hooks.prepare(0, size);
  const double power = acceleration(u, v, t, a);
  hooks.finish(0, size);
  return power;
}

VerletPasses::VerletPasses(Vector& u, Vector& v, const Vector& a, double dt)
    : displacement_(u.data()), velocity_(v.data()), acceleration_(a.data()), dt_(dt), half_dt_(0.5 * dt) {}

void VerletPasses::prepare(int first, int end) {
  kickAndDrift(end - first, half_dt_, dt_, acceleration_ + first, velocity_ + first, displacement_ + first);
}

void VerletPasses::finish(int first, int end) { kick(end - first, half_dt_, acceleration_ + first, velocity_ + first); }

void VerletPasses::kickAndDrift(int count, double half_dt, double dt, const double* __restrict acceleration,
                                double* __restrict velocity, double* __restrict displacement) {
  for (int i = 0; i < count; ++i) {
    velocity[i] += half_dt * acceleration[i];
    displacement[i] += dt * velocity[i];
  }
}

void VerletPasses::kick(int count, double half_dt, const double* __restrict acceleration, double* __restrict velocity) {
  for (int i = 0; i < count; ++i) velocity[i] += half_dt * acceleration[i];
}

double VelocityVerlet::step(Dynamics& dynamics, Vector& u, Vector& v, Vector& a, double& power, double t, double dt) {
  VerletPasses passes(u, v, a, dt);
  // Midpoint rule: the half-step velocity is the step's mean velocity.
  power = dynamics.accelerationInStrips(u, v, t + dt, a, passes);
  return power * dt;
}

double RungeKutta4::step(Dynamics& dynamics, Vector& u, Vector& v, Vector& a, double& power, double t, double dt) {
  static constexpr double kStageShift[4] = {0.0, 0.5, 0.5, 1.0};
  static constexpr double kWeight[4] = {1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0};
  k_u_[0] = v;
  k_v_[0] = a;
  double dissipated = kWeight[0] * dt * power;
  for (int stage = 1; stage < 4; ++stage) {
    const double h = kStageShift[stage] * dt;
    u_stage_ = u + h * k_u_[stage - 1];
    v_stage_ = v + h * k_v_[stage - 1];
    k_u_[stage] = v_stage_;
    dissipated += kWeight[stage] * dt * dynamics.acceleration(u_stage_, v_stage_, t + h, k_v_[stage]);
  }
  for (int stage = 0; stage < 4; ++stage) {
    u.noalias() += kWeight[stage] * dt * k_u_[stage];
    v.noalias() += kWeight[stage] * dt * k_v_[stage];
  }
  power = dynamics.acceleration(u, v, t + dt, a);
  return dissipated;
}

std::unique_ptr<Integrator> buildIntegrator(IntegratorKind kind) {
  if (kind == IntegratorKind::RungeKutta4) return std::make_unique<RungeKutta4>();
  return std::make_unique<VelocityVerlet>();
}

namespace {

class DampedOscillator : public Dynamics {
 public:
  DampedOscillator(double omega, double damping_rate) : omega_(omega), damping_rate_(damping_rate) {}
  double acceleration(const Vector& u, const Vector& v, double, Vector& a) override {
    a.resize(1);
    a[0] = -omega_ * omega_ * u[0] - damping_rate_ * v[0];
    return 0.0;
  }

 private:
  double omega_, damping_rate_;
};

double spectralRadius(IntegratorKind kind, double omega, double damping_rate, double dt) {
  DampedOscillator oscillator(omega, damping_rate);
  auto integrator = buildIntegrator(kind);
  Eigen::Matrix3d map;
  for (int column = 0; column < 3; ++column) {
    Vector u = Vector::Constant(1, column == 0 ? 1.0 : 0.0);
    Vector v = Vector::Constant(1, column == 1 ? 1.0 : 0.0);
    Vector a = Vector::Constant(1, column == 2 ? 1.0 : 0.0);
    if (kind == IntegratorKind::RungeKutta4) oscillator.acceleration(u, v, 0.0, a);
    double power = 0.0;
    integrator->step(oscillator, u, v, a, power, 0.0, dt);
    map.col(column) << u[0], v[0], a[0];
  }
  return map.eigenvalues().cwiseAbs().maxCoeff();
}

/// Largest eigenvalue of a symmetric matrix by Lanczos iteration: its top Ritz value converges far
/// faster than power iteration when the top of the spectrum is dense, as it is for large lattices
/// (power iteration needed thousands of products at 10⁶ nodes). Approaches from below.
double largestEigenvalue(const SparseMatrix& matrix) {
  const int n = static_cast<int>(matrix.rows());
  if (n == 0) return 0.0;
  constexpr int kMaxSteps = 400;
  // Start close to the grid-scale (alternating) modes, with every other mode present too.
  Vector q(n), previous = Vector::Zero(n), w(n);
  for (int i = 0; i < n; ++i) q[i] = (i % 2 ? -1.0 : 1.0) * (1.0 + 0.3 * std::sin(1.7 * i + 0.3));
  q.normalize();
  std::vector<double> alpha, beta;
  double estimate = 0.0, beta_previous = 0.0;
  for (int step = 0; step < std::min(n, kMaxSteps); ++step) {
    w.noalias() = matrix * q;
    alpha.push_back(q.dot(w));
    w -= alpha.back() * q + beta_previous * previous;
    const double beta_next = w.norm();
    // The tridiagonal projection's largest eigenvalue is the estimate.
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> projection;
    projection.computeFromTridiagonal(Eigen::Map<const Vector>(alpha.data(), alpha.size()),
                                      Eigen::Map<const Vector>(beta.data(), beta.size()), Eigen::EigenvaluesOnly);
    const double ritz = projection.eigenvalues().maxCoeff();
    const bool converged = step > 5 && std::abs(ritz - estimate) <= 1e-9 * std::abs(ritz);
    estimate = ritz;
    if (converged || beta_next <= 1e-14 * std::abs(ritz)) break;
    beta.push_back(beta_next);
    previous.swap(q);
    q = w / beta_next;
    beta_previous = beta_next;
  }
  return estimate;
}

}  // namespace

double stabilityLimit(IntegratorKind kind, double omega_max, double damping_rate) {
  if (omega_max <= 0.0) return std::numeric_limits<double>::infinity();
  // Work in units of 1/ω: the amplification matrix then has entries of order one and its eigenvalues
  // are not swamped by round-off.
  const double relative_damping = damping_rate / omega_max;
  auto stable = [&](double dt) { return spectralRadius(kind, 1.0, relative_damping, dt) <= 1.0 + 1e-9; };
  double low = 0.0, high = 1.0;
  while (stable(high)) {
    low = high;
    high *= 1.5;
  }
  for (int iteration = 0; iteration < 60; ++iteration) {
    const double mid = 0.5 * (low + high);
    (stable(mid) ? low : high) = mid;
  }
  return low / omega_max;
}

ModeBounds modeBounds(const Model& model, double interfacial_stiffness) {
  SparseMatrix stiffness = model.stiffnessMatrix();
  for (int node = 0; node < model.interfaceNodeCount(); ++node) {
    const int dof = model.interfaceDof(node);
    stiffness.coeffRef(dof, dof) += interfacial_stiffness;
  }
  // Lanczos approaches from below; 1 % covers what is left after it stops.
  constexpr double kMargin = 1.01;
  ModeBounds bounds;
  bounds.omega_max = std::sqrt(kMargin * largestEigenvalue(stiffness) / model.nodeMass());
  bounds.damping_rate = kMargin * largestEigenvalue(model.dampingMatrix()) / model.nodeMass();
  return bounds;
}

double sceneStabilityLimit(const Scene& scene) {
  const auto model = buildModel(scene);
  const ModeBounds bounds = modeBounds(*model, scene.friction.interfacial_stiffness);
  return stabilityLimit(scene.integrator.scheme, bounds.omega_max, bounds.damping_rate);
}

}  // namespace friction
