// MODEL.md §7.3–7.4: the lattice's elastic constants from static tension and shear, P- and S-wave
// speeds from arrival times, and the node stiffnesses; plus the linearised spring form against the
// geometric one and the strain gauges' interpolation.
#include <gtest/gtest.h>

#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <map>

#include "../benchmarks/naive_lattice.h"
#include "friction_sim/instruments/slip_events.h"
#include "friction_sim/model/lattice_2d.h"
#include "friction_sim/run/simulation.h"
#include "friction_sim/solvers/integrator.h"
#include "test_helpers.h"

namespace friction {
namespace {

/// A free lattice (no foundation, no load, pusher off) of nx × nz nodes at the default spacing 2.5 mm.
Scene freeLatticeScene(int nx, int nz, double damping_coefficient = 0.0) {
  Scene scene;
  scene.lattice.nodes_x = nx;
  scene.lattice.nodes_z = nz;
  scene.geometry.length = 0.0025 * (nx - 1);
  scene.geometry.height = 0.0025 * (nz - 1);
  scene.lattice.foundation_ratio = 0.0;
  scene.load.normal_force = 0.0;
  scene.material.damping_coefficient = damping_coefficient;
  return scene;
}

/// Static linear solve with some displacements prescribed: K_ff u_f = −K_fp u_p.
Vector solveWithPrescribed(const SparseMatrix& stiffness, const std::map<int, double>& prescribed) {
  const int n = static_cast<int>(stiffness.rows());
  std::vector<int> free_index(n, -1);
  int free_count = 0;
  for (int dof = 0; dof < n; ++dof) {
    if (!prescribed.count(dof)) free_index[dof] = free_count++;
  }
  Vector u = Vector::Zero(n);
  for (const auto& [dof, value] : prescribed) u[dof] = value;
  std::vector<Eigen::Triplet<double>> entries;
  Vector rhs = Vector::Zero(free_count);
  for (int column = 0; column < stiffness.outerSize(); ++column) {
    for (SparseMatrix::InnerIterator it(stiffness, column); it; ++it) {
      const int row = free_index[it.row()];
      if (row < 0) continue;
      if (free_index[it.col()] >= 0) {
        entries.emplace_back(row, free_index[it.col()], it.value());
      } else {
        rhs[row] -= it.value() * u[it.col()];
      }
    }
  }
  SparseMatrix reduced(free_count, free_count);
  reduced.setFromTriplets(entries.begin(), entries.end());
  Eigen::SimplicialLDLT<SparseMatrix> solver(reduced);
  const Vector solution = solver.solve(rhs);
  for (int dof = 0; dof < n; ++dof) {
    if (free_index[dof] >= 0) u[dof] = solution[free_index[dof]];
  }
  return u;
}

TEST(LatticeElasticity, UniaxialTensionGivesYoungsModulusAndPoissonRatioOneThird) {
  const Scene scene = freeLatticeScene(41, 21);
  Lattice2D lattice(scene);
  lattice.disconnectPusher();
  const int nx = lattice.nodesX(), nz = lattice.nodesZ();
  const double strain = 1e-4;
  std::map<int, double> prescribed;
  for (int j = 0; j < nz; ++j) {
    prescribed[lattice.xDof(lattice.nodeIndex(0, j))] = 0.0;
    prescribed[lattice.xDof(lattice.nodeIndex(nx - 1, j))] = strain * scene.geometry.length;
  }
  prescribed[lattice.zDof(lattice.nodeIndex(0, nz / 2))] = 0.0;
  const Vector u = solveWithPrescribed(lattice.stiffnessMatrix(), prescribed);

  const int ic = nx / 2, jc = nz / 2, span = 5;
  const double l = lattice.spacing();
  const double strain_xx =
      (u[lattice.xDof(lattice.nodeIndex(ic + span, jc))] - u[lattice.xDof(lattice.nodeIndex(ic - span, jc))]) /
      (2 * span * l);
  const double strain_zz =
      (u[lattice.zDof(lattice.nodeIndex(ic, jc + span))] - u[lattice.zDof(lattice.nodeIndex(ic, jc - span))]) /
      (2 * span * l);
  const auto stress = lattice.cellStress(u, ic, jc);
  const double youngs = stress[0] / strain_xx;
  EXPECT_NEAR(youngs, scene.material.youngs_modulus, 0.01 * scene.material.youngs_modulus);
  EXPECT_NEAR(-strain_zz / strain_xx, 1.0 / 3.0, 0.01 / 3.0);
  EXPECT_NEAR(youngs, 4.0 * lattice.springStiffness() / (3.0 * scene.geometry.width), 0.01 * youngs);
  EXPECT_LT(std::abs(stress[1]), 1e-3 * stress[0]);

  // The strain gauges read the same uniform stress wherever they sit in the uniform region.
  const GaugeStresses gauges = lattice.gaugeStresses(u, jc * l, {(ic - 2.3) * l, ic * l, (ic + 1.7) * l});
  for (double sigma_xx : gauges.sigma_xx) EXPECT_NEAR(sigma_xx, stress[0], 1e-3 * stress[0]);
}

TEST(LatticeElasticity, SimpleShearGivesShearModulusThreeEighthsOfE) {
  const Scene scene = freeLatticeScene(81, 21);
  Lattice2D lattice(scene);
  lattice.disconnectPusher();
  const int nx = lattice.nodesX(), nz = lattice.nodesZ();
  const double shear_strain = 1e-4;
  std::map<int, double> prescribed;
  for (int i = 0; i < nx; ++i) {
    prescribed[lattice.xDof(lattice.nodeIndex(i, 0))] = 0.0;
    prescribed[lattice.zDof(lattice.nodeIndex(i, 0))] = 0.0;
    prescribed[lattice.xDof(lattice.nodeIndex(i, nz - 1))] = shear_strain * scene.geometry.height;
    prescribed[lattice.zDof(lattice.nodeIndex(i, nz - 1))] = 0.0;
  }
  const Vector u = solveWithPrescribed(lattice.stiffnessMatrix(), prescribed);
  const int ic = nx / 2, jc = nz / 2, span = 3;
  const double l = lattice.spacing();
  auto ux = [&](int i, int j) { return u[lattice.xDof(lattice.nodeIndex(i, j))]; };
  auto uz = [&](int i, int j) { return u[lattice.zDof(lattice.nodeIndex(i, j))]; };
  const double gamma = (ux(ic, jc + span) - ux(ic, jc - span)) / (2 * span * l) +
                       (uz(ic + span, jc) - uz(ic - span, jc)) / (2 * span * l);
  const double shear_modulus = lattice.cellStress(u, ic, jc)[2] / gamma;
  EXPECT_NEAR(shear_modulus, 3.0 / 8.0 * scene.material.youngs_modulus, 0.01 * shear_modulus);
}

TEST(LatticeNaiveReference, ComputesTheModelsBulkForces) {
  // bench_kernels measures the model's step against this naive one: it must do the same work. Away from
  // the edges (no foundation, load or pusher there), the forces of both agree to round-off for a state
  // that stretches and turns the bonds (the geometric springs) and moves the nodes (the damping).
  Scene scene = freeLatticeScene(13, 9, 0.05);
  Lattice2D lattice(scene);
  NaiveLattice naive(lattice.nodesX(), lattice.nodesZ(), lattice.spacing(), lattice.springStiffness(),
                     lattice.dampingRate(), lattice.nodeMass());
  Vector u(lattice.dofCount()), v(lattice.dofCount()), force;
  for (int j = 0; j < lattice.nodesZ(); ++j) {
    for (int i = 0; i < lattice.nodesX(); ++i) {
      const int node = lattice.nodeIndex(i, j);
      NaiveLattice::Node& n = naive.node(i, j);
      n.ux = u[lattice.xDof(node)] = 2e-5 * std::sin(0.7 * i + 1.3 * j);
      n.uz = u[lattice.zDof(node)] = 2e-5 * std::cos(1.1 * i - 0.4 * j);
      n.vx = v[lattice.xDof(node)] = 0.3 * std::sin(0.5 * i * j);
      n.vz = v[lattice.zDof(node)] = 0.3 * std::cos(0.9 * i + j);
    }
  }
  ForceEvaluation out;
  lattice.evaluateInto(u, v, 0.0, force, out);
  const double scale = force.cwiseAbs().maxCoeff();
  ASSERT_GT(scale, 100.0);  // N: bonds of 1.35e7 N/m stretched by some 10 µm, far beyond round-off
  ASSERT_GT(lattice.dampingRate(), 0.0);
  for (int j = 1; j + 1 < lattice.nodesZ(); ++j) {
    for (int i = 1; i + 1 < lattice.nodesX(); ++i) {
      const int node = lattice.nodeIndex(i, j);
      const std::array<double, 2> reference = naive.bondForce(i, j);
      EXPECT_NEAR(force[lattice.xDof(node)], reference[0], 1e-12 * scale) << i << ", " << j;
      EXPECT_NEAR(force[lattice.zDof(node)], reference[1], 1e-12 * scale) << i << ", " << j;
    }
  }
}

TEST(LatticeWaves, PAndSWaveSpeedsFromArrivalTimes) {
  const Scene scene = freeLatticeScene(141, 141);
  Lattice2D lattice(scene);
  testing::FreeBody body(lattice);
  const int centre = 70;
  const double l = lattice.spacing();
  Vector u = Vector::Zero(lattice.dofCount()), v = u, a;
  // A smooth x-displacement bump radiates P waves along x and S waves along z.
  for (int j = 0; j < lattice.nodesZ(); ++j) {
    for (int i = 0; i < lattice.nodesX(); ++i) {
      const double r2 = (std::pow(i - centre, 2) + std::pow(j - centre, 2)) / 9.0;
      u[lattice.xDof(lattice.nodeIndex(i, j))] = 1e-8 * std::exp(-r2);
    }
  }
  double power = body.acceleration(u, v, 0.0, a);
  // The speeds that front speeds are expressed in: plane stress, ν = 1/3.
  const WaveSpeeds speeds = waveSpeeds(scene);
  const double c_l = speeds.longitudinal, c_s = speeds.shear;
  const int near = 12, far = 30;
  const int receivers[4] = {lattice.nodeIndex(centre + near, centre), lattice.nodeIndex(centre + far, centre),
                            lattice.nodeIndex(centre, centre + near), lattice.nodeIndex(centre, centre + far)};
  double peak_value[4] = {0, 0, 0, 0}, peak_time[4] = {0, 0, 0, 0};
  const double dt = 5e-8;
  VelocityVerlet verlet;
  for (double t = dt; t < (far + 8) * l / c_s; t += dt) {
    verlet.step(body, u, v, a, power, t - dt, dt);
    for (int r = 0; r < 4; ++r) {
      const double value = u[lattice.xDof(receivers[r])];
      if (value > peak_value[r]) {
        peak_value[r] = value;
        peak_time[r] = t;
      }
    }
  }
  const double p_speed = (far - near) * l / (peak_time[1] - peak_time[0]);
  const double s_speed = (far - near) * l / (peak_time[3] - peak_time[2]);
  EXPECT_NEAR(p_speed, c_l, 0.03 * c_l);
  EXPECT_NEAR(s_speed, c_s, 0.03 * c_s);
}

TEST(LatticePusher, PushesTheRowNearestItsHeightOrItsBandAndSaysWhere) {
  Scene scene;                  // pmma_2d: rows 2.5 mm apart
  scene.pusher.height = 0.006;  // 2.4 spacings: row 2, at 5 mm
  const Lattice2D single_row(scene);
  EXPECT_EQ(single_row.pushedRows(), std::vector<int>{2});
  EXPECT_DOUBLE_EQ(single_row.pushingHeight(), 0.005);
  scene.pusher.band_min = 0.004;  // rows 2, 3 and 4 (5, 7.5 and 10 mm): the resultant at 7.5 mm
  scene.pusher.band_max = 0.011;
  const Lattice2D band(scene);
  EXPECT_EQ(band.pushedRows(), (std::vector<int>{2, 3, 4}));
  EXPECT_DOUBLE_EQ(band.pushingHeight(), 0.0075);
  // What the lattice snapshot carries to rviz.
  EXPECT_DOUBLE_EQ(Simulation(scene).snapshot().pusher_height, 0.0075);
}

TEST(LatticeNodeStiffness, BulkNodeThreeKAndCornerFiveQuarterK) {
  Scene scene = freeLatticeScene(57, 31);
  Lattice2D lattice(scene);
  lattice.disconnectPusher();
  const double k = lattice.springStiffness();
  const double delta = 1e-9;
  ForceEvaluation evaluation;
  auto response = [&](int node, int dof) {
    Vector u = Vector::Zero(lattice.dofCount());
    u[dof] = delta;
    lattice.evaluate(u, Vector::Zero(lattice.dofCount()), 0.0, evaluation);
    return std::array<double, 2>{-evaluation.force[lattice.xDof(node)] / delta,
                                 -evaluation.force[lattice.zDof(node)] / delta};
  };
  const int bulk = lattice.nodeIndex(20, 15);
  const auto bulk_x = response(bulk, lattice.xDof(bulk));
  const auto bulk_z = response(bulk, lattice.zDof(bulk));
  EXPECT_NEAR(bulk_x[0], 3 * k, 1e-6 * k);
  EXPECT_NEAR(bulk_x[1], 0.0, 1e-6 * k);
  EXPECT_NEAR(bulk_z[1], 3 * k, 1e-6 * k);
  const int corner = lattice.nodeIndex(0, lattice.nodesZ() - 1);
  const auto corner_x = response(corner, lattice.xDof(corner));
  const auto corner_z = response(corner, lattice.zDof(corner));
  EXPECT_NEAR(corner_x[0], 1.25 * k, 1e-6 * k);
  EXPECT_NEAR(corner_z[1], 1.25 * k, 1e-6 * k);
  EXPECT_NEAR(std::abs(corner_x[1]), 0.25 * k, 1e-6 * k);
  EXPECT_NEAR(corner_x[1], corner_z[0], 1e-6 * k);
  // Eigenvalues of [[5k/4, ±k/4], [±k/4, 5k/4]]: 3k/2 and k.
  const double mean = 0.5 * (corner_x[0] + corner_z[1]);
  EXPECT_NEAR(mean + std::abs(corner_x[1]), 1.5 * k, 1e-6 * k);
  EXPECT_NEAR(mean - std::abs(corner_x[1]), 1.0 * k, 1e-6 * k);
}

TEST(LatticePusher, StiffnessChangeAtThePusherMakesTheMatrixTheSpringsTangentThere) {
  // The pushed node displaced as a point load displaces it (strains of 1 % in its springs): the matrix
  // plus the change gives the forces' derivative along either component of that node, all of whose
  // springs lie among the six nodes of the change, to the finite difference's round-off.
  Scene scene;  // pmma_2d: pushed at row 2
  Lattice2D lattice(scene);
  Vector u = Vector::Zero(lattice.dofCount());
  lattice.connectPusher(u);
  const int pushed = lattice.nodeIndex(0, lattice.pushedRows()[0]);
  for (int i = 0; i < u.size(); ++i) u[i] = 1e-6 * std::sin(0.37 * i);
  u[lattice.xDof(pushed)] += 2.5e-5;
  u[lattice.zDof(pushed)] -= 1e-5;
  const LocalStiffness change = lattice.stiffnessChangeAtPusher(u);
  ASSERT_EQ(change.dofs.size(), 12u);
  EXPECT_LT((change.matrix - change.matrix.transpose()).norm(), 1e-12 * change.matrix.norm());
  const SparseMatrix stiffness = lattice.stiffnessMatrix();
  for (int dof : {lattice.xDof(pushed), lattice.zDof(pushed)}) {
    SCOPED_TRACE("dof " + std::to_string(dof));
    const double step = 1e-9;  // m
    ForceEvaluation ahead, behind;
    lattice.evaluate(u + step * Vector::Unit(u.size(), dof), Vector::Zero(u.size()), 0.0, ahead);
    lattice.evaluate(u - step * Vector::Unit(u.size(), dof), Vector::Zero(u.size()), 0.0, behind);
    const Vector tangent = -(ahead.force - behind.force) / (2 * step);  // N/m
    const Vector at_rest = stiffness.col(dof);
    Vector changed = at_rest;
    const auto column = std::find(change.dofs.begin(), change.dofs.end(), dof) - change.dofs.begin();
    for (std::size_t r = 0; r < change.dofs.size(); ++r) changed[change.dofs[r]] += change.matrix(r, column);
    EXPECT_LT((changed - tangent).norm(), 1e-6 * tangent.norm());
    EXPECT_GT((at_rest - tangent).norm(), 3e-3 * tangent.norm());
  }
  // Without the pusher, no point load: nothing to change.
  lattice.disconnectPusher();
  EXPECT_TRUE(lattice.stiffnessChangeAtPusher(u).dofs.empty());
}

TEST(LatticeSpringForm, LinearisedForcesAgreeWithGeometricAtSmallStrain) {
  Scene scene = freeLatticeScene(21, 11, 0.1);
  Lattice2D geometric(scene);
  scene.lattice.spring_form = SpringForm::Linearised;
  Lattice2D linearised(scene);
  Vector u(geometric.dofCount()), v(geometric.dofCount());
  for (int i = 0; i < u.size(); ++i) {
    u[i] = 2.5e-6 * std::sin(0.37 * i * i + 1.0);  // strains ~1e-3, as in the rig
    v[i] = 1e-3 * std::cos(0.21 * i);
  }
  ForceEvaluation a, b;
  geometric.evaluate(u, v, 0.0, a);
  linearised.evaluate(u, v, 0.0, b);
  // The geometric correction is second order in the strain: ~1e-3 of the forces here.
  EXPECT_LT((a.force - b.force).norm(), 5e-3 * a.force.norm());
  EXPECT_GT((a.force - b.force).norm(), 0.0);
  EXPECT_NEAR(a.viscous_power, b.viscous_power, 1e-12 * a.viscous_power);
}

}  // namespace
}  // namespace friction
