#include "sim/cloth_simulator.h"

#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>
#include <algorithm>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <gtest/gtest.h>

#include "common/random.h"
#include "sim/cloth_forces.h"
#include "sim/strain_limiter.h"
#include "sim/test_expect_throw.h"

namespace clothwind::sim {
namespace {

// A synthetic Wang-style material (generated, close to ArcSim's camel-ponte-roma in magnitude).
Material TestMaterial(const MaterialMultipliers& mult = {}) {
  Eigen::Matrix<double, 6, 4> s;
  s << 30, 5, 45, 30,  //
      80, 25, 260, 28, 70, 75, 180, 10, 110, 55, 175, 45, 145, 110, 140, 5, 145, 50, 190, 40;
  Eigen::Matrix<double, 3, 5> b;
  b << 3.6e-5, 5.0e-5, 4.6e-5, 4.7e-5, 2.1e-5, 3.3e-5, 3.0e-5, 3.5e-5, 3.4e-5, 1.4e-5, 3.7e-5,
      3.4e-5, 3.3e-5, 3.5e-5, 1.0e-5;
  return MakeMaterial(0.284, s, b, mult);
}

// A w x h rectangle in material space, refined to edges <= edge, placed by `place` (u, v) -> x.
Mesh Sheet(double w, double h, double edge,
           const std::function<Eigen::Vector3d(double, double)>& place) {
  Mesh m;
  m.U.resize(4, 2);
  m.U << 0, 0, w, 0, w, h, 0, h;
  m.V.resize(4, 3);
  m.F.resize(2, 3);
  m.F << 0, 1, 2, 0, 2, 3;
  for (int i = 0; i < 4; ++i) m.V.row(i) = Eigen::Vector3d(m.U(i, 0), m.U(i, 1), 0).transpose();
  m = RefineMesh(m, edge);
  for (int i = 0; i < m.V.rows(); ++i) m.V.row(i) = place(m.U(i, 0), m.U(i, 1)).transpose();
  return m;
}

// Vertical sheet in the x-z plane, top edge at z = 0, hanging from its two top corners
// (vertices 3 and 2 of the unrefined rectangle: (0, h) and (w, h) in material space).
Mesh HangingSheet(double w, double h, double edge) {
  return Sheet(w, h, edge, [h](double u, double v) { return Eigen::Vector3d(u, 0, v - h); });
}

// A material whose stiffness tables are constant (every stretching row and bending entry the
// same): its stretching force is exactly an energy's gradient, as ArcSim freezes the table lookup.
Material ConstantStiffnessMaterial(const MaterialMultipliers& mult = {}) {
  Eigen::Matrix<double, 6, 4> s;
  for (int r = 0; r < 6; ++r) s.row(r) << 60, 10, 90, 30;
  Eigen::Matrix<double, 3, 5> b;
  b.setConstant(3e-3);
  return MakeMaterial(0.3, s, b, mult);
}

SimOptions QuietOptions() {
  SimOptions o;
  o.wind_density = 0;  // no air at all (still air would still drag a moving cloth)
  o.self_collision = false;
  return o;
}

TEST(ClothSimulatorTest, FreeFallMatchesBackwardEulerExactly) {
  const Mesh m = Sheet(0.5, 0.4, 0.1, [](double u, double v) { return Eigen::Vector3d(u, v, 2.0); });
  SimOptions o = QuietOptions();
  o.dt = 0.01;
  o.cg_tolerance = 1e-13;
  o.bending_solve = BendingSolve::kImplicit;  // (bending is exactly translation-invariant)
  ClothSimulator sim(m, TestMaterial(), o, nullptr);
  const Eigen::Vector3d v0(0.3, -0.2, 1.5);
  const Eigen::MatrixX3d V0 = Eigen::RowVector3d(v0.transpose()).replicate(m.V.rows(), 1);
  sim.SetState(m.V, V0);
  const int n = 50;
  for (int i = 0; i < n; ++i) sim.Step();
  const double t = n * o.dt;
  EXPECT_NEAR(sim.time(), t, 1e-12);
  const Eigen::Vector3d g = o.gravity;
  // Backward Euler under a constant force: x_n = x0 + v0 t + g h^2 n (n + 1) / 2, i.e. the exact
  // x0 + v0 t + g t^2 / 2 plus the first-order error g t h / 2.
  const Eigen::Vector3d be = v0 * t + g * o.dt * o.dt * n * (n + 1) / 2;
  const Eigen::Vector3d exact = v0 * t + 0.5 * g * t * t;
  double worst = 0;
  for (int i = 0; i < m.V.rows(); ++i) {
    const Eigen::Vector3d dx = (sim.positions().row(i) - m.V.row(i)).transpose();
    worst = std::max(worst, (dx - be).norm());
  }
  EXPECT_LT(worst, 1e-9);
  EXPECT_NEAR((be - exact).norm(), 0.5 * g.norm() * t * o.dt, 1e-12);
  EXPECT_LT((sim.velocities().row(0).transpose() - (v0 + g * t)).norm(), 1e-9);
}

double MeanSag(const ClothSimulator& sim) {
  return (sim.mesh().V.col(2) - sim.positions().col(2)).mean();
}

// How far the final state of a hanging sheet is from static equilibrium, in units of a node's
// weight: the largest net force on a free node over its own weight m_i |g|, and the handles'
// reaction (minus the total force on the pinned nodes) against the whole cloth's weight M g,
// |R - (-M g)| / (M |g|).
struct Equilibrium {
  double worst_free_force = 0;
  double reaction_error = 0;
};

double HangAndMeasureSag(const MaterialMultipliers& mult, double* max_speed, Equilibrium* eq = nullptr) {
  const Mesh m = HangingSheet(0.6, 0.6, 0.08);
  SimOptions o = QuietOptions();
  o.wind_density = 1.0;  // still air damps the swinging like it does in reality
  o.handles = {2, 3};
  o.cg_tolerance = 1e-8;
  MaterialMultipliers damped = mult;
  damped.damping = 0.02;
  ClothSimulator sim(m, TestMaterial(damped), o, nullptr);
  for (int i = 0; i < 600; ++i) sim.Step();
  *max_speed = sim.velocities().rowwise().norm().maxCoeff();
  if (eq) {
    // A small speed alone does not make a rest state (a solve that barely moves the cloth creeps
    // slowly too): at rest every free node's forces cancel, and the handles carry the whole
    // weight, the internal forces summing to zero (Newton's third law in the assembly).
    const Eigen::MatrixX3d f = sim.Forces();
    const Eigen::VectorXd& mass = sim.masses();
    const double g = o.gravity.norm();
    Eigen::Vector3d on_handles = Eigen::Vector3d::Zero();
    for (int i = 0; i < f.rows(); ++i) {
      const bool pinned = std::find(o.handles.begin(), o.handles.end(), i) != o.handles.end();
      if (pinned)
        on_handles += f.row(i).transpose();
      else
        eq->worst_free_force = std::max(eq->worst_free_force, f.row(i).norm() / (mass[i] * g));
    }
    const Eigen::Vector3d reaction = -on_handles;  // what the handles must push with
    eq->reaction_error = (reaction + mass.sum() * o.gravity).norm() / (mass.sum() * g);
  }
  return MeanSag(sim);
}

TEST(ClothSimulatorTest, HangingClothReachesEquilibriumWithSagOrderedByStiffnessAndWeight) {
  double speed = 0;
  Equilibrium eq;
  const double base = HangAndMeasureSag({}, &speed, &eq);
  EXPECT_LT(speed, 2e-3) << "not at rest";
  EXPECT_GT(base, 1e-3);
  EXPECT_LT(eq.worst_free_force, 1e-3) << "a free node is not in equilibrium";
  EXPECT_LT(eq.reaction_error, 1e-6) << "the handles do not carry the cloth's weight";
  MaterialMultipliers stiff;
  stiff.stretching = 4;
  const double stiffer = HangAndMeasureSag(stiff, &speed);
  EXPECT_LT(speed, 2e-3);
  MaterialMultipliers heavy;
  heavy.density = 2;
  const double heavier = HangAndMeasureSag(heavy, &speed);
  EXPECT_LT(speed, 2e-3);
  EXPECT_LT(stiffer, 0.8 * base) << base << " vs " << stiffer;
  EXPECT_GT(heavier, 1.2 * base) << base << " vs " << heavier;
}

TEST(ClothSimulatorTest, EnergyDoesNotGrowWithoutInput) {
  // Released horizontally, pinned at one corner: swings down, bends, stretches, folds.
  const Mesh m = Sheet(0.5, 0.5, 0.07, [](double u, double v) { return Eigen::Vector3d(u, v, 0); });
  for (int variant = 0; variant < 5; ++variant) {
    // 0: elasticity only; 1: + strain limits; 2: + strain limits and self-repulsion;
    // 3: elasticity only, bending explicit; 4: + strain limits by the global method.
    SCOPED_TRACE("variant " + std::to_string(variant));
    SimOptions o = QuietOptions();
    o.handles = {0};
    if (variant >= 1 && variant != 3) {
      o.strain_min = 0.95;
      o.strain_max = 1.05;
    }
    if (variant == 4) {
      o.strain_limit_method = StrainLimitMethod::kGlobal;
      o.strain_limit_iterations = 30;
      o.strain_limit_tolerance = 1e-3;
    }
    o.self_collision = variant == 2;
    o.bending_solve = variant == 3 ? BendingSolve::kExplicit : BendingSolve::kImplicit;
    ClothSimulator sim(m, TestMaterial(), o, nullptr);
    const double e0 = sim.Energy().Total();
    const double scale = sim.masses().sum() * 9.8 * 0.5;  // m g L
    double previous = e0, highest = e0, worst_increase = 0;
    int increases = 0;
    for (int i = 0; i < 300; ++i) {
      sim.Step();
      const double e = sim.Energy().Total();
      highest = std::max(highest, e);
      if (e > previous + 1e-4 * scale) ++increases;
    worst_increase = std::max(worst_increase, e - previous);
      previous = e;
    }
    // Backward Euler (and the projections) only dissipate. Penalty contacts that start deep
    // within the thickness (a vertex may cross most of it in one step) store energy at once,
    // so with repulsion we only ask that the energy never rise above where it started.
    // Strain limiting moves positions and adds the move / dt to the velocities (as ArcSim does),
    // which may add a trace of kinetic energy in a step.
    // Explicit bending is not strictly dissipative either (a trace, at sharp folds).
    if (variant == 0) {
      EXPECT_EQ(increases, 0);
    }
    if (variant == 1 || variant == 3 || variant == 4) {
      EXPECT_LT(worst_increase, 1e-3 * scale);
    }
    // The global method's positions are a penalty fit stopped at a tolerance, not the exact
    // mass-weighted projection, and its move / dt adds energy the sweeps do not: 6.8e-4 m g L in
    // its worst step and 0.47 % of m g L above the start at most (stop 74; the sweeps: 7e-7, and
    // never above the start). Converged to 1e-7 it gains nothing (docs/simulator.md).
    EXPECT_LT(highest, e0 + (variant == 4 ? 1e-2 : 1e-4) * scale);
    EXPECT_LT(previous, e0 - 0.05 * scale);
  }
}

TEST(ClothSimulatorTest, HalvingTheTimeStepConvergesAtFirstOrder) {
  // A curtain hanging from its top edge, released 30 degrees from vertical in a light breeze: a
  // swing in tension (no buckling, whose direction would depend on round-off).
  const double h = 0.3;
  const Mesh m = Sheet(0.4, h, 0.1, [h](double u, double v) {
    return Eigen::Vector3d(u, 0.5 * (h - v), -0.866 * (h - v));
  });
  std::vector<int> top;
  for (int i = 0; i < m.U.rows(); ++i)
    if (m.U(i, 1) == h) top.push_back(i);
  ASSERT_GE(top.size(), 3u);
  for (bool implicit_bending : {true, false}) {
    SCOPED_TRACE(implicit_bending ? "implicit bending" : "explicit bending");
    auto run = [&](double dt) {
      SimOptions o = QuietOptions();
      o.wind_density = 1;
      o.dt = dt;
      o.handles = top;
      o.cg_tolerance = 1e-12;
      o.cg_max_iterations = 2000;
      o.bending_solve = implicit_bending ? BendingSolve::kImplicit : BendingSolve::kExplicit;
      ClothSimulator sim(m, TestMaterial(), o, std::make_shared<SteadyWind>(Eigen::Vector3d(1, 0, 0)));
      const int n = static_cast<int>(std::lround(0.16 / dt));
      for (int i = 0; i < n; ++i) sim.Step();
      return Eigen::MatrixX3d(sim.positions());
    };
    const Eigen::MatrixX3d a = run(0.004), b = run(0.002), c = run(0.001);
    const double e1 = (a - b).norm(), e2 = (b - c).norm();
    ASSERT_GT(e2, 0);
    const double ratio = e1 / e2;  // 2 for a first-order method
    EXPECT_GT(ratio, 1.7) << e1 << " " << e2;
    EXPECT_LT(ratio, 2.3) << e1 << " " << e2;
    EXPECT_GT(e1, 1e-4) << "the test should move the cloth";
  }
}

TEST(ClothSimulatorTest, HandlesStayPutAndStrainLimitsHold) {
  const Mesh m = HangingSheet(0.6, 0.6, 0.08);
  SimOptions o;
  o.handles = {2, 3};
  o.strain_min = 0.95;
  o.strain_max = 1.05;
  o.strain_limit_iterations = 40;
  ClothSimulator sim(m, TestMaterial(), o, std::make_shared<SteadyWind>(Eigen::Vector3d(0, 8, 0)));
  for (int i = 0; i < 200; ++i) sim.Step();
  for (int h : o.handles) EXPECT_EQ(sim.positions().row(h), m.V.row(h));
  // Deflected downwind (the sheet lies in the x-z plane; the wind blows along +y).
  EXPECT_GT(sim.positions().col(1).mean(), 0.05);
  // Principal stretches close to the limits (a few Gauss-Seidel sweeps, not ArcSim's exact
  // projection: the faces at the pinned corners, where stress concentrates, converge last).
  std::vector<double> stretch, squeeze;
  for (int f = 0; f < m.F.rows(); ++f) {
    const Eigen::Vector2d s = FacePrincipalStretches(m, sim.positions(), f);
    stretch.push_back(s[0]);
    squeeze.push_back(s[1]);
  }
  std::sort(stretch.begin(), stretch.end());
  std::sort(squeeze.begin(), squeeze.end());
  EXPECT_LT(stretch[stretch.size() * 99 / 100], 1.06);
  EXPECT_LT(stretch.back(), 1.08);
  // The lower limit too: the wind folds the sheet sideways, and no face is squeezed far below it.
  EXPECT_GT(squeeze[squeeze.size() / 100], 0.94);
  EXPECT_GT(squeeze.front(), 0.92);
  EXPECT_GT(sim.last_step_stats().strain_limited_faces, 0) << "the wind should strain the cloth";
}

TEST(ClothSimulatorTest, RayleighDampingTakesEnergyOutOfASwingingSheet) {
  // A sheet hanging from two corners, set swinging, in vacuum: backward Euler alone loses some
  // energy; the material's stiffness-proportional damping must take clearly more, and more with a
  // larger coefficient (dropping it from the matrix or the right-hand side fails this).
  const Mesh m = HangingSheet(0.5, 0.4, 0.1);
  SimOptions o = QuietOptions();
  o.handles = {2, 3};
  auto energy_after_swing = [&](double damping) {
    MaterialMultipliers mult;
    mult.damping = damping;
    ClothSimulator sim(m, TestMaterial(mult), o, nullptr);
    Eigen::MatrixX3d v = Eigen::MatrixX3d::Zero(m.V.rows(), 3);
    for (int i = 0; i < v.rows(); ++i) v(i, 1) = 3.0 * (-m.V(i, 2));  // faster further down
    sim.SetState(m.V, v);
    const double start = sim.Energy().Total();
    for (int i = 0; i < 100; ++i) sim.Step();
    return start - sim.Energy().Total();  // energy lost [J]
  };
  const double lost_plain = energy_after_swing(0.0);
  const double lost_some = energy_after_swing(0.01);
  const double lost_more = energy_after_swing(0.05);
  EXPECT_GT(lost_plain, 0.0);
  EXPECT_GT(lost_some, 1.2 * lost_plain);
  EXPECT_GT(lost_more, lost_some);
}

TEST(ClothSimulatorTest, UndampedSwingLosesEnergyOnlyAtBackwardEulersFirstOrder) {
  // Without Rayleigh damping, air, repulsion or strain limits, and with constant stiffness tables
  // (so Energy()'s gravitational + stretching + bending terms are exactly the potential of the
  // assembled forces: AssembledForcesAreMinusTheEnergysGradient), the only sink of energy is
  // backward Euler's numerical dissipation. It must (a) never add energy, beyond the linear
  // solve's round-off, and (b) shrink at first order: halving dt about halves the energy lost over
  // a fixed time. A spurious damping that does not vanish with h (a velocity scaling, a damping
  // floor) takes a loss that stays or grows at dt/2 and fails (b).
  const Mesh m = HangingSheet(0.5, 0.4, 0.1);
  const double T = 0.5;  // simulated time [s], about half a swing
  // Start from the sheet's equilibrium (settled with heavy damping): released at its rest shape,
  // gravity would ring its stiff stretching modes, which backward Euler damps out at any step
  // (they are far above 1 / dt), a loss that does not shrink with h.
  Eigen::MatrixX3d rest;
  {
    SimOptions o = QuietOptions();
    o.dt = 0.02;
    o.handles = {2, 3};
    o.bending_solve = BendingSolve::kImplicit;
    o.cg_tolerance = 1e-12;
    o.cg_max_iterations = 2000;
    MaterialMultipliers settle;
    settle.damping = 0.1;
    ClothSimulator sim(m, ConstantStiffnessMaterial(settle), o, nullptr);
    for (int i = 0; i < 300; ++i) sim.Step();
    ASSERT_LT(sim.velocities().norm(), 1e-6);
    rest = sim.positions();
  }
  auto energy_lost = [&](double dt, double* worst_increase, double* scale) {
    SimOptions o = QuietOptions();
    o.dt = dt;
    o.handles = {2, 3};
    o.bending_solve = BendingSolve::kImplicit;  // all forces in the backward Euler solve
    o.cg_tolerance = 1e-12;
    o.cg_max_iterations = 2000;
    ClothSimulator sim(m, ConstantStiffnessMaterial(), o, nullptr);
    // Swinging about the line of the two handles, faster further down.
    Eigen::MatrixX3d v = Eigen::MatrixX3d::Zero(m.V.rows(), 3);
    for (int i = 0; i < v.rows(); ++i) v(i, 1) = 2.0 * (-rest(i, 2));
    sim.SetState(rest, v);
    const double start = sim.Energy().Total();
    *scale = sim.masses().sum() * 9.8 * 0.4;  // m g L [J]
    double previous = start;
    *worst_increase = -std::numeric_limits<double>::infinity();
    const int n = static_cast<int>(std::lround(T / dt));
    for (int i = 0; i < n; ++i) {
      sim.Step();
      const double e = sim.Energy().Total();
      *worst_increase = std::max(*worst_increase, e - previous);
      previous = e;
    }
    return start - previous;  // [J]
  };
  double increase_coarse = 0, increase_fine = 0, scale = 0;
  const double lost_coarse = energy_lost(0.004, &increase_coarse, &scale);
  const double lost_fine = energy_lost(0.002, &increase_fine, &scale);
  EXPECT_LT(increase_coarse, 1e-9 * scale);
  EXPECT_LT(increase_fine, 1e-9 * scale);
  EXPECT_GT(lost_coarse, 1e-3 * scale) << "the swing should lose a measurable energy";
  const double ratio = lost_fine / lost_coarse;  // 1/2 at first order
  EXPECT_GT(ratio, 0.35) << "lost " << lost_coarse << " J at dt, " << lost_fine << " J at dt/2";
  EXPECT_LT(ratio, 0.65) << "lost " << lost_coarse << " J at dt, " << lost_fine << " J at dt/2";
}

TEST(ClothSimulatorTest, AutoBendingGoesImplicitOnlyForStiffBending) {
  const Mesh m = HangingSheet(0.6, 0.6, 0.08);
  SimOptions o;
  ClothSimulator soft(m, TestMaterial(), o, nullptr);
  EXPECT_FALSE(soft.last_step_stats().implicit_bending);
  MaterialMultipliers stiff;
  stiff.bending = 1e5;  // a sheet of metal rather than fabric
  ClothSimulator hard(m, TestMaterial(stiff), o, nullptr);
  EXPECT_TRUE(hard.last_step_stats().implicit_bending);
  // Explicit bending that auto refuses does go wrong (a wild, non-physical motion); implicit not.
  double speed[2];
  for (BendingSolve mode : {BendingSolve::kExplicit, BendingSolve::kImplicit}) {
    SimOptions forced = QuietOptions();
    forced.bending_solve = mode;
    forced.handles = {2, 3};
    Mesh bent = m;
    for (int i = 0; i < bent.V.rows(); ++i) bent.V(i, 1) = 0.05 * std::sin(10 * bent.U(i, 0));
    ClothSimulator sim(bent, TestMaterial(stiff), forced, nullptr);
    try {
      for (int i = 0; i < 100; ++i) sim.Step();
      speed[mode == BendingSolve::kImplicit] = sim.velocities().rowwise().norm().maxCoeff();
    } catch (const std::runtime_error& e) {  // Step's blow-up check (SimOptions.max_speed)
      speed[mode == BendingSolve::kImplicit] = std::numeric_limits<double>::infinity();
      EXPECT_EQ(mode, BendingSolve::kExplicit) << e.what();
    }
  }
  EXPECT_LT(speed[1], 10.0);
  EXPECT_FALSE(speed[0] < 2 * speed[1]) << speed[0] << " vs " << speed[1];  // NaN counts as wrong
}

TEST(ClothSimulatorTest, RepulsionKeepsFallingSheetAboveAnother) {
  // Two 0.4 m sheets in one mesh: the lower one pinned everywhere (a floor of cloth), the upper
  // one 4 cm above it, dropped.
  const Mesh lower = Sheet(0.4, 0.4, 0.05, [](double u, double v) { return Eigen::Vector3d(u, v, 0); });
  Mesh m;
  const int n = static_cast<int>(lower.V.rows());
  m.V.resize(2 * n, 3);
  m.U.resize(2 * n, 2);
  m.F.resize(2 * lower.F.rows(), 3);
  m.V << lower.V, lower.V.rowwise() + Eigen::RowVector3d(0.013, 0.021, 0.04);
  m.U << lower.U, lower.U;
  m.F << lower.F, lower.F.array() + n;
  auto run = [&](bool collide) {
    SimOptions o;
    o.self_collision = collide;
    for (int i = 0; i < n; ++i) o.handles.push_back(i);
    ClothSimulator sim(m, TestMaterial(), o, nullptr);
    for (int i = 0; i < 200; ++i) sim.Step();
    // Lowest upper-sheet vertex that lies over the lower sheet's interior.
    double lowest = 1e9;
    for (int i = n; i < 2 * n; ++i) {
      const double x = sim.positions()(i, 0), y = sim.positions()(i, 1);
      if (x > 0.02 && x < 0.38 && y > 0.02 && y < 0.38) lowest = std::min(lowest, sim.positions()(i, 2));
    }
    return lowest;
  };
  EXPECT_GT(run(true), 0.0);
  EXPECT_LT(run(false), -0.05);  // the test can fail: without repulsion it falls through
}

TEST(ClothSimulatorTest, ForcesIncludeGravityAndArcSimWind) {
  Mesh m;
  m.V.resize(3, 3);
  m.V << 0, 0, 0, 0, 1, 0, 0, 0, 1;  // in the y-z plane, normal along +-x
  m.U = m.V.rightCols(2);
  m.F.resize(1, 3);
  m.F << 0, 1, 2;
  SimOptions o;
  o.wind_density = 1.2;
  o.wind_drag = 0.1;
  ClothSimulator sim(m, TestMaterial(), o, std::make_shared<SteadyWind>(Eigen::Vector3d(5, 1, 0)));
  const Eigen::MatrixX3d f = sim.Forces();
  const double area = 0.5;
  const Eigen::Vector3d wind_total = 1.2 * area * 25 * Eigen::Vector3d::UnitX() + 0.1 * area * Eigen::Vector3d(0, 1, 0);
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d expected = sim.masses()[i] * o.gravity + wind_total / 3;
    EXPECT_LT((f.row(i).transpose() - expected).norm(), 1e-9) << f.row(i);
  }
  EXPECT_NEAR(sim.masses().sum(), 0.284 * area, 1e-12);
}

// A wind that varies over space (and in time): its value at a face's centroid differs from its
// value at any vertex, at the origin, and from the mean of the vertices' values (it is not linear).
class CurvedWind final : public WindField {
 public:
  Eigen::Vector3d Velocity(const Eigen::Vector3d& x, double t) const override {
    return Eigen::Vector3d(4 + 3 * x.y() * x.y() + x.z() + t, 1 + 2 * x.z() - x.y() * x.z(), 0.5 * x.y());
  }
};

TEST(ClothSimulatorTest, WindIsSampledAtTheCentroidAndActsOnTheRestArea) {
  // docs/simulator.md: per face, the wind is queried at the face centroid and A is the rest area.
  // The test above has a steady wind and an undeformed face, so the wind at a vertex or at the
  // origin, or the current area, gave the same forces. Here the face is stretched 1.2x from rest
  // (current area 1.44 x rest), moving, away from the origin, in a wind that varies over space.
  Mesh m;
  m.V.resize(3, 3);
  m.V << 0, 0, 0, 0, 1, 0, 0, 0, 1;  // rest: in the y-z plane, area 0.5
  m.U = m.V.rightCols(2);
  m.F.resize(1, 3);
  m.F << 0, 1, 2;
  Eigen::MatrixX3d x(3, 3), v(3, 3);
  for (int i = 0; i < 3; ++i) x.row(i) << 0.3, 0.5 + 1.2 * m.V(i, 1), 0.2 + 1.2 * m.V(i, 2);
  v << 0.1, 0.0, 0.2, -0.3, 0.1, 0.0, 0.2, 0.0, -0.1;
  SimOptions o;
  o.wind_density = 1.2;
  o.wind_drag = 0.1;
  const auto wind = std::make_shared<CurvedWind>();
  ClothSimulator sim(m, TestMaterial(), o, wind);
  // The same cloth without any air: gravity and stretching only, so the difference is the wind's.
  SimOptions still = o;
  still.wind_density = 0;
  still.wind_drag = 0;
  ClothSimulator no_air(m, TestMaterial(), still, nullptr);
  sim.SetState(x, v);
  no_air.SetState(x, v);
  const Eigen::MatrixX3d f_wind = sim.Forces() - no_air.Forces();
  Vector9d xf, vf;
  for (int c = 0; c < 3; ++c) {
    xf.segment<3>(3 * c) = x.row(c).transpose();
    vf.segment<3>(3 * c) = v.row(c).transpose();
  }
  const Eigen::Vector3d centroid = (x.row(0) + x.row(1) + x.row(2)).transpose() / 3.0;
  const double rest_area = 0.5, current_area = 1.44 * rest_area;
  const double t = sim.time();
  auto as_rows = [](const Vector9d& f) {
    Eigen::MatrixX3d r(3, 3);
    for (int c = 0; c < 3; ++c) r.row(c) = f.segment<3>(3 * c).transpose();
    return r;
  };
  const Eigen::MatrixX3d expected =
      as_rows(WindForce(xf, vf, wind->Velocity(centroid, t), rest_area, o.wind_density, o.wind_drag));
  EXPECT_LT((f_wind - expected).norm(), 1e-12 * expected.norm()) << f_wind << "\nexpected\n" << expected;
  // The variants the test must tell apart differ from it by far more than its tolerance.
  const Eigen::Vector3d mean_of_vertices =
      (wind->Velocity(x.row(0).transpose(), t) + wind->Velocity(x.row(1).transpose(), t) +
       wind->Velocity(x.row(2).transpose(), t)) / 3.0;
  for (const Eigen::MatrixX3d& wrong :
       {as_rows(WindForce(xf, vf, wind->Velocity(x.row(0).transpose(), t), rest_area, 1.2, 0.1)),
        as_rows(WindForce(xf, vf, wind->Velocity(Eigen::Vector3d::Zero(), t), rest_area, 1.2, 0.1)),
        as_rows(WindForce(xf, vf, mean_of_vertices, rest_area, 1.2, 0.1)),
        as_rows(WindForce(xf, vf, wind->Velocity(centroid, t), current_area, 1.2, 0.1))})
    EXPECT_GT((wrong - expected).norm(), 1e-3 * expected.norm());
}

// The central difference of the simulator's forces along dx at x (at rest), step h: what the
// force Jacobian times dx must be where its form is exact.
Eigen::MatrixX3d ForcesCentralDifference(ClothSimulator& sim, const Eigen::MatrixX3d& x, const Eigen::MatrixX3d& dx,
                                         double h) {
  const Eigen::MatrixX3d still = Eigen::MatrixX3d::Zero(x.rows(), 3);
  sim.SetState(x + h * dx, still);
  const Eigen::MatrixX3d plus = sim.Forces();
  sim.SetState(x - h * dx, still);
  const Eigen::MatrixX3d minus = sim.Forces();
  sim.SetState(x, still);
  return (plus - minus) / (2 * h);
}

// Expects the simulator's forces at x (at rest) to be minus the central-difference gradient of
// `potential` (the terms of Energy() that have a force), coordinate by coordinate, step h [m].
void ExpectForcesAreMinusTheGradient(ClothSimulator& sim, const Eigen::MatrixX3d& x,
                                     const std::function<double(const ClothEnergy&)>& potential, double h) {
  const Eigen::MatrixX3d still = Eigen::MatrixX3d::Zero(x.rows(), 3);
  sim.SetState(x, still);
  const Eigen::MatrixX3d f = sim.Forces();
  auto at = [&](const Eigen::MatrixX3d& y) {
    sim.SetState(y, still);
    return potential(sim.Energy());
  };
  Eigen::MatrixX3d g(x.rows(), 3);
  for (int i = 0; i < x.rows(); ++i)
    for (int c = 0; c < 3; ++c) {
      Eigen::MatrixX3d a = x, z = x;
      a(i, c) += h;
      z(i, c) -= h;
      g(i, c) = -(at(a) - at(z)) / (2 * h);
    }
  EXPECT_LT((f - g).norm(), 1e-6 * f.norm()) << "|F| " << f.norm() << ", |F + dE/dx| " << (f - g).norm();
  sim.SetState(x, still);
}

TEST(ClothSimulatorTest, AssembledForcesAreMinusTheEnergysGradient) {
  // The element tests check each force against its own energy; this checks the simulator's
  // assembly (bending is written inline in the force loop, in both bending modes) against central
  // differences of Energy() on a curved, stretched sheet. The stiffness tables are constant, so
  // the stretching force is exactly an energy's gradient (ArcSim freezes the table lookup).
  const Material material = ConstantStiffnessMaterial();
  const Mesh m = Sheet(0.4, 0.3, 0.12, [](double u, double v) { return Eigen::Vector3d(u, v, 0); });
  Eigen::MatrixX3d x = m.V;
  for (int i = 0; i < x.rows(); ++i) {
    x(i, 0) *= 1.03;
    x(i, 2) = 0.1 * std::sin(7 * m.U(i, 0)) * std::cos(5 * m.U(i, 1)) + 0.01 * std::sin(31.0 * i);
  }
  for (const BendingSolve mode : {BendingSolve::kExplicit, BendingSolve::kImplicit}) {
    SCOPED_TRACE(mode == BendingSolve::kExplicit ? "explicit bending" : "implicit bending");
    SimOptions o = QuietOptions();
    o.bending_solve = mode;
    ClothSimulator sim(m, material, o, nullptr);
    ExpectForcesAreMinusTheGradient(
        sim, x, [](const ClothEnergy& e) { return e.gravitational + e.stretching + e.bending; }, 1e-6);
  }
}

TEST(ClothSimulatorTest, AssembledJacobianIsTheForcesDerivativeWhereItsFormIsExact) {
  // The element Jacobians have their own finite-difference tests; this checks their assembly into
  // the step's block pattern (face, hinge and diagonal block indices). In a flat sheet stretched
  // uniformly (3 % along u, 2 % along v) the positive-definite stretching Jacobian and the
  // Gauss-Newton bending one are exact (every hinge at 0), so (dF/dx) dx must equal the central
  // difference of Forces() along random dx, for every node at once.
  const Material material = ConstantStiffnessMaterial();
  const Mesh m = Sheet(0.4, 0.3, 0.12, [](double u, double v) { return Eigen::Vector3d(1.03 * u, 1.02 * v, 0); });
  SimOptions o = QuietOptions();
  o.bending_solve = BendingSolve::kImplicit;
  ClothSimulator sim(m, material, o, nullptr);
  const Eigen::MatrixX3d x = m.V, still = Eigen::MatrixX3d::Zero(x.rows(), 3);
  Eigen::MatrixX3d dx(x.rows(), 3);
  for (int i = 0; i < dx.rows(); ++i)
    for (int c = 0; c < 3; ++c) dx(i, c) = std::sin(12.9898 * i + 78.233 * c);  // fixed, unstructured
  sim.SetState(x, still);
  const Eigen::MatrixX3d jdx = sim.ForceJacobianTimes(dx);
  const Eigen::MatrixX3d fd = ForcesCentralDifference(sim, x, dx, 1e-7);
  EXPECT_LT((jdx - fd).norm(), 1e-5 * fd.norm()) << "|J dx| " << jdx.norm() << ", |FD| " << fd.norm();
  // Bending contributes (it is in the matrix, implicit): without it the match fails.
  o.bending_solve = BendingSolve::kExplicit;
  ClothSimulator explicit_bending(m, material, o, nullptr);
  explicit_bending.SetState(x, still);
  EXPECT_GT((explicit_bending.ForceJacobianTimes(dx) - fd).norm(), 1e-3 * fd.norm());
}

// The assembled Jacobian is negative semidefinite where the exact one is not: a sheet compressed
// 10 % along u and 5 % along v, crumpled by 1 mm, with a strain-dependent table and implicit
// bending, probed along random directions and smooth folds out of plane (where compression
// buckles). The implicit step solves (M - h^2 J) dv = ..., which conjugate gradients needs
// positive definite; the exact stretching Jacobian of a compressed face is indefinite, and only
// its definite form (ArcSim's max(G, 0)) keeps dx^T J dx <= 0. The tests above check the form
// where both agree (uniform tension), so the exact form put in the assembly passed them.
TEST(ClothSimulatorTest, AssembledJacobianIsNegativeSemidefiniteOnACrumpledCompressedSheet) {
  Eigen::Matrix<double, 6, 4> stretching;
  stretching << 30, 5, 45, 30,  //
      80, 25, 260, 28, 70, 75, 180, 10, 110, 55, 175, 45, 145, 110, 140, 5, 145, 50, 190, 40;
  Eigen::Matrix<double, 3, 5> bending;
  bending << 1e-5, 2e-5, 4e-5, 8e-5, 16e-5, 3e-5, 5e-5, 7e-5, 9e-5, 11e-5, 20e-5, 15e-5, 10e-5, 5e-5, 2e-5;
  const Material material = MakeMaterial(0.284, stretching, bending);
  const Mesh m = Sheet(0.4, 0.3, 0.05, [](double u, double v) {
    return Eigen::Vector3d(0.9 * u, 0.95 * v, 1e-3 * std::sin(31.0 * u) * std::cos(23.0 * v));
  });
  SimOptions o = QuietOptions();
  o.bending_solve = BendingSolve::kImplicit;
  ClothSimulator sim(m, material, o, nullptr);
  sim.SetState(m.V, Eigen::MatrixX3d::Zero(m.V.rows(), 3));
  double worst = -1e300, scale = 0;
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::MatrixX3d dx(m.V.rows(), 3);
    for (int i = 0; i < dx.rows(); ++i)
      for (int c = 0; c < 3; ++c) dx(i, c) = std::sin(12.9898 * i + 78.233 * c + 37.719 * trial);
    if (trial % 2) {  // a smooth fold out of plane: the direction compression buckles into
      dx.setZero();
      for (int i = 0; i < dx.rows(); ++i)
        dx(i, 2) = std::sin(M_PI * (1 + trial % 3) * m.U(i, 0) / 0.4 + trial) * std::cos(M_PI * m.U(i, 1) / 0.3);
    }
    const Eigen::MatrixX3d jdx = sim.ForceJacobianTimes(dx);
    const double quadratic = (dx.array() * jdx.array()).sum();
    worst = std::max(worst, quadratic);
    scale = std::max(scale, dx.norm() * jdx.norm());
  }
  EXPECT_LE(worst, 1e-12 * scale) << "dx^T J dx = " << worst << " > 0";
}

