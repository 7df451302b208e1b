// Every check a scene must pass before a run starts, in one place.
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <initializer_list>
#include <sstream>

#include "friction_sim/model/chain_1d.h"
#include "friction_sim/model/lattice_2d.h"
#include "friction_sim/scene/scene_io.h"
#include "friction_sim/solvers/integrator.h"

namespace friction {

namespace {

class Checker {
 public:
  /// Records "field: value V is not allowed; allowed: ..." unless `ok`.
  void require(bool ok, const std::string& field, double value, const std::string& allowed) {
    requireSetting(ok, field, value, allowed, problems);
  }
  void positive(const std::string& field, double value) {
    require(std::isfinite(value) && value > 0.0, field, value, "a finite number > 0");
  }
  void nonNegative(const std::string& field, double value) {
    require(std::isfinite(value) && value >= 0.0, field, value, "a finite number >= 0");
  }
  void within(const std::string& field, double value, double low, double high, const std::string& what) {
    std::ostringstream allowed;
    allowed << "[" << low << ", " << high << "] (" << what << ")";
    require(value >= low && value <= high, field, value, allowed.str());
  }
  /// True if no problem so far concerns a field starting with one of `prefixes`.
  bool clean(std::initializer_list<const char*> prefixes) const {
    for (const auto& problem : problems) {
      for (const char* prefix : prefixes) {
        if (problem.rfind(prefix, 0) == 0) return false;
      }
    }
    return true;
  }
  std::vector<std::string> problems;
};

void checkBody(Checker& check, const Scene& s) {
  check.positive("geometry.length", s.geometry.length);
  check.positive("geometry.height", s.geometry.height);
  check.positive("geometry.width", s.geometry.width);
  check.positive("material.density", s.material.density);
  check.positive("material.youngs_modulus", s.material.youngs_modulus);
  check.nonNegative("material.damping_coefficient", s.material.damping_coefficient);
}

void checkLattice(Checker& check, const Scene& s) {
  check.require(s.lattice.nodes_x >= 2, "lattice.nodes_x", s.lattice.nodes_x, "an integer >= 2");
  check.require(s.lattice.nodes_z >= 2, "lattice.nodes_z", s.lattice.nodes_z, "an integer >= 2");
  if (s.lattice.nodes_x >= 2 && s.lattice.nodes_z >= 2 && s.geometry.length > 0 && s.geometry.height > 0) {
    const double spacing_x = s.geometry.length / (s.lattice.nodes_x - 1);
    const double spacing_z = s.geometry.height / (s.lattice.nodes_z - 1);
    if (std::abs(spacing_x - spacing_z) > 1e-6 * spacing_x) {
      // Either count may be the one changed: the refusal names both, and the sizes that fit.
      std::ostringstream text;
      text << "lattice.nodes_x/lattice.nodes_z: values " << s.lattice.nodes_x << ", " << s.lattice.nodes_z
           << " are not allowed; allowed: a square lattice: geometry.height/(nodes_z-1) = " << spacing_z
           << " m must equal geometry.length/(nodes_x-1) = " << spacing_x << " m";
      for (int intervals_x = 1; intervals_x <= 10000; ++intervals_x) {
        const double intervals_z = intervals_x * s.geometry.height / s.geometry.length;
        if (std::abs(intervals_z - std::round(intervals_z)) > 1e-6 * intervals_z || std::round(intervals_z) < 1) {
          continue;
        }
        text << "; sizes that fit " << s.geometry.length << " m x " << s.geometry.height
             << " m: nodes_x - 1 a multiple of " << intervals_x << ", e.g. nodes_x: " << 2 * intervals_x + 1
             << ", nodes_z: " << 2 * std::lround(intervals_z) + 1;
        break;
      }
      check.problems.push_back(text.str());
    }
  }
  check.positive("lattice.foundation_ratio", s.lattice.foundation_ratio);
  check.within("instruments.gauge_height", s.instruments.gauge_height, 0.0, s.geometry.height,
               "inside the slider, 0..geometry.height");
}

void checkChain(Checker& check, const Scene& s) {
  check.require(s.chain.blocks >= 1, "chain.blocks", s.chain.blocks, "an integer >= 1");
  check.require(std::isfinite(s.chain.tilt), "chain.tilt", s.chain.tilt, "a finite number");
  check.within("chain.torque_share", s.chain.torque_share, 0.0, 1.0, "share of the moment h*F_X");
  if (s.load.top != TopLoadKind::Uniform) {
    check.problems.push_back(
        "load.top: spring_mattress is not allowed on the chain; allowed: uniform (the chain has "
        "no top row)");
  }
  if (!s.chain.initial_shear.empty()) {
    check.require(static_cast<int>(s.chain.initial_shear.size()) == s.chain.blocks, "chain.initial_shear (length)",
                  s.chain.initial_shear.size(), "one force per block (chain.blocks) or an empty list");
    for (std::size_t i = 0; i < s.chain.initial_shear.size(); ++i) {
      check.require(std::isfinite(s.chain.initial_shear[i]), "chain.initial_shear[" + std::to_string(i) + "]",
                    s.chain.initial_shear[i], "a finite force in N");
    }
    // Elastic anchors start unstretched, holding nothing: the prescribed shear would be lost at once.
    check.require(s.friction.interfacial_stiffness == 0.0, "friction.interfacial_stiffness",
                  s.friction.interfacial_stiffness, "0 (rigid sticking) with a chain.initial_shear profile");
  }
}

void checkRateState(Checker& check, const Scene& s) {
  const RateStateSpec& r = s.friction.rate_state;
  check.positive("friction.reference_coefficient", r.reference_coefficient);
  check.nonNegative("friction.direct_effect", r.direct_effect);
  check.nonNegative("friction.ageing_effect", r.ageing_effect);
  check.positive("friction.characteristic_slip", r.characteristic_slip);
  check.positive("friction.reference_speed", r.reference_speed);
  check.positive("friction.reference_age", r.reference_age);
  check.require(r.initial_age >= 0.0 && std::isfinite(r.initial_age), "friction.initial_age", r.initial_age,
                "a finite age >= 0 s");
  // Its sliding friction is solved with the closing half-kick's velocity (ContactInterface); Runge–Kutta's
  // stages would evaluate it explicitly, unstable at any usable step.
  if (s.integrator.scheme != IntegratorKind::VelocityVerlet) {
    check.problems.push_back(
        "integrator.scheme: rk4 is not allowed with friction.law rate_state; allowed: velocity_verlet");
  }
}

void checkFriction(Checker& check, const Scene& s) {
  const double mu_s = s.friction.static_coefficient, mu_k = s.friction.kinetic_coefficient;
  check.nonNegative("friction.static_coefficient", mu_s);
  // Against a refused µ_s only its own range: "allowed: [0, 0]" would blame a good µ_k.
  if (mu_s >= 0.0) {
    check.within("friction.kinetic_coefficient", mu_k, 0.0, mu_s, "0 <= mu_k <= mu_s = friction.static_coefficient");
  } else {
    check.nonNegative("friction.kinetic_coefficient", mu_k);
  }
  check.nonNegative("friction.weakening_length", s.friction.weakening_length);
  check.nonNegative("friction.interfacial_stiffness", s.friction.interfacial_stiffness);
  if (s.friction.law == FrictionLawKind::RateState) checkRateState(check, s);
}

void checkLoad(Checker& check, const Scene& s) {
  check.positive("load.normal_force", s.load.normal_force);
  if (check.clean({"geometry.", "material.youngs_modulus", "load.normal_force"})) {
    std::ostringstream allowed;
    allowed << "at most " << largestNormalForce(s) << " N (a mean normal stress F_Z/(L*B) of 5 % of E: a small strain)";
    check.require(s.load.normal_force <= largestNormalForce(s), "load.normal_force", s.load.normal_force,
                  allowed.str());
  }
  check.nonNegative("load.mattress_stiffness", s.load.mattress_stiffness);
  check.nonNegative("load.mattress_horizontal_stiffness", s.load.mattress_horizontal_stiffness);
}

void checkPusher(Checker& check, const Scene& s) {
  const bool lattice = s.model == ModelKind::Lattice2D;
  check.positive("pusher.stiffness", s.pusher.stiffness);
  check.within("pusher.height", s.pusher.height, 0.0, s.geometry.height, "inside the slider, 0..geometry.height");
  // A band is given unless both ends are negative (the default): NaN counts as given, and is refused.
  if (!(s.pusher.band_min < 0.0) || !(s.pusher.band_max < 0.0)) {
    check.require(lattice, "pusher.band_min", s.pusher.band_min, "a band only on the 2D lattice");
    check.within("pusher.band_min", s.pusher.band_min, 0.0, s.pusher.band_max, "0..pusher.band_max");
    check.within("pusher.band_max", s.pusher.band_max, std::fmax(s.pusher.band_min, 0.0), s.geometry.height,
                 "pusher.band_min..geometry.height");
    if (lattice && s.lattice.nodes_x >= 2 && s.lattice.nodes_z >= 2 && s.pusher.hasBand()) {
      const double spacing = s.geometry.length / (s.lattice.nodes_x - 1);  // the lattice's own (Lattice2D)
      check.require(!pushedRowsOf(s.pusher, spacing, s.lattice.nodes_z).empty(), "pusher.band_max", s.pusher.band_max,
                    "a band [band_min, band_max] that contains at least one lattice row");
    }
  }
}

void checkStage(Checker& check, const Scene& s) {
  check.positive("stage.max_speed", s.stage.max_speed);
  std::ostringstream fastest;
  fastest << "|speed| <= stage.max_speed (" << s.stage.max_speed << " m/s)";
  for (std::size_t i = 0; i < s.stage.program.size(); ++i) {
    const StageSegment& segment = s.stage.program[i];
    const std::string where = "stage.program[" + std::to_string(i) + "]";
    check.require(std::isfinite(segment.speed) && std::abs(segment.speed) <= s.stage.max_speed, where + ".speed",
                  segment.speed, fastest.str());
    if (i + 1 < s.stage.program.size()) {
      check.require(segment.duration > 0.0 && std::isfinite(segment.duration), where + ".duration", segment.duration,
                    "a finite duration > 0 s: later segments would never run");
    } else {
      check.require(segment.duration > 0.0, where + ".duration", segment.duration, "a duration > 0 s (.inf allowed)");
    }
    if (segment.mode == StageMode::Position) {
      check.require(segment.speed > 0.0, where + ".speed", segment.speed, "a travel speed > 0 in position mode");
      check.require(std::isfinite(segment.target), where + ".target", segment.target, "a finite position");
    }
  }
}

void checkInstrumentsStopAndIntegrator(Checker& check, const Scene& s) {
  check.positive("instruments.loading_curve_rate", s.instruments.loading_curve_rate);
  for (std::size_t i = 0; i < s.instruments.gauge_positions.size(); ++i) {
    check.within("instruments.gauge_positions[" + std::to_string(i) + "]", s.instruments.gauge_positions[i], 0.0,
                 s.geometry.length, "along the slider, 0..geometry.length");
  }
  check.require(s.instruments.front_fit_nodes >= InstrumentSpec::kFewestFrontFitNodes, "instruments.front_fit_nodes",
                s.instruments.front_fit_nodes, "an integer >= " + std::to_string(InstrumentSpec::kFewestFrontFitNodes));
  check.require(std::isfinite(s.instruments.event_slip_speed) && s.instruments.event_slip_speed >= 0.0,
                "instruments.event_slip_speed", s.instruments.event_slip_speed,
                "a finite speed >= 0 m/s (0: any sliding)");
  check.require(s.stop.global_events >= 0, "stop.global_events", s.stop.global_events, "an integer >= 0");
  // ∞ allowed, as set_run_end allows it: the rig publishes and records its scene with the run's end.
  check.require(s.stop.time > 0.0, "stop.time", s.stop.time, "a time > 0 s (.inf allowed)");
  check.require(s.stop.stage_travel > 0.0, "stop.stage_travel", s.stop.stage_travel, "a travel > 0 m (.inf allowed)");
  if (!endsTheRun(s.stop)) check.problems.push_back(std::string("stop: ") + kNoEndProblem);
  check.positive("integrator.time_step", s.integrator.time_step);
  if (s.integrator.time_step > 0.0) {
    // Samples between steps only interpolate: beyond one a step they resolve nothing and, across a
    // fast-forward jump, fill the memory.
    std::ostringstream allowed;
    allowed << "at most one sample per time step, 1/integrator.time_step = " << 1.0 / s.integrator.time_step << " Hz";
    check.require(s.instruments.loading_curve_rate <= 1.0 / s.integrator.time_step, "instruments.loading_curve_rate",
                  s.instruments.loading_curve_rate, allowed.str());
  }
  if (s.integrator.fast_forward) {
    check.require(s.friction.interfacial_stiffness == 0.0, "friction.interfacial_stiffness",
                  s.friction.interfacial_stiffness, "0 (rigid sticking) when integrator.fast_forward is true");
  }
}

/// The chain's statics: every block pressed on the track whichever way the stage pushes, and a prescribed
/// shear profile within the blocks' static thresholds.
void checkChainStatics(Checker& check, const Scene& s) {
  const Chain1D chain(s);
  // |F_X| stays below the interface's total static friction µ_s·F_Z, in either direction: the stage
  // program or the controller may drive the stage back. w_i is linear in F_X, so the ends suffice.
  const double most_shear = s.friction.initialStaticCoefficient() * s.load.normal_force;
  bool reported = false;
  for (double shear : {0.0, most_shear, -most_shear}) {
    const std::vector<double> w = chain.normalForces(shear);
    for (std::size_t i = 0; i < w.size() && !reported; ++i) {
      if (w[i] > 0.0) continue;
      std::ostringstream text;
      text << "chain.tilt/chain.torque_share: the normal force of block " << i << " would be " << w[i]
           << " N at F_X = " << shear << " N; allowed: every block's normal force w_i > 0 for F_X in [" << -most_shear
           << ", " << most_shear << "] N, the stage pushing or pulling (reduce tilt, torque_share or pusher.height)";
      check.problems.push_back(text.str());
      reported = true;
    }
  }
  // A prescribed shear is held by rigid sticking only below each block's static threshold; at or beyond
  // it the block would slide at t = 0 (at it, from round-off), before any event could be detected. The
  // pusher holds the sum.
  const std::vector<double>& shear_profile = s.chain.initial_shear;
  if (!shear_profile.empty()) {
    double held_by_pusher = 0.0;
    for (double f : shear_profile) held_by_pusher -= f;
    const std::vector<double> w = chain.normalForces(held_by_pusher);
    for (std::size_t i = 0; i < shear_profile.size(); ++i) {
      const double threshold = s.friction.initialStaticCoefficient() * std::max(w[i], 0.0);
      if (std::abs(shear_profile[i]) < threshold) continue;
      std::ostringstream allowed;
      allowed << "|f| < mu_s * w_" << i << " = " << threshold << " N, below the block's static threshold with the "
              << "pusher holding F_X = " << held_by_pusher << " N";
      check.require(false, "chain.initial_shear[" + std::to_string(i) + "]", shear_profile[i], allowed.str());
    }
  }
}

/// dt against the stability limit of the scene, which it returns.
double checkTimeStep(Checker& check, const Scene& s) {
  const double limit = sceneStabilityLimit(s);
  std::ostringstream allowed;
  allowed.precision(4);
  if (limit > 0.0) {
    allowed << "dt < " << limit << " s, the stability limit of this scene for "
            << (s.integrator.scheme == IntegratorKind::RungeKutta4 ? "rk4" : "velocity_verlet");
  } else {
    allowed << "none: the scene's stiffest mode has no finite frequency or damping rate, so no time step is "
               "stable; material.density, material.youngs_modulus, lattice.foundation_ratio, pusher.stiffness "
               "or friction.interfacial_stiffness is out of any physical range";
  }
  check.require(s.integrator.time_step < limit, "integrator.time_step", s.integrator.time_step, allowed.str());
  // Ten million steps to the stiffest mode's period resolve nothing more, and a run would not end.
  constexpr double kFinestShare = 1e-7;
  if (std::isfinite(limit) && limit > 0.0) {
    std::ostringstream finest;
    finest.precision(4);
    finest << "dt >= " << kFinestShare * limit << " s, 1e-7 of the stability limit: a finer step resolves nothing "
           << "more and the run would not end";
    check.require(s.integrator.time_step >= kFinestShare * limit, "integrator.time_step", s.integrator.time_step,
                  finest.str());
  }
  return limit;
}

constexpr const char* kMemoryLimitVariable = "FRICTION_MEMORY_LIMIT_MB";

/// bytes a run may use: half this machine's memory, or kMemoryLimitVariable (MB) where it is set; NaN
/// where that is not a number > 0.
double memoryLimit() {
  if (const char* set = std::getenv(kMemoryLimitVariable)) {
    char* end = nullptr;
    const double megabytes = std::strtod(set, &end);
    const bool number = end != set && *end == '\0' && std::isfinite(megabytes) && megabytes > 0.0;
    return number ? megabytes * 1e6 : std::nan("");
  }
  return 0.5 * static_cast<double>(sysconf(_SC_PHYS_PAGES)) * static_cast<double>(sysconf(_SC_PAGE_SIZE));
}

/// What a run's model and solvers hold is estimated before anything is allocated, and a scene that would
/// not fit is refused naming the field that sizes it (measured peaks of 1.0 to 2.6 kB a lattice node
/// from 225 x 121 to 10^6 nodes, taken as 3 kB; a chain block as 1 kB, measured 0.24 kB at 10^5).
void checkMemory(Checker& check, const Scene& s) {
  const double limit = memoryLimit();
  if (std::isnan(limit)) {
    check.problems.push_back(std::string(kMemoryLimitVariable) + " (environment): value '" +
                             std::getenv(kMemoryLimitVariable) + "' is not allowed; allowed: a number of MB > 0");
    return;
  }
  std::ostringstream limit_text;
  limit_text.precision(3);
  limit_text << limit / 1e9 << " GB (half this machine's memory; " << kMemoryLimitVariable << " sets another)";
  const bool lattice = s.model == ModelKind::Lattice2D;
  const double bytes_per_node = lattice ? 3e3 : 1e3;
  const double nodes = lattice ? static_cast<double>(s.lattice.nodes_x) * s.lattice.nodes_z : s.chain.blocks;
  std::ostringstream size_allowed;
  size_allowed << "at most " << std::floor(limit / bytes_per_node)
               << (lattice ? " nodes: nodes_x*nodes_z = " : " blocks: ") << nodes << " need about "
               << nodes * bytes_per_node / 1e9 << " GB, over the memory limit of " << limit_text.str();
  check.require(nodes * bytes_per_node <= limit, lattice ? "lattice.nodes_x" : "chain.blocks",
                lattice ? s.lattice.nodes_x : s.chain.blocks, size_allowed.str());
}

/// The foundation's contact springs carry F_Z: with the linear contact model the slider must sink into
/// the track by a small fraction of a node spacing, or the loading solve is meaningless (and, with k_f
/// far below the bonds, numerically singular).
void checkFoundation(Checker& check, const Scene& s) {
  const double spacing = s.geometry.length / (s.lattice.nodes_x - 1);
  const double bond_stiffness = Lattice2D::springStiffness(s);
  const double least_ratio = 10.0 * s.load.normal_force / (s.lattice.nodes_x * bond_stiffness * spacing);
  std::ostringstream allowed;
  allowed << ">= " << least_ratio << ", so that F_Z sinks the slider into the track by under a tenth of the "
          << "node spacing (F_Z/(nodes_x*k_f) < " << 0.1 * spacing << " m, k_f = ratio*0.75*B*E)";
  check.require(s.lattice.foundation_ratio >= least_ratio, "lattice.foundation_ratio", s.lattice.foundation_ratio,
                allowed.str());
}

}  // namespace

double largestNormalForce(const Scene& scene) {
  return 0.05 * scene.material.youngs_modulus * scene.geometry.length * scene.geometry.width;
}

SceneReview validateScene(const Scene& s, double* stability_limit) {
  Checker check;
  const bool lattice = s.model == ModelKind::Lattice2D;
  checkBody(check, s);
  if (lattice) {
    checkLattice(check, s);
  } else {
    checkChain(check, s);
  }
  checkFriction(check, s);
  checkLoad(check, s);
  checkPusher(check, s);
  checkStage(check, s);
  checkInstrumentsStopAndIntegrator(check, s);
  // Before anything builds the model: a scene too large for the machine is refused, not allocated.
  checkMemory(check, s);
  // Cross-field checks that need a consistent model; run whenever the fields they use are valid, so
  // that one refusal lists everything.
  const bool model_valid = check.clean({"geometry.", "material.", "lattice.", "chain.", "pusher.", "load.",
                                        "friction.interfacial_stiffness", "integrator."});
  if (!model_valid) {
    SceneReview review{check.problems, {}};
    if (check.clean({"integrator.time_step"})) {
      std::ostringstream text;
      text << "integrator.time_step: value " << s.integrator.time_step
           << " not yet checked against the stability limit, which needs the fields above to be valid";
      review.notes.push_back(text.str());
    }
    return review;
  }
  if (!lattice && check.clean({"friction.static_coefficient"})) checkChainStatics(check, s);
  if (lattice) checkFoundation(check, s);
  const double limit = checkTimeStep(check, s);
  if (stability_limit) *stability_limit = limit;
  return {check.problems, {}};
}

std::vector<std::string> sceneWarnings(const Scene& s) {
  std::vector<std::string> warnings;
  if (s.friction.law == FrictionLawKind::SlipWeakening && s.friction.weakening_length == 0.0) {
    warnings.push_back(
        "friction.weakening_length: 0 m with friction.law slip_weakening drops the friction to mu_k "
        "at once, as amontons_coulomb does; give the slip distance xi_mu (m) over which it weakens");
  }
  if (s.friction.law == FrictionLawKind::RateState && s.instruments.event_slip_speed == 0.0) {
    // Its nodes creep, faster and faster, before they slip: from the first creep an event starts below
    // its peak force (µ_k,macro can come out above µ_s,macro) and may not end while the interface creeps.
    warnings.push_back(
        "instruments.event_slip_speed: 0 m/s with friction.law rate_state counts a slip from the slowest "
        "creep, so an event starts below its peak force; give the speed from which sliding is an event "
        "(1e-3 m/s in the shipped rate_state scenes)");
  }
  const double spacing = s.model == ModelKind::Lattice2D ? s.geometry.length / std::max(s.lattice.nodes_x - 1, 1)
                                                         : s.geometry.length / std::max(s.chain.blocks - 1, 1);
  if (s.model == ModelKind::Lattice2D && !s.pusher.hasBand()) {
    // The lattice pushes a node, not a height: the user should know which row their h became.
    const double row_height = nearestRow(s.pusher.height, spacing, s.lattice.nodes_z) * spacing;
    if (std::abs(row_height - s.pusher.height) > 1e-6 * spacing) {
      std::ostringstream text;
      text.precision(4);
      text << "pusher.height: " << s.pusher.height << " m lies between lattice rows (" << spacing
           << " m apart); the pusher acts on the nearest, at " << row_height << " m";
      warnings.push_back(text.str());
    }
  }
  if (s.friction.law == FrictionLawKind::SlipWeakening && s.friction.weakening_length > 0.0 &&
      s.friction.weakening_length < spacing) {
    // What the lattice must resolve is the cohesive zone, where the friction weakens, not ξ_µ itself: an
    // estimate is Λ ≈ G·ξ_µ/((µ_s − µ_k)·σ̄), G the shear modulus (the chain's E: it only stretches) and
    // σ̄ = F_Z/(L·B) the mean normal stress. The warning gives it so that the user can judge.
    const double modulus = s.model == ModelKind::Lattice2D ? Lattice2D::shearModulus(s) : s.material.youngs_modulus;
    const double mean_normal_stress = s.load.normal_force / (s.geometry.length * s.geometry.width);
    const double strength_drop = (s.friction.static_coefficient - s.friction.kinetic_coefficient) * mean_normal_stress;
    std::ostringstream text;
    text.precision(3);
    text << "friction.weakening_length: " << s.friction.weakening_length << " m is shorter than one node spacing ("
         << spacing << " m)";
    if (strength_drop > 0.0) {
      const double cohesive_zone = modulus * s.friction.weakening_length / strength_drop;
      text << "; the cohesive zone it sets, G·ξ_µ/((µ_s − µ_k)·σ̄) ≈ " << cohesive_zone << " m, spans "
           << cohesive_zone / spacing << " node spacings"
           << (cohesive_zone < 3.0 * spacing ? ": not resolved, results depend on the lattice"
                                             : " (3 or more resolve it)");
    }
    warnings.push_back(text.str());
  }
  return warnings;
}

}  // namespace friction
