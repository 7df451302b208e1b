// A naive step of the 2D lattice's bulk, for scale beside the model's (bench_kernels' naiveLatticeStep):
// the same geometric springs and pair damping written as a first implementation would. Each node sums
// its eight bonds, so every bond is computed twice, once from each end; the state is an array of node
// records; velocity Verlet's three passes each sweep the whole state. The bottom row is held in place:
// no contact rules, loads or pusher, which the model's step does on top of this.
#pragma once

#include <array>
#include <cmath>
#include <vector>

namespace friction {

class NaiveLattice {
 public:
  struct Node {
    double ux = 0.0, uz = 0.0;  ///< m, displacement
    double vx = 0.0, vz = 0.0;  ///< m/s
    double ax = 0.0, az = 0.0;  ///< m/s²
  };

  /// `nx` × `nz` nodes `spacing` (m) apart; horizontal and vertical bonds of stiffness `k` (N/m), diagonal
  /// ones of k/2, pair damping `eta` (kg/s), nodes of `mass` (kg): the model's lattice (MODEL.md §2).
  NaiveLattice(int nx, int nz, double spacing, double k, double eta, double mass)
      : nx_(nx), nz_(nz), spacing_(spacing), k_(k), eta_(eta), mass_(mass), nodes_(static_cast<std::size_t>(nx) * nz) {}

  Node& node(int i, int j) { return nodes_[static_cast<std::size_t>(j) * nx_ + i]; }
  const Node& node(int i, int j) const { return nodes_[static_cast<std::size_t>(j) * nx_ + i]; }

  /// N, the force of its bonds on node (i, j), as {x, z}.
  std::array<double, 2> bondForce(int i, int j) const {
    static constexpr int kOffsets[8][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}, {1, 1}, {-1, -1}, {-1, 1}, {1, -1}};
    const Node& self = node(i, j);
    double fx = 0.0, fz = 0.0;
    for (const auto& offset : kOffsets) {
      const int ni = i + offset[0], nj = j + offset[1];
      if (ni < 0 || ni >= nx_ || nj < 0 || nj >= nz_) continue;
      const Node& other = node(ni, nj);
      const bool diagonal = offset[0] != 0 && offset[1] != 0;
      const double stiffness = diagonal ? 0.5 * k_ : k_;
      const double rest_length = diagonal ? std::sqrt(2.0) * spacing_ : spacing_;
      const double bond_x = offset[0] * spacing_ + (other.ux - self.ux);
      const double bond_z = offset[1] * spacing_ + (other.uz - self.uz);
      const double length = std::sqrt(bond_x * bond_x + bond_z * bond_z);
      const double tension_per_length = stiffness * (length - rest_length) / length;
      fx += tension_per_length * bond_x + eta_ * (other.vx - self.vx);
      fz += tension_per_length * bond_z + eta_ * (other.vz - self.vz);
    }
    return {fx, fz};
  }

  /// One velocity Verlet step of `dt` (s).
  void step(double dt) {
    for (Node& n : nodes_) {
      n.vx += 0.5 * dt * n.ax;
      n.vz += 0.5 * dt * n.az;
      n.ux += dt * n.vx;
      n.uz += dt * n.vz;
    }
    for (int j = 1; j < nz_; ++j) {
      for (int i = 0; i < nx_; ++i) {
        const std::array<double, 2> force = bondForce(i, j);
        node(i, j).ax = force[0] / mass_;
        node(i, j).az = force[1] / mass_;
      }
    }
    for (Node& n : nodes_) {
      n.vx += 0.5 * dt * n.ax;
      n.vz += 0.5 * dt * n.az;
    }
  }

 private:
  int nx_, nz_;
  double spacing_, k_, eta_, mass_;
  std::vector<Node> nodes_;
};

}  // namespace friction