// Two flat 0.2 m sheets in one mesh, the upper 5 mm above the lower (within the 10 mm repulsion
// thickness) and shifted so each one's vertices lie over the other's faces.
Mesh TwoSheetsInContact() {
  const Mesh lower = Sheet(0.2, 0.2, 0.1, [](double u, double v) { return Eigen::Vector3d(u, v, 0); });
  const Mesh upper = Sheet(0.2, 0.2, 0.1, [](double u, double v) { return Eigen::Vector3d(u + 0.031, v + 0.047, 5e-3); });
  Mesh m;
  const int n = static_cast<int>(lower.V.rows());
  m.V.resize(2 * n, 3);
  m.V << lower.V, upper.V;
  m.U.resize(2 * n, 2);
  m.U << lower.U, upper.U;
  m.F.resize(lower.F.rows() + upper.F.rows(), 3);
  m.F << lower.F, (upper.F.array() + n).matrix();
  return m;
}

// The repulsion's scale against ArcSim's rule evaluated by hand: collision_stiffness times the
// smaller of the vertex's area (a third of its faces' rest areas) and the face's. A small
// triangle's three corners hover 5 mm over a large one, so the vertex area is 1/800 of the
// face's; the finite-difference tests cancel the scale, so max() or the face's area alone passed.
TEST(ClothSimulatorTest, RepulsionStiffnessIsTheSmallerOfTheVertexAndFaceAreas) {
  Mesh m;
  m.V.resize(6, 3);
  m.V << 0, 0, 0, 0.4, 0, 0, 0, 0.4, 0,  // face 0: 0.08 m^2
      0.1, 0.1, 0.005, 0.13, 0.1, 0.005, 0.1, 0.12, 0.005;  // face 1: 3e-4 m^2, over face 0
  m.U = m.V.leftCols(2);
  m.F.resize(2, 3);
  m.F << 0, 1, 2, 3, 4, 5;
  SimOptions o = QuietOptions();
  o.gravity.setZero();
  ClothSimulator apart(m, ConstantStiffnessMaterial(), o, nullptr);
  o.self_collision = true;
  ClothSimulator close(m, ConstantStiffnessMaterial(), o, nullptr);
  const Eigen::MatrixX3d repulsion = close.Forces() - apart.Forces();

  const Eigen::Vector3d a = m.V.row(0).transpose(), b = m.V.row(1).transpose(), c = m.V.row(2).transpose();
  const double face_area = 0.5 * (b - a).cross(c - a).norm();
  const double vertex_area = 0.5 * (m.V.row(4) - m.V.row(3)).cross(m.V.row(5) - m.V.row(3)).norm() / 3.0;
  ASSERT_LT(800 * vertex_area, 1.01 * face_area);
  const double stiffness = o.collision_stiffness * std::min(vertex_area, face_area);
  Eigen::MatrixX3d expected = Eigen::MatrixX3d::Zero(6, 3);
  for (int p = 3; p < 6; ++p) {
    Vector12d x;
    x << m.V.row(p).transpose(), a, b, c;
    const double side = (b - a).cross(c - a).dot(m.V.row(p).transpose() - a) > 0 ? 1.0 : -1.0;
    const Vector12d f = RepulsionForce(x, side, o.repulsion_thickness, stiffness).force;
    expected.row(p) += f.segment<3>(0).transpose();
    for (int k = 0; k < 3; ++k) expected.row(k) += f.segment<3>(3 + 3 * k).transpose();
  }
  ASSERT_GT(expected.norm(), 0.0);
  EXPECT_LT((repulsion - expected).norm(), 1e-9 * expected.norm()) << "repulsion\n" << repulsion << "\nexpected\n"
                                                                   << expected;
}

