// The static solve by direct factor and by multigrid-preconditioned conjugate gradients: the same
// equilibrium, and a multigrid iteration count that does not grow with the lattice.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "friction_sim/solvers/static_solver.h"
#include "test_helpers.h"

namespace friction {
namespace {

std::unique_ptr<Model> pmmaLattice(int nodes_x, int nodes_z) {
  return buildModel(testing::pmmaScene(nodes_x, nodes_z));
}

/// The loading step: F_Z applied with the interface held along x and the pusher off.
Vector loadedState(Model& model, StaticMethod method) {
  model.disconnectPusher();
  Vector u = Vector::Zero(model.dofCount());
  StaticSolver(model, model.blockedDofsDuringLoading(), true, method).solve(model, u, 0.0);
  return u;
}

TEST(StaticSolver, MultigridLoadsTheLatticeAsTheFactorDoes) {
  for (const auto& [nx, nz] : {std::pair{57, 31}, std::pair{60, 32}}) {  // odd and even node counts
    auto model = pmmaLattice(nx, nz);
    const Vector direct = loadedState(*model, StaticMethod::kDirect);
    const Vector multigrid = loadedState(*model, StaticMethod::kMultigrid);
    ASSERT_GT(direct.lpNorm<Eigen::Infinity>(), 1e-7);  // F_Z compresses the slider by micrometres
    EXPECT_LT((multigrid - direct).lpNorm<Eigen::Infinity>(), 1e-9 * direct.lpNorm<Eigen::Infinity>())
        << nx << " x " << nz;
  }
}

TEST(StaticSolver, TheSpringMattressCarriesItsLoadAfterAFewCorrections) {
  // The plate moves by the stiffness its last move met, the plate's springs and the slider in series.
  // By the plate's springs alone, each solve closed 1/32 of the excess at 57 × 31, and 500 corrections
  // left 3.3e-15 m, above the tolerance.
  Scene scene = testing::pmmaScene(57, 31);
  scene.load.top = TopLoadKind::SpringMattress;
  auto model = buildModel(scene);
  model->disconnectPusher();
  Vector u = Vector::Zero(model->dofCount());
  const StaticSolver loading(*model, model->blockedDofsDuringLoading(), true);
  EXPECT_LE(loading.solve(*model, u, 0.0), 15);  // 12 measured
  ForceEvaluation loaded;
  model->evaluate(u, Vector::Zero(u.size()), 0.0, loaded);
  EXPECT_NEAR(loaded.normal_load, scene.load.normal_force, 1e-12 * scene.load.normal_force);
}

TEST(StaticSolver, MultigridResponseToTheStageMatchesTheFactor) {
  // The fast-forward's affine slope: the pinned lattice's response to the pusher's force.
  auto model = pmmaLattice(57, 31);
  model->connectPusher(Vector::Zero(model->dofCount()));
  std::vector<int> interface;
  for (int node = 0; node < model->interfaceNodeCount(); ++node) {
    interface.push_back(model->interfaceDof(node));
    interface.push_back(model->interfaceDof(node) + model->dofCount() / 2);
  }
  ForceEvaluation at_rest, moved;
  const Vector zero = Vector::Zero(model->dofCount());
  model->evaluate(zero, zero, 0.0, at_rest);
  model->evaluate(zero, zero, 1e-6, moved);
  const Vector push = moved.force - at_rest.force;
  const Vector direct = StaticSolver(*model, interface, false, StaticMethod::kDirect).response(push);
  const Vector multigrid = StaticSolver(*model, interface, false, StaticMethod::kMultigrid).response(push);
  EXPECT_LT((multigrid - direct).lpNorm<Eigen::Infinity>(), 1e-8 * direct.lpNorm<Eigen::Infinity>());
}

TEST(StaticSolver, AddedSpringsRespondAsAFreshFactor) {
  // Fast-forward's pinned solver from the loading solver: the same matrix but for the pusher's springs.
  auto model = pmmaLattice(57, 31);
  const std::vector<int> held = model->blockedDofsDuringLoading();
  model->disconnectPusher();
  const Vector unpushed = model->anchorStiffness();
  auto loading = std::make_unique<StaticSolver>(*model, held, true, StaticMethod::kDirect);
  model->connectPusher(Vector::Zero(model->dofCount()));
  const Vector added = model->anchorStiffness() - unpushed;
  ASSERT_GT(added.maxCoeff(), 1e5);  // N/m: pmma_2d's pusher, 4 MN/m, on its row
  const auto pushed = StaticSolver::withAddedSprings(std::move(loading), added);
  ASSERT_NE(pushed, nullptr);
  const StaticSolver fresh(*model, held, false, StaticMethod::kDirect);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> newtons(-1.0, 1.0);
  Vector force(model->dofCount());
  for (double& f : force) f = newtons(random);
  const Vector expected = fresh.response(force);
  EXPECT_LT((pushed->response(force) - expected).lpNorm<Eigen::Infinity>(), 1e-12 * expected.lpNorm<Eigen::Infinity>());
  // A multigrid solver is set up afresh instead: a solve per spring costs more than that.
  auto multigrid = std::make_unique<StaticSolver>(*model, held, false, StaticMethod::kMultigrid);
  EXPECT_EQ(StaticSolver::withAddedSprings(std::move(multigrid), added), nullptr);
}

TEST(StaticSolver, ManyAddedSpringsAreRefused) {
  auto model = pmmaLattice(20, 10);
  for (int springs : {StaticSolver::kMostAddedSprings, StaticSolver::kMostAddedSprings + 1}) {
    auto solver = std::make_unique<StaticSolver>(*model, model->blockedDofsDuringLoading());
    Vector added = Vector::Zero(model->dofCount());
    for (int i = 0; i < springs; ++i) added[solver->freeDofs()[i]] = 1e6;
    EXPECT_EQ(StaticSolver::withAddedSprings(std::move(solver), added) != nullptr,
              springs <= StaticSolver::kMostAddedSprings);
  }
}

TEST(StaticSolver, MultigridSolvesWhateverIsFixed) {
  // Coarse dofs stand only where the fine dof is free: fixing the last row of an even grid (whose
  // last coarse row interpolates to it alone) or a random quarter of the dofs leaves the coarse
  // matrices positive definite.
  auto model = pmmaLattice(40, 20);
  model->disconnectPusher();
  const Vector body_force = Vector::Ones(model->dofCount());
  std::vector<int> last_row, quarter = model->blockedDofsDuringLoading();
  for (int i = 0; i < 40; ++i) {
    last_row.push_back(19 * 40 + i);
    last_row.push_back(model->dofCount() / 2 + 19 * 40 + i);
  }
  std::mt19937 random(7);
  for (int dof = 0; dof < model->dofCount(); ++dof) {
    if (random() % 4 == 0) quarter.push_back(dof);
  }
  for (const auto& fixed : {last_row, quarter}) {
    const Vector direct = StaticSolver(*model, fixed, false, StaticMethod::kDirect).response(body_force);
    const Vector multigrid = StaticSolver(*model, fixed, false, StaticMethod::kMultigrid).response(body_force);
    ASSERT_GT(direct.lpNorm<Eigen::Infinity>(), 0.0);
    EXPECT_LT((multigrid - direct).lpNorm<Eigen::Infinity>(), 1e-8 * direct.lpNorm<Eigen::Infinity>());
  }
}

TEST(StaticSolver, AutomaticChoiceFactorsAChain) {
  // A chain's factor has no fill-in, so even 5·10⁵ blocks are factored.
  Scene scene = loadScene(testing::scenePath("pmma_1d_side"));
  scene.chain.blocks = 500000;
  auto chain = buildModel(scene);
  const StaticSolver solver(*chain, {0});
  const Vector pull = Vector::Ones(chain->dofCount());
  const Vector u = solver.response(pull);
  // K·u = pull on every free block.
  Vector residual = chain->stiffnessMatrix() * u - pull;
  residual[0] = 0.0;
  // The internal forces reach the total pull (5·10⁵ N); the residual is round-off against them.
  EXPECT_LT(residual.lpNorm<Eigen::Infinity>(), 1e-9 * pull.sum());
  EXPECT_EQ(solver.multigridIterations(), 0);
}

TEST(StaticSolver, ACorrectionInvertsTheFactoredStiffnessPlusThePushersTangent) {
  // One correction from a state strained around the pusher: its step solves (K + ΔK)·du = f, with ΔK
  // the springs' tangent there (Model::stiffnessChangeAtPusher, added by Woodbury's identity), to the
  // single-precision factor's error; K's own step is off by much more.
  auto model = pmmaLattice(29, 16);
  Vector u = Vector::Zero(model->dofCount());
  model->connectPusher(u);
  for (int dof : model->stiffnessChangeAtPusher(u).dofs) u[dof] = 2e-5 * std::sin(1.0 + dof);  // 1 % strains
  const LocalStiffness change = model->stiffnessChangeAtPusher(u);
  ASSERT_FALSE(change.dofs.empty());
  std::vector<int> fixed;
  for (int node = 0; node < model->interfaceNodeCount(); ++node) fixed.push_back(model->interfaceDof(node));
  const StaticSolver solver(*model, fixed);
  Vector stepped = u;
  solver.correct(*model, stepped, 0.0);
  const std::vector<int>& free = solver.freeDofs();
  const int n = static_cast<int>(free.size());
  Eigen::MatrixXd stiffness = Eigen::MatrixXd(model->stiffnessMatrix());
  Eigen::MatrixXd changed = stiffness;
  for (std::size_t r = 0; r < change.dofs.size(); ++r) {
    for (std::size_t c = 0; c < change.dofs.size(); ++c) changed(change.dofs[r], change.dofs[c]) += change.matrix(r, c);
  }
  ForceEvaluation evaluation;
  model->evaluate(u, Vector::Zero(u.size()), 0.0, evaluation);
  Eigen::MatrixXd stiffness_free(n, n), changed_free(n, n);
  Vector force(n), step(n);
  for (int r = 0; r < n; ++r) {
    force[r] = evaluation.force[free[r]];
    step[r] = stepped[free[r]] - u[free[r]];
    for (int c = 0; c < n; ++c) {
      stiffness_free(r, c) = stiffness(free[r], free[c]);
      changed_free(r, c) = changed(free[r], free[c]);
    }
  }
  const Vector expected = changed_free.ldlt().solve(force);
  const Vector unchanged = stiffness_free.ldlt().solve(force);
  const double size = expected.lpNorm<Eigen::Infinity>();
  EXPECT_LT((step - expected).lpNorm<Eigen::Infinity>(), 1e-5 * size);
  EXPECT_GT((unchanged - expected).lpNorm<Eigen::Infinity>(), 1e-3 * size);
}

TEST(StaticSolver, MultigridIterationsDoNotGrowWithTheLattice) {
  // Multigrid's point: the work per solve grows as the unknowns, not faster. Each refinement doubles
  // the nodes per axis; the iterations to the 1e-10 residual stay within a few of each other.
  std::vector<int> iterations;
  for (const auto& [nx, nz] : {std::pair{57, 31}, std::pair{113, 61}, std::pair{225, 121}}) {
    auto model = pmmaLattice(nx, nz);
    model->disconnectPusher();
    ForceEvaluation load;
    const Vector zero = Vector::Zero(model->dofCount());
    model->evaluate(zero, zero, 0.0, load);
    const std::vector<int> fixed = model->blockedDofsDuringLoading();
    const StaticSolver multigrid(*model, fixed, false, StaticMethod::kMultigrid);
    const Vector solution = multigrid.response(load.force);
    const Vector direct = StaticSolver(*model, fixed, false, StaticMethod::kDirect).response(load.force);
    EXPECT_LT((solution - direct).lpNorm<Eigen::Infinity>(), 1e-8 * direct.lpNorm<Eigen::Infinity>()) << nx;
    iterations.push_back(multigrid.multigridIterations());
  }
  EXPECT_GT(iterations.front(), 0);
  EXPECT_LE(iterations.back(), iterations.front() + 3);
  EXPECT_LE(iterations.back(), 20);
}

}  // namespace
}  // namespace friction
