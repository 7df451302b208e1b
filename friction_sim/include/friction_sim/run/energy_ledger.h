// The energy budget's running sums (MODEL.md §7): the work the pusher and the top load put in, and what
// the pair damping dissipated. The rest of the budget (stored, kinetic, friction) is read from the state.
#pragma once

#include "friction_sim/contact/contact_interface.h"
#include "friction_sim/instruments/instruments.h"
#include "friction_sim/model/model.h"

namespace friction {

class EnergyLedger {
 public:
  /// At the loaded equilibrium `u`, which stores `elastic` (J).
  void start(double elastic, const Vector& u) {
    initial_elastic_ = elastic;
    top_load_reference_u_ = u;
  }
  /// J, work done on the slider by the stage.
  void addPusherWork(double work) { pusher_work_ += work; }
  /// The pusher's work while F_X went from `shear_start` to `shear_end` (N) and the stage from
  /// `stage_start` to `stage_end` (m), by the trapezoid.
  void addPusherWork(double shear_start, double shear_end, double stage_start, double stage_end) {
    pusher_work_ += 0.5 * (shear_start + shear_end) * (stage_end - stage_start);
  }
  /// J, dissipated by the pair damping.
  void addViscous(double dissipated) { viscous_dissipation_ += dissipated; }
  /// F_Z is about to change with the slider at `u`: the top load's work so far is closed.
  void closeTopLoadWork(const Model& model, const Vector& u) {
    top_load_work_closed_ += model.externalWork(top_load_reference_u_, u);
    top_load_reference_u_ = u;
  }
  /// J, the slider's potential energy at `u`: stored elastic energy less the top load's work since F_Z
  /// last changed.
  double potential(const Model& model, const Vector& u, double stage_position) const {
    return model.elasticEnergy(u, stage_position) - model.externalWork(top_load_reference_u_, u);
  }
  EnergyBudget budget(const Model& model, const ContactInterface& contact, const Vector& u, double stage_position,
                      double kinetic) const {
    EnergyBudget budget;
    budget.work_in = pusher_work_ + top_load_work_closed_ + model.externalWork(top_load_reference_u_, u);
    budget.elastic = model.elasticEnergy(u, stage_position) + contact.anchorEnergy(u);
    budget.initial_elastic = initial_elastic_;
    budget.kinetic = kinetic;
    budget.friction_dissipation = contact.frictionDissipation();
    budget.viscous_dissipation = viscous_dissipation_;
    return budget;
  }

 private:
  double initial_elastic_ = 0.0;       ///< J, stored at the loaded equilibrium
  double pusher_work_ = 0.0;           ///< J
  double top_load_work_closed_ = 0.0;  ///< J, the top load's work before F_Z last changed
  Vector top_load_reference_u_;        ///< m, the displacements when F_Z last changed
  double viscous_dissipation_ = 0.0;   ///< J
};

}  // namespace friction