// A coarse panel beside a fine one in one mesh: a 2 m square of two faces and, 5 mm above its
// middle, a 0.2 m sheet of ~1 cm edges (so the mean rest edge is under 2 cm). The proximity
// grid's cell was the mean edge, raised to twice the 1 cm thickness: 2 cm, across which each large
// face spans about 100 cells, and the grid skips a face past 32 as an exploded one: no fine
// vertex was repelled from the panel under it. Each must be, upwards (its faces' own sheet is flat
// and adds nothing along z).
TEST(ClothSimulatorTest, RepulsionReachesAFaceFarLargerThanTheMeanEdge) {
  const Mesh fine = Sheet(0.2, 0.2, 0.01, [](double u, double v) { return Eigen::Vector3d(0.9 + u, 0.9 + v, 5e-3); });
  Mesh m;
  const int n = static_cast<int>(fine.V.rows());
  m.V.resize(4 + n, 3);
  m.V.topRows(4) << 0, 0, 0, 2, 0, 0, 2, 2, 0, 0, 2, 0;
  m.V.bottomRows(n) = fine.V;
  m.U = m.V.leftCols(2);
  m.F.resize(2 + fine.F.rows(), 3);
  m.F.topRows(2) << 0, 1, 2, 0, 2, 3;
  m.F.bottomRows(fine.F.rows()) = (fine.F.array() + 4).matrix();
  SimOptions o = QuietOptions();
  o.gravity.setZero();
  ASSERT_EQ(o.repulsion_thickness, 0.01);
  ClothSimulator apart(m, ConstantStiffnessMaterial(), o, nullptr);
  o.self_collision = true;
  ClothSimulator close(m, ConstantStiffnessMaterial(), o, nullptr);
  const Eigen::MatrixX3d repulsion = close.Forces() - apart.Forces();
  int repelled = 0;
  for (int p = 4; p < 4 + n; ++p) repelled += repulsion(p, 2) > 0 ? 1 : 0;
  EXPECT_EQ(repelled, n) << "of the fine sheet's " << n << " vertices, 5 mm over the panel, only " << repelled
                         << " were pushed up";
  EXPECT_LT(repulsion.topRows(4).col(2).sum(), 0) << "the panel is not pushed down";
}

