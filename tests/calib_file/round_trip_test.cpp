// Save → load round trips of the calibration file are bit-exact, and the checksum is the one the
// doc defines.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <limits>
#include <random>

#include "calib_file/calib_test_data.hpp"
#include "gfins/calib_file/calibration_file.hpp"

namespace gfins::calib_file {
namespace {

using testing::read_text;
using testing::table6_data;
using testing::TempDir;

// Bit-exact comparison of every double: the canonical serialisation holds their bit patterns.
void expect_bit_identical(const CalibrationData& a, const CalibrationData& b) {
  EXPECT_EQ(canonical_serialisation(a), canonical_serialisation(b));
  EXPECT_TRUE(a == b);
}

TEST(RoundTrip, Table6DataSavedAndLoadedIsBitIdenticalAndResavesToTheSameBytes) {
  // Given the paper's Table 6 as calibration data
  const TempDir dir;
  const auto path = dir.path() / "cal.toml";
  const CalibrationData original = table6_data();
  // When it is saved, loaded and saved again
  ASSERT_TRUE(save_calibration_file(path, original).is_ok());
  const std::string first_text = read_text(path);
  const auto loaded = load_calibration_file(path);
  ASSERT_TRUE(loaded.is_ok()) << loaded.status().message();
  ASSERT_TRUE(save_calibration_file(path, loaded.value()).is_ok());
  // Then every value is bit-identical and the file bytes do not change
  expect_bit_identical(original, loaded.value());
  EXPECT_EQ(first_text, read_text(path));
}

TEST(RoundTrip, TheFileIsReadableTomlWithUnitsAndTable6Digits) {
  // Given Table 6 written as text
  const std::string text = to_toml_text(table6_data());
  // Then a reader sees the paper's digits (shortest round-trip formatting) and the units
  EXPECT_NE(text.find("scale_v_per_g = 0.332572\n"), std::string::npos) << text;
  EXPECT_NE(text.find("xy_deg = 1.117319\n"), std::string::npos);
  EXPECT_NE(text.find("angle = 'deg'"), std::string::npos);
  EXPECT_NE(text.find("scale_factor = 'V/g'"), std::string::npos);
  EXPECT_NE(text.find("format_version = 4\n"), std::string::npos);
  // Format version 3: each sensor's correlations, keyed by the Table 6 names of its two angles
  // (sensor 3 is row y of set β: Δβ_yx, Δβ_yz).
  EXPECT_NE(text.find("[sensor.3.correlation]\n    bias_yx = 0.0625\n"), std::string::npos) << text;
  EXPECT_NE(text.find("yx_yz = 0.1875\n"), std::string::npos);
  EXPECT_NE(text.find("[orientation]\ncorrelations = 'stated'\n"), std::string::npos);
  EXPECT_NE(text.find("[gravity]\nlocal_mps2 = 9.7894\n"), std::string::npos) << text;
  EXPECT_NE(text.find("compensator = 'exact'"), std::string::npos);
  EXPECT_TRUE(text.ends_with(std::string(kEndMarker) + "\n"));
}

// Random values spanning each key's whole domain, including awkward doubles (subnormal-free but
// with all 53 mantissa bits in use, negative zero, extremes of the ranges).
CalibrationData random_data(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const auto any = [&](double scale) { return scale * unit(rng); };
  const auto pos = [&](double scale) { return scale * (0.5 + 0.5 * std::fabs(unit(rng))); };
  CalibrationData d = table6_data();
  d.geometry.rho_m = pos(1.0);
  d.gravity_mps2 = 9.8 + any(0.1);  // the whole accepted range [9.7, 9.9]
  for (auto& s : d.sensors) {
    s.adc_lsb_v_per_count = pos(1e-6);
    s.scale_v_per_g = pos(5.0);
    s.scale_sigma_v_per_g = pos(1e-3);
    s.bias_g = any(0.01);
    s.bias_sigma_g = pos(1e-4);
    for (std::size_t k = 0; k < 3; ++k) {
      s.location_error_m[k] = any(0.4 * d.geometry.rho_m);
      s.location_error_sigma_m[k] = pos(1e-3);
    }
    // |ρ| ≤ 0.3: three off-diagonals per row sum below 1, a valid (diagonally dominant) matrix.
    for (double& r : s.correlation) r = any(0.3);
  }
  d.correlations_known = (rng() & 1u) != 0;
  // Every sigma source, residuals with any dof of the domain.
  for (auto& s : d.sensors) {
    const auto basis = static_cast<SigmaBasis>(rng() % 4u);
    s.sigma_source = SigmaSource{basis, basis == SigmaBasis::kResiduals
                                            ? static_cast<std::int32_t>(1 + rng() % kMaxSigmaDof)
                                            : 0};
  }
  for (std::size_t i = 0; i < 6; ++i) {
    d.beta.angle_deg[i] = any(kMaxAngleDeg);
    d.alpha.angle_deg[i] = any(kMaxAngleDeg);
    d.beta.angle_sigma_deg[i] = pos(0.1);
    d.alpha.angle_sigma_deg[i] = pos(0.1);
  }
  d.sensors[0].location_error_m[2] = -0.0;
  d.beta.angle_deg[0] = kMaxAngleDeg;
  d.alpha.angle_deg[5] = -kMaxAngleDeg;
  return d;
}

TEST(RoundTrip, RandomValuesOverTheirWholeDomainsReadBackBitExactly) {
  // Given 300 random calibrations (fixed seed: reproducible)
  std::mt19937_64 rng(20240501);
  constexpr int kCases = 300;
  for (int c = 0; c < kCases; ++c) {
    const CalibrationData d = random_data(rng);
    // When each is written as text and parsed back
    const auto back = parse_calibration_text(to_toml_text(d), "random.toml");
    // Then it is valid and every bit is preserved (negative zero included)
    ASSERT_TRUE(back.is_ok()) << back.status().message();
    ASSERT_EQ(canonical_serialisation(d), canonical_serialisation(back.value())) << "case " << c;
    ASSERT_TRUE(std::signbit(back.value().sensors[0].location_error_m[2]));
  }
}

TEST(RoundTrip, CustomGeometryRoundTripsAndItsAxesAreChecked) {
  // Given an array whose geometry is given explicitly (Table 1 axes, positions of ρ = 0.2 m)
  CalibrationData d = table6_data();
  d.geometry.kind = GeometryKind::kCustom;
  d.geometry.rho_m = 0.2;
  const auto t1 = nav::table1_geometry<double>(0.2);
  for (std::size_t j = 0; j < kNumSensors; ++j) {
    for (int k = 0; k < 3; ++k) {
      d.geometry.positions_m[j][static_cast<std::size_t>(k)] = t1.rho_b[j](k);
      d.geometry.axes[j][static_cast<std::size_t>(k)] = t1.theta_b[j](k);
    }
  }
  // When it is written and parsed back
  const std::string text = to_toml_text(d);
  const auto back = parse_calibration_text(text, "custom.toml");
  // Then it is the same, and the positions are stated in the file
  ASSERT_TRUE(back.is_ok()) << back.status().message();
  expect_bit_identical(d, back.value());
  EXPECT_NE(text.find("[geometry.sensor.3]"), std::string::npos) << text;
  // And an axis that is not a unit vector is refused, naming its key
  d.geometry.axes[2] = {1.0, 1.0, 0.0};
  const auto bad = parse_calibration_text(to_toml_text(d), "custom.toml");
  ASSERT_FALSE(bad.is_ok());
  EXPECT_NE(bad.status().message().find("geometry.sensor.3.axis"), std::string::npos)
      << bad.status().message();
}

TEST(Checksum, Fnv1a64MatchesTheReferenceVectors) {
  // Reference values of FNV-1a 64 (Fowler/Noll/Vo test suite): "" and "a" and "foobar".
  EXPECT_EQ(fnv1a64(""), 0xcbf29ce484222325ULL);
  EXPECT_EQ(fnv1a64("a"), 0xaf63dc4c8601ec8cULL);
  EXPECT_EQ(fnv1a64("foobar"), 0x85944171f73967e8ULL);
}

TEST(Checksum, CanonicalSerialisationIsKeyEqualsBitPatternLines) {
  // Given Table 6 data
  const CalibrationData d = table6_data();
  // When serialised canonically
  const std::string c = canonical_serialisation(d);
  // Then it starts with the version and identity, doubles are their 16-hex-digit bit patterns,
  // and the file's checksum is FNV-1a 64 of exactly this text
  EXPECT_TRUE(c.starts_with("format_version=4\ndevice_id=gfins-test-01\n")) << c;
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx",
                static_cast<unsigned long long>(std::bit_cast<std::uint64_t>(0.332572)));
  EXPECT_NE(c.find(std::string("sensor.2.scale_v_per_g=") + hex + "\n"), std::string::npos);
  EXPECT_TRUE(c.ends_with("compensator=exact\n"));
  char sum[40];
  std::snprintf(sum, sizeof sum, "fnv1a64:%016llx", static_cast<unsigned long long>(fnv1a64(c)));
  EXPECT_NE(to_toml_text(d).find(sum), std::string::npos);
}

}  // namespace
}  // namespace gfins::calib_file

namespace gfins::calib_file {
namespace {

TEST(CalibrationId, IsTheChecksumFoldedTo32BitsAndChangesWithAnyValue) {
  // docs/calibration.md, install: cal_id = h ^ (h >> 32) of the file's FNV-1a 64 checksum.
  const CalibrationData d = testing::table6_data();
  const std::uint64_t h = fnv1a64(canonical_serialisation(d));
  EXPECT_EQ(cal_id_of(d), static_cast<std::uint32_t>(h ^ (h >> 32)));
  CalibrationData e = d;
  e.sensors[4].bias_g = std::nextafter(e.sensors[4].bias_g, 1.0);  // one ulp
  EXPECT_NE(cal_id_of(e), cal_id_of(d));
}

}  // namespace
}  // namespace gfins::calib_file
