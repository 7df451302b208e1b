// What the rig's instruments report (MODEL.md §6), as plain structs the nodes turn into messages.
#pragma once

#include <cstdint>
#include <vector>

#include "friction_sim/model/model.h"

namespace friction {

/// Load cells and counters at one instant.
struct LoadCellReading {
  double time = 0.0;                  ///< s, simulated
  double stage_position = 0.0;        ///< m, X_s
  double shear_force = 0.0;           ///< N, F_X on the pusher
  double normal_force = 0.0;          ///< N, F_Z on the top face (positive pressing down)
  double interface_normal_sum = 0.0;  ///< N, Σ N_i measured at the interface
  int sliding_nodes = 0;              ///< N_sliding
};

/// The weight of the later of two readings, at `b_time` (s), at time t (s) against the earlier, at
/// `a_time`: 0 at a's time, 1 at b's (and 1 if the times coincide).
double interpolationWeight(double a_time, double b_time, double t);

/// The load cells at time t between two readings, linearly (exact across a fast-forward jump, where
/// the forces are affine in time); the counters are those of `b`.
LoadCellReading interpolate(const LoadCellReading& a, const LoadCellReading& b, double t);

/// What the stage does at one instant.
struct StageReading {
  StageMode mode = StageMode::Hold;
  double velocity = 0.0;  ///< m/s
  double target = 0.0;    ///< m, of a move to a position
  double travel = 0.0;    ///< m, total distance moved
};

/// The stage state: the load cells (time, stage position, forces) and what the stage does.
struct StageStateReading {
  LoadCellReading cells;
  StageReading stage;
};

/// The stage state at time t between two readings across a fast-forward jump: the load cells and the
/// travel linearly; the stage keeps `a`'s motion until `b`'s time (a jump ends where the motion changes).
StageStateReading interpolate(const StageStateReading& a, const StageStateReading& b, double t);

/// The fast camera's frame: the interface's state per node.
struct InterfaceFrame {
  double time = 0.0;                   ///< s
  std::vector<double> position;        ///< m, rest x of each interface node
  std::vector<std::uint8_t> state;     ///< 0 stuck, 1 sliding, 2 detached (contact lost)
  std::vector<double> slip_velocity;   ///< m/s, dx/dt
  std::vector<double> slip;            ///< m, accumulated since the run started
  std::vector<double> normal_force;    ///< N, N_i
  std::vector<double> friction_force;  ///< N, f_i, x force of the track on the slider
  std::vector<double> normal_stress;   ///< Pa, σ_i = N_i/(l·B), positive in compression
  std::vector<double> shear_stress;    ///< Pa, τ_i = −f_i/(l·B), positive when resisting a push in +x
  /// µ_s each node holds up to now, dimensionless: the law's (rate_state: µ(0, φ), rising with the age φ)
  std::vector<double> static_coefficient;
};

/// Strain gauges at height z_g: stress tensor components (tension positive).
struct GaugeProfile {
  double time = 0.0;             ///< s
  double height = 0.0;           ///< m, z_g
  std::vector<double> position;  ///< m, x of each gauge
  GaugeStresses stress;
};

/// The slider's nodes at one instant, for visualisation.
struct LatticeSnapshot {
  double time = 0.0;                          ///< s
  int nodes_x = 0, nodes_z = 0;               ///< grid shape (the chain: N × 1)
  double spacing = 0.0;                       ///< m, rest spacing
  std::vector<double> x, z;                   ///< m, current node positions
  std::vector<double> speed;                  ///< m/s
  GaugeStresses stress;                       ///< Pa, per node
  std::vector<std::uint8_t> interface_state;  ///< per interface node, as in InterfaceFrame
  double stage_position = 0.0;                ///< m
  double pusher_height = 0.0;                 ///< m, Model::pushingHeight
  double normal_force = 0.0;                  ///< N
};

/// Strain gauges at time t between two profiles at the same positions, linearly.
GaugeProfile interpolate(const GaugeProfile& a, const GaugeProfile& b, double t);

/// The camera's frame at time t between two frames of a fast-forward jump: slip, forces and stresses
/// linearly; the contact states are `a`'s until `b`'s time (a jump ends where a state changes).
InterfaceFrame interpolate(const InterfaceFrame& a, const InterfaceFrame& b, double t);

/// The slider's nodes at time t between two snapshots of a fast-forward jump, as the frames are.
LatticeSnapshot interpolate(const LatticeSnapshot& a, const LatticeSnapshot& b, double t);

/// Energy budget since the loaded equilibrium: work in = Δelastic + Δkinetic + dissipated.
struct EnergyBudget {
  double work_in = 0.0;               ///< J, by the pusher's stage and the top load
  double elastic = 0.0;               ///< J, stored now (springs, foundation, pusher, top, anchors)
  double initial_elastic = 0.0;       ///< J, stored at the loaded equilibrium
  double kinetic = 0.0;               ///< J
  double friction_dissipation = 0.0;  ///< J
  double viscous_dissipation = 0.0;   ///< J
  /// J, work_in − (Δelastic + kinetic + dissipation): zero for exact integration
  double residual() const {
    return work_in - (elastic - initial_elastic + kinetic + friction_dissipation + viscous_dissipation);
  }
  /// residual relative to the largest term of the budget; NaN where no energy changed hands (every term
  /// below 10⁻⁹ of the stored energy)
  double relativeResidual() const;
};

}  // namespace friction