// Two free sheets in contact, no gravity, no air, no handles: every internal force and every
// Jacobian block comes in pairs that sum to zero, so the total momentum is kept step after step
// (to the linear solve's tolerance). A term that is not translation-invariant, or a block added on
// one side only, shows here first.
TEST(ClothSimulatorTest, FreeSheetsInContactKeepTheirMomentum) {
  const Mesh m = TwoSheetsInContact();
  SimOptions o = QuietOptions();
  o.self_collision = true;
  o.gravity.setZero();
  o.crossing_sweeps = 0;
  o.cg_tolerance = 1e-13;
  o.cg_max_iterations = 5000;
  o.bending_solve = BendingSolve::kImplicit;
  ClothSimulator sim(m, ConstantStiffnessMaterial(), o, nullptr);
  Eigen::MatrixX3d v(m.V.rows(), 3);
  for (int i = 0; i < v.rows(); ++i)
    for (int c = 0; c < 3; ++c) v(i, c) = 0.2 * std::sin(12.9898 * i + 78.233 * c);
  Eigen::MatrixX3d x = m.V;
  for (int i = 0; i < x.rows(); ++i) x(i, 2) += 1e-3 * std::sin(3.1 * i);  // gaps 3-7 mm: repelling
  sim.SetState(x, v);
  const Eigen::VectorXd& mass = sim.masses();
  const Eigen::RowVector3d start = mass.transpose() * v;
  const double scale = mass.sum() * v.rowwise().norm().maxCoeff();
  int repelling_steps = 0;
  for (int step = 0; step < 20; ++step) {
    sim.Step();
    repelling_steps += sim.last_step_stats().repulsion_pairs > 0 ? 1 : 0;
    const Eigen::RowVector3d now = mass.transpose() * sim.velocities();
    ASSERT_LT((now - start).norm(), 1e-9 * scale) << "step " << step << ": " << now << " against " << start;
  }
  EXPECT_GT(repelling_steps, 0);  // the contact was in the steps
}

