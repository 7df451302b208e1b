// A scene describes one whole experiment of the rig: the slider model, its material and geometry,
// the friction law, the loads, the pusher, the stage program, the integrator, the instruments and
// when to stop. Every field states its unit and meaning; SI units, REP 103 axes (x along the track
// in the sliding direction, trailing edge at x = 0; z up, interface at z = 0).
//
// The defaults are MODEL.md's `pmma_2d` table.
#pragma once

#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace friction {

enum class ModelKind { Lattice2D, Chain1D };
enum class SpringForm { Geometric, Linearised };
enum class TopLoadKind { Uniform, SpringMattress };
/// How the interface moves tangentially while F_Z is applied (MODEL.md §2, loading protocol).
enum class InterfaceLoading {
  Stuck,  ///< held in x, as MODEL.md §2 step 1: the slider's blocked Poisson expansion stays in the interface as shear
  Free,   ///< free in x (a lubricated placement): no shear stored; the nodes stick where the load left them
};
enum class ChainDriving { Side, Top };
enum class FrictionLawKind { AmontonsCoulomb, SlipWeakening, RateState };
enum class IntegratorKind { VelocityVerlet, RungeKutta4 };
enum class StageMode { Velocity, Hold, Position };

struct GeometrySpec {
  double length = 0.140;  ///< m, slider length L along x
  double height = 0.075;  ///< m, slider height H along z
  double width = 0.006;   ///< m, slider width B along y (plane-stress thickness)
};

struct MaterialSpec {
  double density = 1200.0;        ///< kg/m^3, ρ; slider mass M = ρ·L·H·B
  double youngs_modulus = 3.0e9;  ///< Pa, E; sets k = 3BE/4 (2D) or k = EHB/a (1D)
  /// dimensionless c in the pair damping η = sqrt(c·k·m); 0 switches damping off
  double damping_coefficient = 0.1;
};

struct LatticeSpec {
  int nodes_x = 57;  ///< N_x, nodes along x (spacing l = L/(N_x−1) must equal H/(N_z−1))
  int nodes_z = 31;  ///< N_z, nodes along z
  /// geometric: central springs along the current bond; linearised: projected on the rest bond
  SpringForm spring_form = SpringForm::Geometric;
  double foundation_ratio = 0.5;  ///< k_f/k, one-sided normal spring of each bottom node
};

struct ChainSpec {
  int blocks = 57;                            ///< N, number of blocks (1 = a single block on a spring)
  ChainDriving driving = ChainDriving::Side;  ///< side: pusher on block 0; top: K/N on every block
  double tilt = 0.0;          ///< θ, dimensionless tilt of the normal load (θ > 0 loads the leading edge)
  double torque_share = 0.0;  ///< g ∈ [0, 1], share of the moment h·F_X carried by the interface
  /// N, per-block friction force at t = 0 (empty: no stored shear); length must equal `blocks`
  std::vector<double> initial_shear;
};

/// Rate-and-state friction with the ageing law (friction.law rate_state, MODEL.md §4):
/// µ(v, φ) = f0 + a·ln(1 + |v|/v*) + b·f0·ln(1 + φ/φ*), dφ/dt = 1 − |v|·φ/D. Defaults: PMMA.
struct RateStateSpec {
  double reference_coefficient = 0.285;  ///< f0, dimensionless
  double direct_effect = 0.005;          ///< a, dimensionless: µ's rise per e-fold of slip speed
  double ageing_effect = 0.075;          ///< b, dimensionless: b·f0 is µ's rise per e-fold of contact age
  double characteristic_slip = 0.5e-6;   ///< m, D: the slip that renews the contacts
  double reference_speed = 1.0e-7;       ///< m/s, v*
  double reference_age = 0.33e-3;        ///< s, φ*
  double initial_age = 100.0;            ///< s, φ of every contact when the run starts (F_Z applied)

  /// µ at slip speed `speed` (m/s, ≥ 0) and contact age `age` (s).
  double coefficient(double speed, double age) const {
    return reference_coefficient + direct_effect * std::log1p(speed / reference_speed) +
           ageing_effect * reference_coefficient * std::log1p(age / reference_age);
  }
  /// µ(0, φ): a stuck contact of age `age` (s) holds up to this times N.
  double staticCoefficient(double age) const { return coefficient(0.0, age); }
  /// ∂µ/∂v (s/m) at slip speed `speed`.
  double speedSlope(double speed) const { return direct_effect / (reference_speed + speed); }
  /// µ of steady sliding at `speed` (m/s, > 0): φ = D/speed.
  double steadyStateCoefficient(double speed) const { return coefficient(speed, characteristic_slip / speed); }
  /// s, the age of a contact `age` (s) old after it slid `slip` (m) at a constant speed over `elapsed` (s):
  /// the ageing law dφ/dt = 1 − vφ/D solved exactly, φ relaxing towards D/v as exp(−|slip|/D).
  double ageAfterSlip(double age, double slip, double elapsed) const {
    const double renewed = std::abs(slip) / characteristic_slip;
    // elapsed·(1 − e^(−x))/x, which is elapsed as x → 0.
    const double grown = renewed > 0.0 ? elapsed * -std::expm1(-renewed) / renewed : elapsed;
    return age * std::exp(-renewed) + grown;
  }
};

