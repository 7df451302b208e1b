// Turning a model's forces into accelerations strip by strip, friction included, for Simulation's
// steps and step groups.
#pragma once

#include <algorithm>

#include "friction_sim/contact/contact_interface.h"
#include "friction_sim/model/model.h"

namespace friction {
/// About 4·10³ nodes: the strip's displacements, velocities and accelerations (≈ 200 kB) stay in the
/// L2 cache between the force evaluation and the integrator's passes.
constexpr int kStripNodes = 4096;
/// About 2·10³ nodes while a group of steps is swept at once: each sweep keeps one or two strips behind
/// the one ahead of it in the cache. At 10⁶ nodes with two steps per sweep, 1024 and 2048 gave 4.8–5.1 ns
/// per node-step, 4096 4.9–5.7 and 8192 5.5–6.0 (by hand, 2026-11-24).
constexpr int kGroupStripNodes = 2048;

/// Turns each finished strip's forces into accelerations before passing it on: the interface's entries
/// with their friction, which needs nothing beyond the strip's own nodes.
class AccelerationStrips : public StripHooks {
 public:
  AccelerationStrips(StripHooks& caller, Vector& a, double inverse_mass, ContactInterface& contact,
                     const ForceEvaluation& evaluation, const Vector& u, const Vector& v)
      : caller_(caller),
        a_(a),
        inverse_mass_(inverse_mass),
        contact_(contact),
        evaluation_(evaluation),
        u_(u),
        v_(v),
        interface_begin_(contact.firstDof()),
        interface_end_(interface_begin_ + contact.size()) {}
  void prepare(int first, int end) override { caller_.prepare(first, end); }
  void finish(int first, int end) override {
    scaleOutsideInterface(first, std::min(end, interface_begin_));
    const int first_node = std::max(first, interface_begin_) - interface_begin_;
    const int end_node = std::min(end, interface_end_) - interface_begin_;
    if (first_node < end_node) {
      contact_.applyFriction(evaluation_, u_, v_, inverse_mass_, a_, first_node, end_node, caller_.closingKick());
    }
    scaleOutsideInterface(std::max(first, interface_end_), end);
    caller_.finish(first, end);
  }

 private:
  void scaleOutsideInterface(int first, int end) {
    if (first < end) a_.segment(first, end - first) *= inverse_mass_;
  }

  StripHooks& caller_;
  Vector& a_;
  double inverse_mass_;
  ContactInterface& contact_;
  const ForceEvaluation& evaluation_;
  const Vector& u_;
  const Vector& v_;
  int interface_begin_, interface_end_;
};

}  // namespace friction