TEST(ClothSimulatorTest, RepulsionInTheAssembledForcesIsMinusItsEnergysGradient) {
  // The element test checks the repulsion force against its own energy; this checks it inside the
  // simulator (pairs found, forces added at the vertex and its face's three) and that Energy()
  // reports the repulsion of the state it is asked about.
  const Mesh m = TwoSheetsInContact();
  SimOptions o = QuietOptions();
  o.self_collision = true;
  o.gravity.setZero();
  ClothSimulator sim(m, ConstantStiffnessMaterial(), o, nullptr);
  Eigen::MatrixX3d x = m.V;
  for (int i = 0; i < x.rows(); ++i) x(i, 2) += 1e-3 * std::sin(3.1 * i);  // gaps 3-7 mm, not uniform
  const Eigen::MatrixX3d still = Eigen::MatrixX3d::Zero(x.rows(), 3);
  sim.SetState(x, still);
  const Eigen::MatrixX3d f = sim.Forces();
  const double repulsion = sim.Energy().repulsion;
  ASSERT_GT(repulsion, 0) << "the sheets are not in contact";
  // Energy() of a state further apart is smaller: it is the asked state's, not the last step's.
  Eigen::MatrixX3d apart = x;
  apart.bottomRows(x.rows() / 2).col(2).array() += 2e-3;
  sim.SetState(apart, still);
  EXPECT_LT(sim.Energy().repulsion, repulsion);
  // A step far below the distances at which a pair switches on or off.
  ExpectForcesAreMinusTheGradient(
      sim, x, [](const ClothEnergy& e) { return e.stretching + e.bending + e.repulsion; }, 1e-7);
  // Without the repulsion the forces differ: the check above is not about the sheets alone.
  SimOptions apart_options = o;
  apart_options.self_collision = false;
  ClothSimulator no_contact(m, ConstantStiffnessMaterial(), apart_options, nullptr);
  no_contact.SetState(x, still);
  EXPECT_GT((no_contact.Forces() - f).norm(), 0.1 * f.norm());
}