struct FrictionSpec {
  FrictionLawKind law = FrictionLawKind::AmontonsCoulomb;  ///< the sliding resistance µ (MODEL.md §4)
  double static_coefficient = 0.4;    ///< µ_s, dimensionless: a stuck node holds up to µ_s·N (not rate_state)
  double kinetic_coefficient = 0.17;  ///< µ_k, dimensionless (≤ µ_s): sliding friction, after weakening
  double weakening_length = 0.0;      ///< m, ξ_µ of linear slip weakening (0 = Amontons–Coulomb)
  RateStateSpec rate_state;           ///< the rate_state law's parameters
  /// N/m, k_T: a stuck node is held by this spring to its anchor; 0 = rigid stick constraint
  double interfacial_stiffness = 0.0;

  /// µ_s at the start of the run: static_coefficient, or rate_state's µ(0, initial_age).
  double initialStaticCoefficient() const {
    return law == FrictionLawKind::RateState ? rate_state.staticCoefficient(rate_state.initial_age)
                                             : static_coefficient;
  }
};

struct LoadSpec {
  double normal_force = 1920.0;            ///< N, F_Z pressed on the top face (downwards)
  TopLoadKind top = TopLoadKind::Uniform;  ///< 2D only: how F_Z reaches the top row
  /// The interface's tangential motion while F_Z is applied. 2D only in effect: the chain has no Poisson
  /// expansion, so F_Z moves none of its blocks either way.
  InterfaceLoading interface_while_loading = InterfaceLoading::Stuck;
  double mattress_stiffness = 0.0;  ///< N/m per top node, k_top (spring_mattress only; 0 = k)
  /// N/m, total horizontal stiffness of the mattress plate shared by the top nodes (0 = plate free in x)
  double mattress_horizontal_stiffness = 0.0;
};

struct PusherSpec {
  double stiffness = 4.0e6;  ///< N/m, K, loading-stage stiffness (load cell included)
  double height = 0.005;     ///< m, h, pushing height above the interface
  /// m, optional band [band_min, band_max] of pushed rows (2D); equal values = single row at `height`
  double band_min = -1.0;
  double band_max = -1.0;
  bool hasBand() const { return band_min >= 0.0 && band_max >= 0.0; }
};

/// One segment of the stage program.
struct StageSegment {
  StageMode mode = StageMode::Velocity;  ///< drive at `speed`, hold still, or travel to `target`
  double speed = 4.0e-4;                 ///< m/s, stage speed (velocity mode) or travel speed (position mode)
  double target = 0.0;                   ///< m, stage position to reach (position mode)
  double duration = std::numeric_limits<double>::infinity();  ///< s, how long the segment lasts
};

struct StageSpec {
  std::vector<StageSegment> program{StageSegment{}};  ///< segments run in order; the last one persists
  double max_speed = 1.0;                             ///< m/s, commands faster than this are refused
};

struct IntegratorSpec {
  IntegratorKind scheme = IntegratorKind::VelocityVerlet;  ///< the explicit time integrator
  double time_step = 2.0e-7;  ///< s, dt; must be below the stability limit computed from the scene
  /// while the whole interface sticks, jump along the static equilibrium to the next threshold
  /// crossing instead of integrating (MODEL.md §5); needs rigid sticking (interfacial_stiffness 0)
  bool fast_forward = false;
};

struct InstrumentSpec {
  double loading_curve_rate = 1.0e4;    ///< Hz of simulated time, load-cell samples (F_X, F_Z, ΣN, N_sliding)
  double gauge_height = 0.002;          ///< m, z_g of the strain gauges above the interface
  std::vector<double> gauge_positions;  ///< m, gauge x positions; empty = every lattice column
  int front_fit_nodes = 5;              ///< nodes in the sliding linear fit of first-unstick times for v_c(x)
  static constexpr int kFewestFrontFitNodes = 2;  ///< a line through fewer is no fit
  /// m/s, a node slips in a slip event when it slides at least this fast; 0: whenever it slides
  /// (SlipCriterion; rate_state nodes creep between events)
  double event_slip_speed = 0.0;
};

struct StopSpec {
  int global_events = 1;  ///< stop after this many global slip events have ended (0 = never)
  double time = 10.0;     ///< s, simulated time limit
  double stage_travel = std::numeric_limits<double>::infinity();  ///< m, stop after this stage travel
};

/// Whether `stop` has a condition that ends a run: a count of global events, or a finite time or travel
/// (a negative count is refused on its own, not also as no condition).
inline bool endsTheRun(const StopSpec& stop) {
  return stop.global_events != 0 || stop.time < std::numeric_limits<double>::infinity() ||
         stop.stage_travel < std::numeric_limits<double>::infinity();
}
/// Whether a run under `stop` has ended: `global_events` global slip events ended, the clock at `time`
/// (s), the stage moved by `stage_travel` (m). The simulator's rule, and a controller's for its protocol.
inline bool stopReached(const StopSpec& stop, int global_events, double time, double stage_travel) {
  return (stop.global_events > 0 && global_events >= stop.global_events) || !(time < stop.time) ||
         !(stage_travel < stop.stage_travel);
}
/// The refusal of a stop condition that does not (scenes and set_run_end alike).
constexpr const char* kNoEndProblem =
    "no condition, so the run would never end; give global_events, time or stage_travel";

struct Scene {
  std::string name = "pmma_2d";            ///< names the run's results (results/<name>) and its summary
  ModelKind model = ModelKind::Lattice2D;  ///< 2D lattice in the x–z plane, or 1D chain of blocks
  GeometrySpec geometry;
  MaterialSpec material;
  LatticeSpec lattice;
  ChainSpec chain;
  FrictionSpec friction;
  LoadSpec load;
  PusherSpec pusher;
  StageSpec stage;
  IntegratorSpec integrator;
  InstrumentSpec instruments;
  StopSpec stop;
};

}  // namespace friction
