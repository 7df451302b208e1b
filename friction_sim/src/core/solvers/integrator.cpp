#include "friction_sim/solvers/integrator.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

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

/// λ_max of a symmetric matrix of one or two rows, given as its diagonal d and off-diagonal entry e.
double blockTop(double d0, double d1, double e) { return 0.5 * (d0 + d1) + std::hypot(0.5 * (d0 - d1), e); }

/// An upper bound on λ_max(K), K = B + A with B the bonds' part and A the anchors (diagonal): since
/// (x − y)² ≤ 2x² + 2y², a bond's k_b(e_b·(u_a − u_b))² is at most twice its share of the diagonal
/// blocks of its two nodes, so uᵀKu ≤ Σ_nodes u_iᵀ(2B_ii + A_ii)u_i and λ_max(K) ≤ max_i λ_max(2K_ii − A_ii).
/// At an interior node of the lattice this is 6k, the infinite lattice's top; at its edges nodes have
/// fewer bonds, which leaves room for the anchors there.
double nodeByNodeBound(const NodeStiffness& blocks, const Vector& anchors) {
  const int nodes = static_cast<int>(blocks.xx.size());
  const bool planar = blocks.zz.size() > 0;
  double bound = 0.0;
  for (int node = 0; node < nodes; ++node) {
    const double x = 2.0 * blocks.xx[node] - anchors[node];
    bound =
        std::max(bound, planar ? blockTop(x, 2.0 * blocks.zz[node] - anchors[nodes + node], 2.0 * blocks.xz[node]) : x);
  }
  return bound;
}

}  // namespace

double stabilityLimit(IntegratorKind kind, double omega_max, double damping_rate) {
  // A mode of infinite (or undefined) frequency or damping: no step is stable. The eigenvalues of a
  // non-finite amplification matrix would not converge.
  if (!std::isfinite(omega_max) || !std::isfinite(damping_rate)) return 0.0;
  if (omega_max <= 0.0) return std::numeric_limits<double>::infinity();
  // Work in units of 1/ω: the amplification matrix then has entries of order one and its eigenvalues
  // are not swamped by round-off.
  const double relative_damping = damping_rate / omega_max;
  auto stable = [&](double dt) { return spectralRadius(kind, 1.0, relative_damping, dt) <= 1.0 + 1e-9; };
  // Every scheme here is unstable beyond a few periods per step: the growth ends in a few iterations.
  double low = 0.0, high = 1.0;
  for (int growth = 0; growth < 100 && stable(high); ++growth) {
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
  NodeStiffness blocks = model.nodeStiffness();
  Vector anchors = model.anchorStiffness();
  const int nodes = static_cast<int>(blocks.xx.size());
  for (int node = 0; node < model.interfaceNodeCount(); ++node) {
    const int dof = model.interfaceDof(node);
    (dof < nodes ? blocks.xx[dof] : blocks.zz[dof - nodes]) += interfacial_stiffness;
    anchors[dof] += interfacial_stiffness;
  }
  // Two bounds, each close where the other is loose: the bonds' closed form plus the largest anchor
  // (the anchors are a diagonal matrix), and the node-by-node bound, which sees where the anchors are.
  const double stiffness_bound =
      std::min(model.bondStiffnessBound() + anchors.maxCoeff(), nodeByNodeBound(blocks, anchors));
  ModeBounds bounds;
  bounds.omega_max = std::sqrt(stiffness_bound / model.nodeMass());
  bounds.damping_rate = model.dampingBound() / model.nodeMass();
  return bounds;
}

double sceneStabilityLimit(const Scene& scene) {
  const auto model = buildModel(scene);
  const ModeBounds bounds = modeBounds(*model, scene.friction.interfacial_stiffness);
  return stabilityLimit(scene.integrator.scheme, bounds.omega_max, bounds.damping_rate);
}

}  // namespace friction
