// Accuracy of the solver set-up in single precision (ArraySolver<float>::create: a one-sided
// Jacobi SVD in float, so that the Cortex-M4F image holds no double arithmetic) against a double
// reference built here: H and Q of the array equations written out from the geometry (row j of
// H = [(ρ_j×θ_j)ᵀ/ρ̄  θ_jᵀ], geometry.hpp / paper eq. (22)) and Eigen's double JacobiSVD for the
// pseudo-inverse and the condition number (a third-party implementation).
//
// Bound. With u = 2⁻²⁴ (float unit roundoff, ε/2) and κ the condition number of the
// column-scaled H, the float set-up is the exact SVD of H + δH with ‖δH‖_F ≤ c·u·‖H‖_F:
// rounding H's entries (3 operations each) and one-sided Jacobi's rotations (backward stable,
// about 6u per rotation applied to a column; 5 rotations per column and sweep, at most 6 sweeps
// for a 6×6 matrix) give c = 3 + 6·5·6 = 183. First-order perturbation of the (pseudo-)inverse
// then gives ‖δM‖_F/‖M‖_F ≤ κ·c·u (Higham, Accuracy and Stability of Numerical Algorithms, §14.1
// and §25), and the same for K = M Q and for κ itself. A plausible bug (a wrong rotation sign, a
// missed sweep, the lever arm applied to the wrong rows) gives errors of order one. The reference
// is computed from the float geometry cast to double, so only the set-up's arithmetic counts.
#include <gtest/gtest.h>

#include <Eigen/SVD>
#include <cmath>
#include <limits>
#include <random>

#include "gfins/nav_core/geometry.hpp"
#include "gfins/nav_core/geometry_impl.hpp"  // the 8-sensor instantiation
#include "gfins/nav_core/misalignment.hpp"
#include "gfins/nav_core/paper_table6.hpp"

