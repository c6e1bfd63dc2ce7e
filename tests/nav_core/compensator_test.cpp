// The two misalignment compensators of paper §5 (eqs. (22)-(30)) on a noise-free misaligned
// array: both are exact at rest; under rotation only the exact one stays exact, and the paper's
// residual is exactly the one derived in docs/compensator.md.
//
// The oracle is independent of the code under test: the sensor outputs come from the forward
// physics of each sensor, written here from the paper (Table 1, eqs. (14)/(15), (19), (20)):
//   s_j = θ*_j · (f + ω̇ × ρ*_j + ω × (ω × ρ*_j)),   f = a − g at o_b,
// with θ*_j and ρ*_j = ρ_j + Δρ_j built here too — not with ArraySolver::predict or
// misaligned_geometry, which the exact compensator itself inverts.
#include "gfins/nav_core/compensator.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "gfins/nav_core/geometry.hpp"
#include "gfins/nav_core/misalignment.hpp"

namespace gfins::nav {
namespace {

using Vec3d = Vec3<double>;
using Vec6d = Vec6<double>;

constexpr double kRho = 0.1;  // cube half-size, m
constexpr double kDegToRad = 3.14159265358979323846 / 180.0;
constexpr double kLocationError = 1e-3;  // |Δρ_j|, m (1 mm, random directions)

// The bound on the algebraic residual of a correct compensator, rad/s² and m/s². Double
// rounding of outputs of about 10 m/s² through M (row 1-norm ≤ 14 /m) is about 1e-14, so any
// residual near this bound is a model error, not rounding.
constexpr double kExactBound = 1e-5;
// Float: outputs up to about 14 m/s² are rounded to 1e-6 m/s² (half an ulp), M s adds six
// products; through the ω̇ rows (1-norm 4/√2/(2ρ) = 14 /m) that is about 2e-5 rad/s². 1e-4 is
// 5× that; the paper form's spin residual (≥ 1e-2) stays far above it.
constexpr double kFloatBound = 1e-4;
// Below this the uncompensated array would look compensated: Table 6 angles of up to 2.7° on
// outputs of about 10 m/s² give errors of order 0.1 m/s² (docs/simulation.md §6.3: ≈0.35 m/s²).
constexpr double kUncompensatedAtLeast = 1e-2;

Misalignment<double> table6_misalignment() {
  // Table 6 as printed (degrees), order xy, xz, yx, yz, zx, zy.
  const std::array<double, 6> beta = {1.117319,  -0.175730, -0.581196,
                                      -0.738742, 2.454457,  2.482135};
  const std::array<double, 6> alpha = {-2.654967, 2.596778, -0.838703,
                                       -0.737387, 0.119537, -1.451107};
  Misalignment<double> m;
  for (std::size_t i = 0; i < 6; ++i) {
    m.orientation.beta[i] = beta[i] * kDegToRad;
    m.orientation.alpha[i] = alpha[i] * kDegToRad;
  }
  std::mt19937_64 rng(2007);  // fixed seed: the directions are random but reproducible
  std::normal_distribution<double> n(0.0, 1.0);
  for (auto& d : m.drho_b) d = kLocationError * Vec3d(n(rng), n(rng), n(rng)).normalized();
  return m;
}

// Paper Table 1, written here: positions (units of ρ) and unit sensitive axes.
const std::array<Vec3d, 6> kTable1Position = {Vec3d(0, 0, -1), Vec3d(0, -1, 0), Vec3d(-1, 0, 0),
                                              Vec3d(1, 0, 0),  Vec3d(0, 1, 0),  Vec3d(0, 0, 1)};
const std::array<Vec3d, 6> kTable1Axis = {
    Vec3d(1, 1, 0) / std::sqrt(2.0),  Vec3d(1, 0, 1) / std::sqrt(2.0),
    Vec3d(0, 1, 1) / std::sqrt(2.0),  Vec3d(0, -1, 1) / std::sqrt(2.0),
    Vec3d(-1, 0, 1) / std::sqrt(2.0), Vec3d(-1, 1, 0) / std::sqrt(2.0)};

// θ*_j of eqs. (14)/(15) written out: a set (x, y, z members, 0-based sensors) with its angles
// xy, xz, yx, yz, zx, zy senses along
//   θ*_x = θ_x + Δxz θ_y − Δxy θ_z,  θ*_y = −Δyz θ_x + θ_y + Δyx θ_z,  θ*_z = Δzy θ_x − Δzx θ_y +
//   θ_z.
void tilt_set(const std::array<int, 3>& member, const std::array<double, 6>& d,
              std::array<Vec3d, 6>& axis) {
  const Vec3d tx = kTable1Axis[static_cast<std::size_t>(member[0])];
  const Vec3d ty = kTable1Axis[static_cast<std::size_t>(member[1])];
  const Vec3d tz = kTable1Axis[static_cast<std::size_t>(member[2])];
  const double xy = d[0], xz = d[1], yx = d[2], yz = d[3], zx = d[4], zy = d[5];
  axis[static_cast<std::size_t>(member[0])] = tx + xz * ty - xy * tz;
  axis[static_cast<std::size_t>(member[1])] = -yz * tx + ty + yx * tz;
  axis[static_cast<std::size_t>(member[2])] = zy * tx - zx * ty + tz;
}

// The real array: θ*_j (set β = sensors 2, 3, 5; set α = 1, 4, 6) and ρ*_j = ρ_j + Δρ_j.
struct RealArray {
  std::array<Vec3d, 6> axis;
  std::array<Vec3d, 6> position;
};

RealArray real_array(const Misalignment<double>& m) {
  RealArray r;
  tilt_set({1, 2, 4}, m.orientation.beta, r.axis);
  tilt_set({0, 3, 5}, m.orientation.alpha, r.axis);
  for (std::size_t j = 0; j < 6; ++j) r.position[j] = kRho * kTable1Position[j] + m.drho_b[j];
  return r;
}

struct Motion {
  Vec3d w_b;     // rad/s
  Vec3d wdot_b;  // rad/s²
  Vec3d f_b;     // m/s², at o_b
};

// At rest, tilted: specific force of gravity plus a small linear acceleration.
const Motion kStatic{Vec3d::Zero(), Vec3d::Zero(), Vec3d(0.8, -1.1, -9.6)};
// Spin of 5 rad/s with 10 rad/s² angular acceleration, axes deliberately not aligned.
const Motion kSpin{5.0 * Vec3d(1, 2, 2).normalized(), 10.0 * Vec3d(-2, 1, 2).normalized(),
                   Vec3d(0.8, -1.1, -9.6)};

struct Residual {
  double wdot = 0.0;  // max |ω̇ error|, rad/s²
  double f = 0.0;     // max |f error|, m/s²
  double max() const { return std::max(wdot, f); }
};

template <typename T>
Residual residual(const Vec3<T>& wdot, const Vec3<T>& f, const Motion& m) {
  return {(wdot.template cast<double>() - m.wdot_b).cwiseAbs().maxCoeff(),
          (f.template cast<double>() - m.f_b).cwiseAbs().maxCoeff()};
}

struct AllThree {
  Residual none, paper, exact;
};

// Eqs. (19)/(20) per sensor, rigid body: s_j = θ*_j·(f + ω̇×ρ*_j + ω×(ω×ρ*_j)).
Vec6d forward_outputs(const RealArray& real, const Motion& m) {
  Vec6d s;
  for (std::size_t j = 0; j < 6; ++j) {
    const Vec3d& p = real.position[j];
    s(static_cast<int>(j)) =
        real.axis[j].dot(m.f_b + m.wdot_b.cross(p) + m.w_b.cross(m.w_b.cross(p)));
  }
  return s;
}

// Outputs s** of the misaligned array (forward physics above, in double), then each
// compensator in scalar type T. The paper compensator gets the TRUE ω and
// ω̇: in the firmware it uses the previous step's estimates, but here the algebraic residual of
// eqs. (27)-(30) is isolated from any estimation lag.
template <typename T>
AllThree run_compensators(const Motion& m) {
  const Misalignment<double> mis = table6_misalignment();
  const ArrayGeometry<double, 6> nominal = table1_geometry(kRho);
  const Vec6<T> s_raw = forward_outputs(real_array(mis), m).template cast<T>();

  const ArrayGeometry<T, 6> nominal_t = nominal.cast<T>();
  Misalignment<T> mis_t;
  for (std::size_t i = 0; i < 6; ++i) {
    mis_t.orientation.beta[i] = static_cast<T>(mis.orientation.beta[i]);
    mis_t.orientation.alpha[i] = static_cast<T>(mis.orientation.alpha[i]);
    mis_t.drho_b[i] = mis.drho_b[i].cast<T>();
  }
  const Vec3<T> w = m.w_b.cast<T>();
  const Vec3<T> wdot = m.wdot_b.cast<T>();

  AllThree out;
  Vec3<T> wdot_est;
  Vec3<T> f_est;
  const auto nominal_solver = ArraySolver<T>::create(nominal_t);
  EXPECT_TRUE(nominal_solver.is_ok());
  nominal_solver->solve(s_raw, w, wdot_est, f_est);  // no compensation
  out.none = residual(wdot_est, f_est, m);

  const auto paper = Compensator<T>::create(CompensatorKind::kPaper, nominal_t, mis_t);
  EXPECT_TRUE(paper.is_ok()) << paper.status().message();
  Vec6<T> s;
  paper->apply(s_raw, w, wdot, s);  // eqs. (27)/(28) then (29)/(30)
  const auto paper_solver = ArraySolver<T>::create(
      Compensator<T>::solver_geometry(CompensatorKind::kPaper, nominal_t, mis_t));
  EXPECT_TRUE(paper_solver.is_ok());
  paper_solver->solve(s, w, wdot_est, f_est);
  out.paper = residual(wdot_est, f_est, m);

  const auto exact = Compensator<T>::create(CompensatorKind::kExact, nominal_t, mis_t);
  EXPECT_TRUE(exact.is_ok());
  exact->apply(s_raw, w, wdot, s);  // passes through
  const auto exact_solver = ArraySolver<T>::create(
      Compensator<T>::solver_geometry(CompensatorKind::kExact, nominal_t, mis_t));
  EXPECT_TRUE(exact_solver.is_ok()) << exact_solver.status().message();
  exact_solver->solve(s, w, wdot_est, f_est);
  out.exact = residual(wdot_est, f_est, m);
  return out;
}

void report(const char* name, const AllThree& r) {
  // paper/exact compares with rounding noise when the exact residual is at rounding level;
  // paper/none says how much of the uncompensated error the paper's form removes.
  const double ratio = r.paper.max() / r.exact.max();
  const double ratio_none = r.paper.max() / r.none.max();
  std::printf(
      "%s: none wdot %.3e f %.3e | paper wdot %.3e f %.3e | exact wdot %.3e f %.3e | "
      "paper/exact %.3e paper/none %.3f\n",
      name, r.none.wdot, r.none.f, r.paper.wdot, r.paper.f, r.exact.wdot, r.exact.f, ratio,
      ratio_none);
  const std::string p(name);
  ::testing::Test::RecordProperty(p + "_none", std::to_string(r.none.max()));
  ::testing::Test::RecordProperty(p + "_paper", std::to_string(r.paper.max()));
  ::testing::Test::RecordProperty(p + "_exact", std::to_string(r.exact.max()));
  ::testing::Test::RecordProperty(p + "_paper_over_exact", std::to_string(ratio));
  ::testing::Test::RecordProperty(p + "_paper_over_none", std::to_string(ratio_none));
}

TEST(CompensatorTest, BothCompensatorsAreExactAtRest) {
  // Given a misaligned array at rest (Table 6 angles, 1 mm location errors), noise-free,
  const AllThree r = run_compensators<double>(kStatic);
  report("static", r);
  // then without compensation the error is large, and both compensators remove it.
  EXPECT_GT(r.none.max(), kUncompensatedAtLeast);
  EXPECT_LT(r.paper.wdot, kExactBound);
  EXPECT_LT(r.paper.f, kExactBound);
  EXPECT_LT(r.exact.wdot, kExactBound);
  EXPECT_LT(r.exact.f, kExactBound);
}

TEST(CompensatorTest, UnderRotationOnlyTheExactCompensatorStaysExact) {
  // Given the same array spinning at 5 rad/s with 10 rad/s² angular acceleration,
  const AllThree r = run_compensators<double>(kSpin);
  report("spin", r);
  // then the exact compensator is still at rounding level, the paper's form is not.
  EXPECT_GT(r.none.max(), kUncompensatedAtLeast);
  EXPECT_LT(r.exact.wdot, kExactBound);
  EXPECT_LT(r.exact.f, kExactBound);
  EXPECT_GT(r.paper.max(), 100.0 * kExactBound);
}

TEST(CompensatorTest, PaperResidualIsTheDerivedCrossSensorTerm) {
  // Given the spin case, the paper compensator's output error is predicted exactly by
  //   e = C⁻¹ r,  r_i = Σ_{k≠i} C_ik θ_k·R(ρ*_i − ρ*_k),  R(x) = ω̇×x + ω×(ω×x)
  // per set (docs/compensator.md), and the state error is M e.
  const Misalignment<double> mis = table6_misalignment();
  const ArrayGeometry<double, 6> nominal = table1_geometry(kRho);
  const RealArray real = real_array(mis);
  const auto rigid = [&](const Vec3d& x) -> Vec3d {
    return kSpin.wdot_b.cross(x) + kSpin.w_b.cross(kSpin.w_b.cross(x));
  };
  Vec6d e = Vec6d::Zero();
  const auto set_error = [&](const std::array<int, 3>& set, const std::array<double, 6>& angles) {
    const Mat3<double> c = set_matrix(angles);
    Vec3d r = Vec3d::Zero();
    for (int i = 0; i < 3; ++i) {
      const auto ji = static_cast<std::size_t>(set[static_cast<std::size_t>(i)]);
      for (int k = 0; k < 3; ++k) {
        if (k == i) continue;
        const auto jk = static_cast<std::size_t>(set[static_cast<std::size_t>(k)]);
        r(i) += c(i, k) * kTable1Axis[jk].dot(rigid(real.position[ji] - real.position[jk]));
      }
    }
    const Vec3d ei = c.inverse() * r;
    for (int i = 0; i < 3; ++i) e(set[static_cast<std::size_t>(i)]) = ei(i);
  };
  set_error(kSetBeta, mis.orientation.beta);
  set_error(kSetAlpha, mis.orientation.alpha);
  const auto solver = ArraySolver<double>::create(nominal);
  ASSERT_TRUE(solver.is_ok());
  const Vec6d predicted = solver->m() * e;  // [ω̇ error; f error]

  const auto paper = Compensator<double>::create(CompensatorKind::kPaper, nominal, mis);
  ASSERT_TRUE(paper.is_ok());
  Vec6d s;
  paper->apply(forward_outputs(real, kSpin), kSpin.w_b, kSpin.wdot_b, s);
  Vec3d wdot_est;
  Vec3d f_est;
  solver->solve(s, kSpin.w_b, wdot_est, f_est);
  Vec6d measured;
  measured << wdot_est - kSpin.wdot_b, f_est - kSpin.f_b;
  constexpr double kRoundingTol = 1e-12;  // both sides computed in double from the same inputs
  EXPECT_LT((measured - predicted).cwiseAbs().maxCoeff(), kRoundingTol)
      << "measured " << measured.transpose() << "\npredicted " << predicted.transpose();
  EXPECT_GT(predicted.cwiseAbs().maxCoeff(), 100.0 * kExactBound);  // the term is not trivial
}

TEST(CompensatorTest, FloatInstantiationKeepsTheSameOrdering) {
  // Given the float instantiation (the target's), at rest and under spin,
  const AllThree rest = run_compensators<float>(kStatic);
  const AllThree spin = run_compensators<float>(kSpin);
  report("float_static", rest);
  report("float_spin", spin);
  // then both compensators are at float rounding level at rest, the exact one also under spin,
  // and the paper form's spin residual is still far above float rounding.
  EXPECT_LT(rest.paper.max(), kFloatBound);
  EXPECT_LT(rest.exact.max(), kFloatBound);
  EXPECT_LT(spin.exact.max(), kFloatBound);
  EXPECT_GT(spin.paper.max(), 100.0 * kFloatBound);
}

}  // namespace
}  // namespace gfins::nav