TEST(ClothSimulatorTest, AssembledRepulsionJacobianIsTheForcesDerivativeAlongTheNormal) {
  // The repulsion Jacobian is Gauss-Newton: exact where the normals do not turn. Moving the upper
  // flat sheet rigidly along the normal (z) turns none, stretches and bends nothing, so J dx must
  // equal the central difference of Forces(): a check of every block the repulsion adds (the
  // vertex's diagonal block, a face's own blocks, and the vertex-to-face-vertex blocks outside
  // the fixed pattern).
  const Mesh m = TwoSheetsInContact();
  SimOptions o = QuietOptions();
  o.self_collision = true;
  o.gravity.setZero();
  o.bending_solve = BendingSolve::kImplicit;
  ClothSimulator sim(m, ConstantStiffnessMaterial(), o, nullptr);
  const Eigen::MatrixX3d x = m.V, still = Eigen::MatrixX3d::Zero(x.rows(), 3);
  Eigen::MatrixX3d dx = Eigen::MatrixX3d::Zero(x.rows(), 3);
  dx.bottomRows(x.rows() / 2).col(2).setOnes();
  sim.SetState(x, still);
  const Eigen::MatrixX3d jdx = sim.ForceJacobianTimes(dx);
  const Eigen::MatrixX3d fd = ForcesCentralDifference(sim, x, dx, 1e-7);
  ASSERT_GT(fd.norm(), 1.0) << "the sheets are not in contact";
  EXPECT_LT((jdx - fd).norm(), 1e-5 * fd.norm()) << "|J dx| " << jdx.norm() << ", |FD| " << fd.norm();
  // The lower sheet is pushed too (through the blocks between a vertex and another sheet's face).
  EXPECT_GT(jdx.topRows(x.rows() / 2).norm(), 0.1 * jdx.norm());
}

