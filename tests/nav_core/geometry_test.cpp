#include "gfins/nav_core/geometry.hpp"

#include <gtest/gtest.h>

namespace gfins::nav {
namespace {

// Table 1 must reproduce the paper's S/(2ρ) and T/2 of eq. (4) exactly (to double rounding).
constexpr double kExact = 1e-14;

TEST(ArraySolverTest, Table1MatchesPaperSAndT) {
  const double rho = 0.35;
  const auto solver = ArraySolver<double>::create(table1_geometry(rho));
  ASSERT_TRUE(solver.is_ok()) << solver.status().message();
  const double k = 1.0 / std::sqrt(2.0);
  Eigen::Matrix<double, 3, 6> s_paper;
  s_paper << 1, -1, 0, 0, 1, -1,  //
      -1, 0, 1, -1, 0, -1,        //
      0, 1, -1, -1, 1, 0;
  Eigen::Matrix<double, 3, 6> t_paper;
  t_paper << 1, 1, 0, 0, -1, -1,  //
      1, 0, 1, -1, 0, 1,          //
      0, 1, 1, 1, 1, 0;
  s_paper *= k;
  t_paper *= k;
  EXPECT_LT((solver->m().topRows<3>() - s_paper / (2 * rho)).cwiseAbs().maxCoeff(), kExact);
  EXPECT_LT((solver->m().bottomRows<3>() - t_paper / 2).cwiseAbs().maxCoeff(), kExact);
  EXPECT_NEAR(solver->condition_number(), 1.0, 1e-12);
  // Centripetal term: −K m(ω) = [0; ρ(ωyωz, ωxωz, ωxωy)].
  const Vec3<double> w(0.3, -1.7, 2.2);
  const Vec6<double> c = -solver->centripetal_part(w);
  EXPECT_LT(c.head<3>().norm(), kExact);
  EXPECT_NEAR(c(3), rho * w.y() * w.z(), kExact);
  EXPECT_NEAR(c(4), rho * w.x() * w.z(), kExact);
  EXPECT_NEAR(c(5), rho * w.x() * w.y(), kExact);
}

}  // namespace
}  // namespace gfins::nav
