// The per-sample form of the paper's compensator (s = P s** − D [m(ω); ω̇]) must be the same
// function as the step-by-step eqs. (27)-(30): only the order of the floating-point operations
// differs.
#include <gtest/gtest.h>

#include <random>

#include "gfins/nav_core/compensator.hpp"

namespace gfins::nav {
namespace {

template <typename T>
T max_difference_over_random_inputs(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Misalignment<T> m;
  for (std::size_t i = 0; i < 6; ++i) {
    m.orientation.beta[i] = static_cast<T>(0.05 * u(rng));
    m.orientation.alpha[i] = static_cast<T>(0.05 * u(rng));
    m.drho_b[i] = Vec3<T>(T(0.003) * static_cast<T>(u(rng)), T(0.003) * static_cast<T>(u(rng)),
                          T(0.003) * static_cast<T>(u(rng)));
  }
  const auto comp = Compensator<T>::create(CompensatorKind::kPaper, table1_geometry(T(0.1)), m);
  EXPECT_TRUE(comp.is_ok());
  T worst = T(0);
  for (int trial = 0; trial < 200; ++trial) {
    Vec6<T> s_raw;
    for (int j = 0; j < 6; ++j) s_raw(j) = static_cast<T>(20.0 * u(rng));
    const Vec3<T> w(static_cast<T>(8 * u(rng)), static_cast<T>(8 * u(rng)),
                    static_cast<T>(8 * u(rng)));
    const Vec3<T> wdot(static_cast<T>(50 * u(rng)), static_cast<T>(50 * u(rng)),
                       static_cast<T>(50 * u(rng)));
    Vec6<T> fused;
    Vec6<T> reference;
    comp->apply(s_raw, w, wdot, fused);
    comp->apply_reference(s_raw, w, wdot, reference);
    worst = std::max(worst, (fused - reference).cwiseAbs().maxCoeff());
  }
  return worst;
}

// Outputs reach 20 m/s² and the location terms ~0.4 m/s²: a few units of rounding of that size.
TEST(CompensatorFusedTest, EqualsTheStepByStepFormDouble) {
  EXPECT_LT(max_difference_over_random_inputs<double>(7), 1e-13);
}
TEST(CompensatorFusedTest, EqualsTheStepByStepFormFloat) {
  EXPECT_LT(max_difference_over_random_inputs<float>(7), 2e-5f);
}

TEST(CompensatorFusedTest, DiffersWhenTheMisalignmentDiffers) {
  Misalignment<double> m;
  m.orientation.beta[0] = 0.02;
  const auto with = Compensator<double>::create(CompensatorKind::kPaper, table1_geometry(0.1), m);
  const auto without = Compensator<double>::create(CompensatorKind::kPaper, table1_geometry(0.1),
                                                   Misalignment<double>{});
  Vec6<double> s_raw;
  s_raw << 1, 2, 3, 4, 5, 6;
  Vec6<double> a;
  Vec6<double> b;
  with->apply(s_raw, Vec3<double>::Zero(), Vec3<double>::Zero(), a);
  without->apply(s_raw, Vec3<double>::Zero(), Vec3<double>::Zero(), b);
  EXPECT_GT((a - b).norm(), 1e-3);
  EXPECT_EQ(b, s_raw);  // no misalignment: identity
}

}  // namespace
}  // namespace gfins::nav