TEST(ClothSimulatorTest, OneStepSolvesTheLinearSystemForceJacobianTimesDescribes) {
  // The step is one Newton iteration of backward Euler with Rayleigh damping:
  //   (M - h (h + gamma) K) dv = h (f0 + (h + gamma) K v0)   on the free rows,
  // K the force Jacobian at x0. ForceJacobianTimes is checked against finite differences above;
  // this checks that the step solves the system built from that same K, every block included:
  // damping in the matrix and the right-hand side, the repulsion blocks outside the fixed pattern,
  // the pinned rows left out. The energy and damping tests pass with damping doubled or the
  // off-pattern blocks dropped; this residual is ~1e-12 and those make it 0.1-0.75.
  const double gamma = 0.02;
  auto sheet = [](double dx, double dy, double z) {
    return Sheet(0.2, 0.2, 0.05, [=](double u, double v) {
      return Eigen::Vector3d(1.02 * u + dx, v + dy, z + 0.004 * std::sin(40 * u));  // stretched, wavy
    });
  };
  const Mesh lower = sheet(0, 0, 0), upper = sheet(0.031, 0.047, 5e-3);  // 5 mm apart: in contact
  const int n = static_cast<int>(lower.V.rows());
  Mesh m;
  m.V.resize(2 * n, 3);
  m.V << lower.V, upper.V;
  m.U.resize(2 * n, 2);
  m.U << lower.U, upper.U;
  m.F.resize(2 * lower.F.rows(), 3);
  m.F << lower.F, (upper.F.array() + n).matrix();
  MaterialMultipliers mult;
  mult.damping = gamma;
  SimOptions o = QuietOptions();
  o.self_collision = true;
  o.crossing_sweeps = 0;  // the correction after the solve would move x, not v, but keep it out
  o.bending_solve = BendingSolve::kImplicit;  // bending in K too
  o.cg_tolerance = 1e-12;
  o.cg_max_iterations = 5000;
  o.handles = {0, 1, n + 2};
  ClothSimulator sim(m, ConstantStiffnessMaterial(mult), o, nullptr);
  Rng rng(11);
  Eigen::MatrixX3d v0(m.V.rows(), 3);
  for (int i = 0; i < v0.rows(); ++i)
    for (int c = 0; c < 3; ++c) v0(i, c) = rng.Uniform(-0.5, 0.5);  // [m/s]
  for (int h : o.handles) v0.row(h).setZero();
  const Eigen::MatrixX3d x0 = m.V;
  sim.SetState(x0, v0);
  const Eigen::MatrixX3d f0 = sim.Forces(), Kv0 = sim.ForceJacobianTimes(v0);
  sim.Step();
  ASSERT_GT(sim.last_step_stats().repulsion_pairs, 10) << "the sheets are not in contact";
  EXPECT_LT(sim.last_step_stats().cg_relative_residual, 1e-12);
  const Eigen::MatrixX3d dv = sim.velocities() - v0;
  sim.SetState(x0, v0);  // K at x0, where the step assembled it
  const Eigen::MatrixX3d Kdv = sim.ForceJacobianTimes(dv);
  const double h = o.dt;
  Eigen::MatrixX3d lhs = sim.masses().asDiagonal() * dv - h * (h + gamma) * Kdv;
  Eigen::MatrixX3d rhs = h * (f0 + (h + gamma) * Kv0);
  for (int p : o.handles) {
    EXPECT_EQ(sim.velocities().row(p).norm(), 0.0) << "handle " << p;  // (dv = 0 there)
    lhs.row(p).setZero();
    rhs.row(p).setZero();
  }
  // Each term matters at this size (so dropping one cannot pass): |h (h + gamma) K v0| and
  // |h f0| are both a good part of |rhs|.
  ASSERT_GT((h * (h + gamma) * Kv0).norm(), 0.1 * rhs.norm());
  ASSERT_GT((h * f0).norm(), 0.1 * rhs.norm());
  EXPECT_LT((lhs - rhs).norm(), 1e-9 * rhs.norm())
      << "|M dv - h(h+g) K dv - h(f0 + (h+g) K v0)| / |rhs| = " << (lhs - rhs).norm() / rhs.norm();
}

TEST(ClothSimulatorTest, ALinearSystemBeyondDoubleRangeThrowsInsteadOfFreezingTheCloth) {
  // Gravity of 1e200 m/s^2 gives finite forces (~1e197 N) whose sum of squares overflows: the
  // relative residual was inf / inf = NaN, `NaN > tol` is false, so CG stopped before its first
  // iteration and the step left the cloth exactly where it was (a scene ran to its end, exit 0,
  // with a cloth that never moved). A damping of 1e307 s leaves the right-hand side of a cloth at
  // rest finite but overflows the matrix: the residual turns NaN inside the iterations, which
  // ended the solve as if converged.
  const Mesh m = HangingSheet(0.3, 0.3, 0.15);
  SimOptions o = QuietOptions();
  o.handles = {2, 3};
  SimOptions heavy = o;
  heavy.gravity = Eigen::Vector3d(0, 0, -1e200);
  MaterialMultipliers sticky;
  sticky.damping = 1e307;
  struct Case {
    const char* name;
    SimOptions options;
    Material material;
    const char* says;
  };
  const Case cases[] = {
      {"gravity 1e200", heavy, TestMaterial(), "right-hand side h (f + (h + damping) K v) has a norm beyond double range"},
      {"damping 1e307", o, TestMaterial(sticky), "residual became non-finite after 0 CG iterations"}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    ClothSimulator sim(m, c.material, c.options, nullptr);
    ExpectThrowContaining([&] { sim.Step(); }, "blew up at t = 0.0050 s (step 1)");
    ExpectThrowContaining([&] { sim.Step(); }, c.says);  // stays failed, naming the cause
    EXPECT_TRUE(sim.positions() == m.V);  // (the solve failed before the step moved anything)
  }
}

// The simulator's bending on one hinge against ArcSim's formula evaluated by hand: the stiffness
// read from a table that varies along both axes, at the hinge's curvature |theta| l / (A0 + A1)
// and its edge's direction in material space (U, here rotated 30 degrees against the world's),
// then BendingForce with it. The assembled finite-difference tests use a constant bending, and
// Energy() repeats the simulator's expression, so a wrong scale (l dropped, 2A, the direction
// taken from V instead of U) passed every test.
TEST(ClothSimulatorTest, BendingReadsTheTableAtTheHingesCurvatureAndDirection) {
  Eigen::Matrix<double, 6, 4> stretching;
  stretching << 30, 5, 45, 30,  //
      80, 25, 260, 28, 70, 75, 180, 10, 110, 55, 175, 45, 145, 110, 140, 5, 145, 50, 190, 40;
  Eigen::Matrix<double, 3, 5> table;
  table << 1e-5, 2e-5, 4e-5, 8e-5, 16e-5,  //
      3e-5, 5e-5, 7e-5, 9e-5, 11e-5,        //
      20e-5, 15e-5, 10e-5, 5e-5, 2e-5;
  const Material material = MakeMaterial(0.284, stretching, table);
  // A 0.1 m square in material space, rotated 30 degrees, split along its diagonal 0-2 (the hinge).
  const double side = 0.1, turn = M_PI / 6;
  const Eigen::Matrix2d R = Eigen::Rotation2Dd(turn).toRotationMatrix();
  Mesh m;
  m.U.resize(4, 2);
  const Eigen::Vector2d corners[4] = {{0, 0}, {side, 0}, {side, side}, {0, side}};
  for (int i = 0; i < 4; ++i) m.U.row(i) = (R * corners[i]).transpose();
  m.F.resize(2, 3);
  m.F << 0, 1, 2, 0, 2, 3;
  // In the world: face (0, 1, 2) flat in z = 0 as in U; face (0, 2, 3) folded about the diagonal
  // by 1 rad (edge lengths kept: no stretching).
  m.V.resize(4, 3);
  for (int i = 0; i < 3; ++i) m.V.row(i) << m.U(i, 0), m.U(i, 1), 0;
  const Eigen::Vector3d a(m.U(0, 0), m.U(0, 1), 0), c(m.U(2, 0), m.U(2, 1), 0), d(m.U(3, 0), m.U(3, 1), 0);
  const Eigen::Vector3d axis = (c - a).normalized();
  m.V.row(3) = (a + Eigen::AngleAxisd(1.0, axis) * (d - a)).transpose();
  // The whole cloth turned in space (bending does not change): the edge's direction in the world
  // is not its direction in U.
  const Eigen::Matrix3d Q = Eigen::AngleAxisd(0.9, Eigen::Vector3d(0.3, 0.5, 0.8).normalized()).toRotationMatrix();
  for (int i = 0; i < 4; ++i) m.V.row(i) = (Q * m.V.row(i).transpose()).transpose();
  SimOptions o = QuietOptions();
  o.gravity.setZero();
  ClothSimulator sim(m, material, o, nullptr);
  const Eigen::MatrixX3d f = sim.Forces();

  Vector12d x;
  x << m.V.row(0).transpose(), m.V.row(2).transpose(), m.V.row(1).transpose(), m.V.row(3).transpose();
  const double theta = DihedralAngle(x);
  ASSERT_NEAR(std::abs(theta), 1.0, 1e-9);
  const double l = std::sqrt(2.0) * side, areas = side * side;
  const Eigen::Vector2d du = (m.U.row(2) - m.U.row(0)).transpose();
  const double ke = material.BendingStiffness(std::abs(theta) * l / areas, du);
  const Vector12d expected = BendingForce(x, ke, l, areas, 0.0).force;
  const int order[4] = {0, 2, 1, 3};
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d want = expected.segment<3>(3 * k), got = f.row(order[k]).transpose();
    EXPECT_LT((got - want).norm(), 1e-9 * expected.norm()) << "vertex " << order[k] << ": " << got.transpose()
                                                             << " against " << want.transpose();
  }
  // The table's variation matters here: another direction or curvature reads another stiffness.
  EXPECT_GT(std::abs(material.BendingStiffness(std::abs(theta) * l / areas, Eigen::Vector2d(1, 0)) - ke), 0.05 * ke);
  EXPECT_GT(std::abs(material.BendingStiffness(2 * std::abs(theta) * l / areas, du) - ke), 0.05 * ke);
}

