#include "gfins/nav_core/geometry.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

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

TEST(ArraySolverTest, RefusesSingularAndIllConditionedGeometries) {
  // All axes in the x-y plane: nothing senses specific force along z. Singular.
  auto flat = table1_geometry(0.1);
  for (auto& th : flat.theta_b) th = Vec3<double>(th.x(), th.y(), 0.0).normalized();
  flat.theta_b[1] = Vec3<double>(1, 0, 0);
  flat.theta_b[2] = Vec3<double>(0, 1, 0);
  flat.theta_b[3] = Vec3<double>(0, -1, 0);
  flat.theta_b[4] = Vec3<double>(-1, 0, 0);
  const auto r1 = ArraySolver<double>::create(flat);
  EXPECT_EQ(r1.status().code(), ErrorCode::kSingular);
  EXPECT_NE(std::string(r1.status().message()).find("ill-conditioned"), std::string::npos);

  // Sensor 6 moved 1 cm from sensor 1 and tilted 1.1 degrees from its axis: invertible in exact
  // arithmetic, but the condition number (2834, computed independently with numpy) is far above
  // the limit.
  auto near = table1_geometry(0.1);
  near.rho_b[5] = near.rho_b[0] + Vec3<double>(0.01, 0.0, 0.0);
  near.theta_b[5] = (near.theta_b[0] + Vec3<double>(0.0, 0.0, 0.02)).normalized();
  const auto r2 = ArraySolver<double>::create(near);
  EXPECT_EQ(r2.status().code(), ErrorCode::kSingular);
  // The same geometry passes if the caller explicitly accepts a huge condition number: the
  // refusal above is the conditioning check, not an inversion failure.
  const auto r3 = ArraySolver<double>::create(near, 1e12);
  ASSERT_TRUE(r3.is_ok()) << r3.status().message();
  EXPECT_NEAR(r3->condition_number(), 2834.24, 0.01);

  // Axes that are not unit vectors (beyond the 10 % a calibrated axis may carry) and sensors
  // without lever arm are refused as invalid arguments.
  auto scaled = table1_geometry(0.1);
  scaled.theta_b[2] *= 1.5;
  EXPECT_EQ(ArraySolver<double>::create(scaled).status().code(), ErrorCode::kInvalidArgument);
  auto point = table1_geometry(0.1);
  for (auto& r : point.rho_b) r.setZero();
  const auto r4 = ArraySolver<double>::create(point);
  EXPECT_EQ(r4.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(std::string(r4.status().message()).find("no lever arm"), std::string::npos);
  // A NaN position is named as such, not as "no lever arm" (the NaN mean it made).
  auto nan_rho = table1_geometry(0.1);
  nan_rho.rho_b[3].y() = std::nan("");
  const auto r5 = ArraySolver<double>::create(nan_rho);
  EXPECT_EQ(r5.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(std::string(r5.status().message()).find("position is not a finite number"),
            std::string::npos)
      << r5.status().message();
}

}  // namespace
}  // namespace gfins::nav
