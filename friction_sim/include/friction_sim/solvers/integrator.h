// Time integrators: velocity Verlet and classical fourth-order Runge–Kutta, both advancing
// u'' = a(u, u', t). Stick/slip transitions happen between steps (ContactInterface); within a step the
// contact states are fixed.
#pragma once

#include <memory>

#include "friction_sim/model/model.h"

namespace friction {

/// The system an integrator advances.
class Dynamics {
 public:
  virtual ~Dynamics() = default;
  /// Writes the acceleration at (u, v, t) into `a`; returns the power (W) dissipated by the
  /// velocity-dependent forces there.
  virtual double acceleration(const Vector& u, const Vector& v, double t, Vector& a) = 0;
  /// acceleration() with the caller's passes over the state fused in strip by strip (StripHooks; a
  /// range is finished once its accelerations are final). By default one strip.
  virtual double accelerationInStrips(const Vector& u, const Vector& v, double t, Vector& a, StripHooks& hooks);
};

class Integrator {
 public:
  virtual ~Integrator() = default;
  /// Advances (u, v) from t to t + dt. On entry `a` (sized like u) and `power` are the acceleration and
  /// dissipated power at the start of the step; on exit, at its end. Returns the energy (J) dissipated by the
  /// velocity-dependent forces during the step, integrated with the scheme's own quadrature.
  virtual double step(Dynamics& dynamics, Vector& u, Vector& v, Vector& a, double& power, double t, double dt) = 0;
};

/// Velocity Verlet's passes over the state, run by a force evaluation strip by strip (StripHooks): a
/// range is kicked and drifted when prepared, while its accelerations are still those of the step's
/// start, and given its closing kick when finished.
class VerletPasses : public StripHooks {
 public:
  /// (u, v) in m and m/s, `a` in m/s², dt in s; all kept by reference.
  VerletPasses(Vector& u, Vector& v, const Vector& a, double dt);
  void prepare(int first, int end) override;
  void finish(int first, int end) override;
  double closingKick() const override { return half_dt_; }

 private:
  // Static, with restrict parameters: GCC honours restrict only on parameters.
  static void kickAndDrift(int count, double half_dt, double dt, const double* __restrict acceleration,
                           double* __restrict velocity, double* __restrict displacement);
  static void kick(int count, double half_dt, const double* __restrict acceleration, double* __restrict velocity);

  double* displacement_;
  double* velocity_;
  const double* acceleration_;
  double dt_, half_dt_;
};

/// Kick–drift–kick velocity Verlet; velocity-dependent forces are evaluated with the half-step velocity.
/// Its passes run inside the force evaluation's strips (Dynamics::accelerationInStrips).
class VelocityVerlet : public Integrator {
 public:
  double step(Dynamics& dynamics, Vector& u, Vector& v, Vector& a, double& power, double t, double dt) override;
};

/// Classical RK4 on the first-order system (u, v); one extra evaluation at the end gives `a`.
class RungeKutta4 : public Integrator {
 public:
  double step(Dynamics& dynamics, Vector& u, Vector& v, Vector& a, double& power, double t, double dt) override;

 private:
  Vector u_stage_, v_stage_, k_u_[4], k_v_[4];
};

std::unique_ptr<Integrator> buildIntegrator(IntegratorKind kind);

/// s, the largest stable time step of `kind` for the scene's stiffest, most damped mode:
/// ω² = λ_max(K)/m and damping rate c = λ_max(C)/m, found from the integrator's own amplification
/// of the damped oscillator u'' = −ω²u − c·u'.
double stabilityLimit(IntegratorKind kind, double omega_max, double damping_rate);

/// Upper bounds on ω_max (rad/s) and c_max (1/s) of a model (with the interfacial stiffness k_T on its
/// interface dofs), from Model's closed-form bounds: no eigenvalue solve.
struct ModeBounds {
  double omega_max = 0.0;     ///< rad/s, at least the highest angular frequency of the undamped model
  double damping_rate = 0.0;  ///< 1/s, at least the highest damping rate c of its modes
};
ModeBounds modeBounds(const Model& model, double interfacial_stiffness);

/// s, the stability limit of a whole scene.
double sceneStabilityLimit(const Scene& scene);

}  // namespace friction