// The simulator's stretching of one triangle against Wang et al.'s formula with the stiffness read
// by hand from a table that varies with the strain, at the triangle's Green strain (anisotropic,
// sheared). Every assembled finite-difference test uses constant tables, so a stiffness read at
// zero strain, or at another triangle's, passed them all.
TEST(ClothSimulatorTest, StretchingReadsTheTableAtTheTrianglesStrain) {
  Eigen::Matrix<double, 6, 4> stretching;
  stretching << 30, 5, 45, 30,  //
      80, 25, 260, 28, 70, 75, 180, 10, 110, 55, 175, 45, 145, 110, 140, 5, 145, 50, 190, 40;
  Eigen::Matrix<double, 3, 5> bending = Eigen::Matrix<double, 3, 5>::Constant(1e-5);
  const Material material = MakeMaterial(0.284, stretching, bending);
  Mesh m;
  m.U.resize(3, 2);
  m.U << 0, 0, 0.1, 0.01, 0.02, 0.08;
  m.F.resize(1, 3);
  m.F << 0, 1, 2;
  // Stretched 8 % along u, 3 % along v and sheared, then turned in space.
  Eigen::Matrix<double, 3, 2> A;
  A << 1.08, 0.05, 0.0, 1.03, 0.02, -0.01;
  const Eigen::Matrix3d Q = Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.2, -0.6, 0.77).normalized()).toRotationMatrix();
  m.V.resize(3, 3);
  for (int i = 0; i < 3; ++i) m.V.row(i) = (Q * (A * m.U.row(i).transpose())).transpose();
  SimOptions o = QuietOptions();
  o.gravity.setZero();
  ClothSimulator sim(m, material, o, nullptr);
  const Eigen::MatrixX3d f = sim.Forces();

  Vector9d x;
  x << m.V.row(0).transpose(), m.V.row(1).transpose(), m.V.row(2).transpose();
  const TriangleRest rest = MakeTriangleRest(m.U.row(0).transpose(), m.U.row(1).transpose(), m.U.row(2).transpose());
  const Eigen::Matrix2d G = GreenStrain(x, rest);
  const Eigen::Vector4d k = material.StretchingStiffness(G);
  const Vector9d expected = StretchingForce(x, rest, k, true).force;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d want = expected.segment<3>(3 * i), got = f.row(i).transpose();
    EXPECT_LT((got - want).norm(), 1e-9 * expected.norm()) << "vertex " << i << ": " << got.transpose()
                                                             << " against " << want.transpose();
  }
  // The table's variation matters here: at zero strain it reads another stiffness.
  EXPECT_GT((material.StretchingStiffness(Eigen::Matrix2d::Zero()) - k).norm(), 0.05 * k.norm());
}

TEST(ClothSimulatorTest, DeterministicAcrossInstancesAndThreads) {
  const Mesh m = HangingSheet(0.5, 0.4, 0.07);
  SimOptions o;
  o.handles = {2, 3};
  o.strain_min = 0.95;
  o.strain_max = 1.05;
  auto run = [&](Eigen::MatrixX3d* out) {
    ClothSimulator sim(m, TestMaterial(), o, std::make_shared<SteadyWind>(Eigen::Vector3d(6, 1, 0)));
    for (int i = 0; i < 150; ++i) sim.Step();
    *out = sim.positions();
  };
  Eigen::MatrixX3d a, b, c;
  run(&a);
  std::thread t1(run, &b), t2(run, &c);
  t1.join();
  t2.join();
  EXPECT_TRUE(a == b);
  EXPECT_TRUE(a == c);
}

TEST(ClothSimulatorTest, BadInputsFailClearly) {
  const Mesh good = HangingSheet(0.3, 0.3, 0.15);
  SimOptions o;
  o.handles = {0, 999};
  ExpectThrowContaining([&] { ClothSimulator(good, TestMaterial(), o, nullptr); },
                        "handles: vertex index 999 out of range");
  o.handles = {};
  Mesh nan = good;
  nan.V(1, 1) = std::nan("");
  ExpectThrowContaining([&] { ClothSimulator(nan, TestMaterial(), o, nullptr); }, "non-finite position");
  Mesh flat = good;
  flat.V.row(flat.F(0, 2)) = flat.V.row(flat.F(0, 0));
  ExpectThrowContaining([&] { ClothSimulator(flat, TestMaterial(), o, nullptr); }, "degenerate");
  SimOptions bad_dt;
  bad_dt.dt = 0;
  ExpectThrowContaining([&] { ClothSimulator(good, TestMaterial(), bad_dt, nullptr); }, "dt must be");
  ExpectThrowContaining([&] { ClothSimulator(good, Material{}, SimOptions{}, nullptr); }, "material is not initialised");
  Mesh flipped = good;
  flipped.F.row(0) = Eigen::RowVector3i(good.F(0, 0), good.F(0, 2), good.F(0, 1));
  ExpectThrowContaining([&] { ClothSimulator(flipped, TestMaterial(), SimOptions{}, nullptr); }, "oriented inconsistently");
  // A tolerance the first residual (exactly 1) already meets: the cloth would never move.
  for (double tol : {1.0, 2.0, std::nan("")}) {
    SimOptions o_tol;
    o_tol.cg_tolerance = tol;
    ExpectThrowContaining([&] { ClothSimulator(good, TestMaterial(), o_tol, nullptr); }, "cg_tolerance must be in (0, 1)");
  }
  SimOptions o_inf;
  o_inf.collision_stiffness = std::numeric_limits<double>::infinity();
  ExpectThrowContaining([&] { ClothSimulator(good, TestMaterial(), o_inf, nullptr); }, "collision_stiffness must be finite");
  o_inf = SimOptions{};
  o_inf.wind_density = std::numeric_limits<double>::infinity();
  ExpectThrowContaining([&] { ClothSimulator(good, TestMaterial(), o_inf, nullptr); }, "wind_density and wind_drag must be finite");
  SimOptions o_sweeps;
  o_sweeps.strain_max = 1.1;
  o_sweeps.strain_limit_iterations = 0;  // the limit would be silently off
  ExpectThrowContaining([&] { ClothSimulator(good, TestMaterial(), o_sweeps, nullptr); }, "strain_limit_iterations must be >= 1");
  // The global method with the sweeps' 4 iterations (it went unstable with 5-10).
  o_sweeps.strain_limit_iterations = 4;
  o_sweeps.strain_limit_method = StrainLimitMethod::kGlobal;
  ExpectThrowContaining([&] { ClothSimulator(good, TestMaterial(), o_sweeps, nullptr); },
                        "strain_limit_iterations must be >= 20 with the global strain-limit method");
  ClothSimulator sim(good, TestMaterial(), SimOptions{}, nullptr);
  ExpectThrowContaining([&] { sim.SetState(Eigen::MatrixX3d::Zero(2, 3), Eigen::MatrixX3d::Zero(2, 3)); }, "SetState");
}

}  // namespace
}  // namespace clothwind::sim