namespace gfins::nav {
namespace {

// c of the bound above: 3 roundings of each entry of H + 6 sweeps × 5 rotations × 6u.
constexpr double kBackwardFactor = 3.0 + 6.0 * 5.0 * 6.0;
template <typename T>
constexpr double kUnitRoundoff = static_cast<double>(std::numeric_limits<T>::epsilon()) / 2.0;

template <int N>
struct Reference {
  Eigen::Matrix<double, 6, N> m;
  Eigen::Matrix<double, 6, 6> k;
  double cond = 0.0;
};

// M = pinv(H) and K = M Q in double, from the geometry alone.
// GCC 12 for armhf (-O3) reports the singular values read below as maybe uninitialised: a false
// positive from inside Eigen's JacobiSVD::compute, which writes every one of them (no other
// target's build warns). Silenced for this function only, and for GCC only (Clang has no such
// warning and would report the unknown option).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
template <int N>
Reference<N> reference(const ArrayGeometry<double, N>& g) {
  double lever = 0.0;
  for (const auto& r : g.rho_b) lever += r.norm();
  lever /= N;
  Eigen::Matrix<double, N, 6> h_scaled;
  Eigen::Matrix<double, N, 6> q;
  for (int j = 0; j < N; ++j) {
    const Eigen::Vector3d rho = g.rho_b[static_cast<std::size_t>(j)];
    const Eigen::Vector3d th = g.theta_b[static_cast<std::size_t>(j)];
    h_scaled.row(j) << rho.cross(th).transpose() / lever, th.transpose();
    // c_j(ω) = (θ·ω)(ρ·ω) − (θ·ρ)|ω|² as coefficients of [ωx², ωy², ωz², ωyωz, ωxωz, ωxωy].
    const double tr = th.dot(rho);
    q.row(j) << th.x() * rho.x() - tr, th.y() * rho.y() - tr, th.z() * rho.z() - tr,
        th.y() * rho.z() + th.z() * rho.y(), th.x() * rho.z() + th.z() * rho.x(),
        th.x() * rho.y() + th.y() * rho.x();
  }
  const Eigen::JacobiSVD<Eigen::Matrix<double, N, 6>> svd(
      h_scaled, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const auto& sv = svd.singularValues();
  Reference<N> r;
  r.cond = sv(0) / sv(5);
  r.m = svd.matrixV() * sv.cwiseInverse().asDiagonal() *
        svd.matrixU().template leftCols<6>().transpose();
  r.m.template topRows<3>() /= lever;
  r.k = r.m * q;
  return r;
}
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

struct Errors {
  double m = 0.0;     // ‖δM‖_F/‖M‖_F
  double k = 0.0;     // ‖δK‖_F/‖K‖_F
  double cond = 0.0;  // |δκ|/κ
  double kappa = 0.0;
};

template <typename T, int N>
Errors setup_errors(const ArrayGeometry<T, N>& g) {
  const auto solver = ArraySolver<T, N>::create(g);
  EXPECT_TRUE(solver.is_ok()) << solver.status().message();
  Errors e;
  if (!solver.is_ok()) return e;
  const Reference<N> ref = reference<N>(g.template cast<double>());
  e.kappa = ref.cond;
  e.m = (solver->m().template cast<double>() - ref.m).norm() / ref.m.norm();
  e.k = (solver->k().template cast<double>() - ref.k).norm() / ref.k.norm();
  e.cond = std::abs(solver->condition_number() - ref.cond) / ref.cond;
  return e;
}

template <typename T>
void expect_within_bound(const Errors& e) {
  const double bound = e.kappa * kBackwardFactor * kUnitRoundoff<T>;
  EXPECT_LE(e.m, bound) << "kappa " << e.kappa;
  EXPECT_LE(e.k, bound) << "kappa " << e.kappa;
  EXPECT_LE(e.cond, bound) << "kappa " << e.kappa;
}

template <typename T>
ArrayGeometry<T, 6> table6_exact_geometry() {
  Misalignment<T> m = paper_table6::misalignment<T>();
  for (std::size_t j = 0; j < 6; ++j) {
    const T sgn = (j % 2 == 0) ? T(1) : T(-1);
    m.drho_b[j] = Vec3<T>(T(0.001) * sgn, T(-0.0005), T(0.0008) * sgn);  // m, about 1 mm
  }
  return misaligned_geometry(table1_geometry(T(0.1)), m);
}

// Random arrays: positions within a 0.1 m ball, random unit axes; kept when the double
// reference's condition number is at most the solver's default limit, so the sample spans
// κ from a few to 100.
template <int N>
ArrayGeometry<double, N> random_geometry(std::mt19937_64& rng) {
  std::normal_distribution<double> n01(0.0, 1.0);
  for (;;) {
    ArrayGeometry<double, N> g;
    for (std::size_t j = 0; j < static_cast<std::size_t>(N); ++j) {
      g.rho_b[j] = 0.1 * Eigen::Vector3d(n01(rng), n01(rng), n01(rng)) / 2.0;
      g.theta_b[j] = Eigen::Vector3d(n01(rng), n01(rng), n01(rng)).normalized();
    }
    const auto gf = g.template cast<float>().template cast<double>();
    if (reference<N>(gf).cond <= kDefaultMaxCondition) return g;
  }
}

template <typename T>
class SolverSetupAccuracyTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(SolverSetupAccuracyTest, Scalars);

TYPED_TEST(SolverSetupAccuracyTest, Table1) {
  expect_within_bound<TypeParam>(setup_errors(table1_geometry(TypeParam(0.1))));
}

TYPED_TEST(SolverSetupAccuracyTest, Table6GeometryOfTheExactCompensator) {
  expect_within_bound<TypeParam>(setup_errors(table6_exact_geometry<TypeParam>()));
}

TYPED_TEST(SolverSetupAccuracyTest, RandomArraysUpToTheConditionLimit) {
  std::mt19937_64 rng(13);   // fixed seed: reproducible geometries
  double worst_ratio = 0.0;  // error / (κ u): how much of the bound is used
  double max_kappa = 0.0;
  for (int i = 0; i < 200; ++i) {
    const auto g6 = random_geometry<6>(rng).template cast<TypeParam>();
    const Errors e6 = setup_errors(g6);
    expect_within_bound<TypeParam>(e6);
    const auto g8 = random_geometry<8>(rng).template cast<TypeParam>();
    const Errors e8 = setup_errors(g8);
    expect_within_bound<TypeParam>(e8);
    for (const Errors& e : {e6, e8}) {
      max_kappa = std::max(max_kappa, e.kappa);
      worst_ratio =
          std::max(worst_ratio, std::max(e.m, e.k) / (e.kappa * kUnitRoundoff<TypeParam>));
    }
  }
  std::printf("[ stats    ] largest kappa %.1f, worst error %.1f kappa*u (bound %.0f)\n", max_kappa,
              worst_ratio, kBackwardFactor);
  // The sample must reach ill-conditioned arrays, or the check above proves little.
  EXPECT_GT(max_kappa, 30.0);
}

// The exact zeros the per-sample path relies on survive the float set-up: for Table 1 the ω̇
// rows of K vanish (ω̇ = S s/(2ρ), eq. (4)), so the integrator skips them, and M has the zero
// pattern of the paper's S and T.
TEST(SolverSetupStructureTest, Table1ZerosAreExactInFloat) {
  const auto solver = ArraySolver<float>::create(table1_geometry(0.1f));
  ASSERT_TRUE(solver.is_ok());
  EXPECT_TRUE((solver->k().topRows<3>().array() == 0.0f).all());
  const Eigen::Matrix<float, 6, 6> m = solver->m();
  int zeros = 0;
  for (int i = 0; i < 36; ++i) zeros += m.data()[i] == 0.0f ? 1 : 0;
  EXPECT_EQ(zeros, 12);  // S and T of eq. (4) have two zeros per row
}

}  // namespace
}  // namespace gfins::nav
