// Every way a calibration file can be bad is refused with a message that names the file, the
// problem and, where there is one, the key and line.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <limits>
#include <string>

#include "calib_file/calib_test_data.hpp"
#include "gfins/calib_file/calibration_file.hpp"

namespace gfins::calib_file {
namespace {

using ::testing::HasSubstr;
using testing::table6_data;
using testing::TempDir;
using testing::write_text;

// The 1-based line of the first occurrence of `needle` in `text`.
int line_of(const std::string& text, const std::string& needle) {
  const auto at = text.find(needle);
  EXPECT_NE(at, std::string::npos) << needle;
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'));
}

// The line of a dotted key in a file written by to_toml_text: "a.b.c" is "c = " after "[a.b]".
int key_line(const std::string& text, const std::string& key) {
  const auto dot = key.rfind('.');
  if (dot == std::string::npos) return line_of(text, "\n" + key + " = ") + 1;
  const std::string header = "[" + key.substr(0, dot) + "]\n";
  const auto table_at = text.find(header);
  EXPECT_NE(table_at, std::string::npos) << header;
  return line_of(text, header) + line_of(text.substr(table_at), key.substr(dot + 1) + " = ") - 1;
}

std::string replace_once(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

class LoadErrors : public ::testing::Test {
 protected:
  // Writes `text` as bad.toml and loads it; the load must fail.
  FileStatus load_text(const std::string& text) {
    write_text(path_, text);
    const auto r = load_calibration_file(path_);
    EXPECT_FALSE(r.is_ok());
    // Every message names the file.
    EXPECT_THAT(r.status().message(), HasSubstr("calibration file '" + path_.string() + "'"));
    return r.status();
  }

  const TempDir dir_;
  const std::filesystem::path path_ = dir_.path() / "bad.toml";
  const std::string good_ = to_toml_text(table6_data());
};

TEST_F(LoadErrors, MissingFileIsAnIoErrorNamingTheOsReason) {
  const auto r = load_calibration_file(dir_.path() / "absent.toml");
  ASSERT_FALSE(r.is_ok());
  EXPECT_EQ(r.status().code(), ErrorCode::kIoError);
  EXPECT_THAT(r.status().message(), HasSubstr("absent.toml"));
  EXPECT_THAT(r.status().message(), HasSubstr("No such file or directory"));
}

TEST_F(LoadErrors, FileCutInTheMiddleOfALineIsTruncated) {
  const FileStatus s = load_text(good_.substr(0, good_.size() / 2));
  EXPECT_EQ(s.code(), ErrorCode::kDataLoss);
  EXPECT_THAT(s.message(), HasSubstr("truncated"));
}

TEST_F(LoadErrors, FileCutAtALineBoundaryBeforeTheEndMarkerIsTruncated) {
  // Given the file without its last line: still valid TOML, so only the marker can tell
  const std::string cut = good_.substr(0, good_.find(std::string(kEndMarker)));
  const FileStatus s = load_text(cut);
  EXPECT_EQ(s.code(), ErrorCode::kDataLoss);
  EXPECT_THAT(s.message(), HasSubstr("truncated"));
}

TEST_F(LoadErrors, EmptyFileIsTruncated) {
  const FileStatus s = load_text("");
  EXPECT_EQ(s.code(), ErrorCode::kDataLoss);
  EXPECT_THAT(s.message(), HasSubstr("truncated"));
}

TEST_F(LoadErrors, AChangedDigitIsACorruptionCaughtByTheChecksum) {
  // Given Table 6 with one digit of SF_a2 changed (0.332572 → 0.332672): still valid, in range
  const FileStatus s =
      load_text(replace_once(good_, "scale_v_per_g = 0.332572", "scale_v_per_g = 0.332672"));
  EXPECT_EQ(s.code(), ErrorCode::kDataLoss);
  EXPECT_THAT(s.message(), HasSubstr("checksum mismatch"));
  EXPECT_THAT(s.message(),
              HasSubstr("line " + std::to_string(line_of(good_, "checksum = ")) + ":"));
}

TEST_F(LoadErrors, AnAlteredChecksumIsACorruption) {
  const auto at = good_.find("fnv1a64:") + 8;
  std::string text = good_;
  text[at] = text[at] == '0' ? '1' : '0';
  const FileStatus s = load_text(text);
  EXPECT_EQ(s.code(), ErrorCode::kDataLoss);
  EXPECT_THAT(s.message(), HasSubstr("checksum mismatch"));
}

TEST_F(LoadErrors, MissingChecksumIsRefused) {
  const FileStatus s = load_text(replace_once(good_, "checksum = ", "# checksum = "));
  EXPECT_EQ(s.code(), ErrorCode::kDataLoss);
  EXPECT_THAT(s.message(), HasSubstr("integrity.checksum"));
}

TEST_F(LoadErrors, BrokenSyntaxNamesTheLineAndColumn) {
  // Given a key whose '=' has been lost
  const int line = line_of(good_, "bias_g = ");
  const FileStatus s = load_text(replace_once(good_, "bias_g = ", "bias_g "));
  EXPECT_EQ(s.code(), ErrorCode::kDataLoss);
  EXPECT_THAT(s.message(), HasSubstr("TOML syntax error"));
  EXPECT_THAT(s.message(), HasSubstr("line " + std::to_string(line) + ", column "));
}

TEST_F(LoadErrors, AnotherFormatVersionIsRefusedNamingBothVersions) {
  const int line = line_of(good_, "format_version = 4");
  const FileStatus s = load_text(replace_once(good_, "format_version = 4", "format_version = 5"));
  EXPECT_EQ(s.code(), ErrorCode::kUnimplemented);
  EXPECT_THAT(s.message(), HasSubstr("line " + std::to_string(line) +
                                     ": format version 5 is "
                                     "not supported (this build reads versions 1 to 4)"));
}

// Removes every line of `text` that starts with `prefix` (canonical text: one key per line).
std::string drop_lines(std::string text, const std::string& prefix) {
  std::string out;
  std::size_t at = 0;
  while (at < text.size()) {
    const auto end = text.find('\n', at);
    const std::string line = text.substr(at, end - at + 1);
    if (line.rfind(prefix, 0) != 0) out += line;
    at = end + 1;
  }
  return out;
}

// Removes the TOML table whose header line contains `header` (up to the next blank line).
std::string drop_table(std::string text, const std::string& header) {
  const auto h = text.find(header);
  EXPECT_NE(h, std::string::npos) << header;
  const auto line_start = text.rfind('\n', h) + 1;
  const auto end = text.find("\n\n", h);
  return text.erase(line_start, end + 2 - line_start);
}

// A file as an older build wrote it (written here from docs/calibration-file.md, versioning):
// version 3 without sensor.N.sigma_source, version 2 also without the sensor.N.correlation
// tables and orientation.correlations, version 1 also without [gravity]; the checksum over that
// version's key list.
std::string older_version_text(const CalibrationData& d, int version) {
  std::string text = to_toml_text(d);
  std::string canon = canonical_serialisation(d);
  text = drop_lines(text, "sigma_source = ");
  for (int j = 1; j <= 6; ++j)
    canon = drop_lines(canon, "sensor." + std::to_string(j) + ".sigma_source=");
  if (version < 3) {
    for (int j = 1; j <= 6; ++j) {
      text = drop_table(text, "[sensor." + std::to_string(j) + ".correlation]\n");
      canon = drop_lines(canon, "sensor." + std::to_string(j) + ".correlation.");
    }
    text = replace_once(text, "[orientation]\ncorrelations = 'stated'\n\n", "");
    canon = drop_lines(canon, "orientation.correlations=");
  }
  if (version < 2) {
    text = drop_table(text, "[gravity]\n");
    canon = drop_lines(canon, "gravity.");
  }
  const std::string v = std::to_string(version);
  text = replace_once(text, "format_version = 4", "format_version = " + v);
  canon = replace_once(canon, "format_version=4\n", "format_version=" + v + "\n");
  char old_sum[40];
  char new_sum[40];
  std::snprintf(old_sum, sizeof old_sum, "fnv1a64:%016llx",
                static_cast<unsigned long long>(checksum(d)));
  std::snprintf(new_sum, sizeof new_sum, "fnv1a64:%016llx",
                static_cast<unsigned long long>(fnv1a64(canon)));
  return replace_once(text, old_sum, new_sum);
}
std::string version1_text(const CalibrationData& d) { return older_version_text(d, 1); }

TEST(FormatVersion2, LoadsWithoutCorrelationsAndSaysSo) {
  // Given a version-2 file (σ of SF, b and the angles, but not their correlations)
  const CalibrationData d = table6_data();
  const auto r = parse_calibration_text(older_version_text(d, 2), "v2.toml");
  // Then every value reads back, the correlations are 0 and marked as not known
  ASSERT_TRUE(r.is_ok()) << r.status().message();
  CalibrationData expected = d;
  for (auto& s : expected.sensors) {
    s.correlation = {};
    s.sigma_source = SigmaSource{SigmaBasis::kUnknown, 0};
  }
  expected.correlations_known = false;
  EXPECT_EQ(r.value(), expected);
  // And re-saved as version 4 the file says that they are not known
  const std::string text = to_toml_text(r.value());
  EXPECT_NE(text.find("correlations = 'unknown: taken as 0'"), std::string::npos) << text;
  const auto again = parse_calibration_text(text, "v4.toml");
  ASSERT_TRUE(again.is_ok()) << again.status().message();
  EXPECT_EQ(again.value(), expected);
}

TEST(FormatVersion3, LoadsWithoutSigmaSourcesAndSaysSo) {
  // Given a version-3 file (correlations, but not where the σ came from)
  const CalibrationData d = table6_data();
  const auto r = parse_calibration_text(older_version_text(d, 3), "v3.toml");
  // Then every value reads back and each sensor's σ source is "unknown: older file"
  ASSERT_TRUE(r.is_ok()) << r.status().message();
  CalibrationData expected = d;
  for (auto& s : expected.sensors) s.sigma_source = SigmaSource{SigmaBasis::kUnknown, 0};
  EXPECT_EQ(r.value(), expected);
  // And re-saved as version 4 the file says so, sensor by sensor
  const std::string text = to_toml_text(r.value());
  std::size_t n = 0;
  for (auto at = text.find("sigma_source = 'unknown: older file'"); at != std::string::npos;
       at = text.find("sigma_source = 'unknown: older file'", at + 1)) {
    ++n;
  }
  EXPECT_EQ(n, 6U) << text;
}

TEST_F(LoadErrors, AVersion4FileWithoutASigmaSourceOrWithAnUnknownOneIsRefused) {
  EXPECT_THAT(load_text(replace_once(good_, "sigma_source = 'stated'\n", "")).message(),
              HasSubstr("missing key 'sensor.1.sigma_source'"));
  for (const char* bad : {"'residuals'", "'residuals, 0 dof'", "'residuals, 04 dof'",
                          "'residuals, -3 dof'", "'residuals, 10001 dof'", "'Stated'", "3"}) {
    const FileStatus s = load_text(
        replace_once(good_, "sigma_source = 'stated'", std::string("sigma_source = ") + bad));
    EXPECT_EQ(s.code(), ErrorCode::kInvalidArgument) << bad;
    EXPECT_THAT(s.message(), HasSubstr("sensor.1.sigma_source")) << bad;
  }
}

TEST_F(LoadErrors, AVersion3FileWithoutCorrelationsIsRefused) {
  const FileStatus s = load_text(replace_once(good_, "scale_bias = 0.25\n", ""));
  EXPECT_EQ(s.code(), ErrorCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("missing key 'sensor.1.correlation.scale_bias'"));
}

TEST_F(LoadErrors, AnUnknownCorrelationsStateIsRefused) {
  const FileStatus s =
      load_text(replace_once(good_, "correlations = 'stated'", "correlations = 'x'"));
  EXPECT_THAT(s.message(), HasSubstr("orientation.correlations is \"x\": expected \"stated\" or"));
}

TEST(FormatVersion1, LoadsWithStandardGravityAndSaysSo) {
  // Given a version-1 file (the format before the calibration site's gravity was stored)
  const CalibrationData d = table6_data();
  // When it is loaded
  const auto r = parse_calibration_text(version1_text(d), "v1.toml");
  // Then every value reads back, and the gravity is the standard one the version-1 front end
  // converted with, labelled as an assumption
  ASSERT_TRUE(r.is_ok()) << r.status().message();
  CalibrationData expected = d;
  expected.gravity_mps2 = nav::kStandardGravity;
  expected.gravity_source = kVersion1GravitySource;
  for (auto& s : expected.sensors) {
    s.correlation = {};  // not in version 1 either
    s.sigma_source = SigmaSource{SigmaBasis::kUnknown, 0};
  }
  expected.correlations_known = false;
  EXPECT_EQ(r.value(), expected);
  // And re-saved it becomes a version-4 file that loads with the same values
  const auto again = parse_calibration_text(to_toml_text(r.value()), "v4.toml");
  ASSERT_TRUE(again.is_ok()) << again.status().message();
  EXPECT_EQ(again.value(), expected);
}

TEST(FormatVersion1, AGravityTableInAVersion1FileIsAnUnknownKey) {
  std::string text = version1_text(table6_data());
  text = replace_once(text, "[integrity]", "[gravity]\nlocal_mps2 = 9.8\n\n[integrity]");
  const auto r = parse_calibration_text(text, "v1.toml");
  ASSERT_FALSE(r.is_ok());
  EXPECT_THAT(r.status().message(), HasSubstr("unknown key 'gravity.local_mps2'"));
}

TEST_F(LoadErrors, AVersion2FileWithoutGravityIsRefused) {
  const FileStatus s = load_text(replace_once(good_, "local_mps2 = 9.7894\n", ""));
  EXPECT_EQ(s.code(), ErrorCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("missing key 'gravity.local_mps2'"));
}

TEST_F(LoadErrors, MissingVersionIsRefused) {
  const FileStatus s = load_text(replace_once(good_, "format_version = 4", ""));
  EXPECT_THAT(s.message(), HasSubstr("missing key 'format_version'"));
}

TEST_F(LoadErrors, MissingKeyIsNamed) {
  const FileStatus s = load_text(replace_once(good_, "bias_g = -0.000242\n", ""));
  EXPECT_EQ(s.code(), ErrorCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("missing key 'sensor.2.bias_g'"));
}

TEST_F(LoadErrors, UnknownKeyIsNamedWithItsLine) {
  // Given a misspelt extra key (it would not be covered by the checksum)
  const std::string text =
      replace_once(good_, "bias_g = -0.000242\n", "bias_g = -0.000242\nbias_gg = 0.5\n");
  const int line = line_of(text, "bias_gg");
  const FileStatus s = load_text(text);
  EXPECT_EQ(s.code(), ErrorCode::kInvalidArgument);
  EXPECT_THAT(s.message(),
              HasSubstr("line " + std::to_string(line) + ": unknown key 'sensor.2.bias_gg'"));
}

TEST_F(LoadErrors, WrongTypeIsNamedWithItsLine) {
  const int line = line_of(good_, "scale_v_per_g = 0.332572");
  const FileStatus s =
      load_text(replace_once(good_, "scale_v_per_g = 0.332572", "scale_v_per_g = '0.332572'"));
  EXPECT_EQ(s.code(), ErrorCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("line " + std::to_string(line) +
                                     ": sensor.2.scale_v_per_g must be a number, found a string"));
}

TEST_F(LoadErrors, AnotherUnitIsRefused) {
  // Given angles declared in radians: the values would be read 57× too large or too small
  const FileStatus s = load_text(replace_once(good_, "angle = 'deg'", "angle = 'rad'"));
  EXPECT_EQ(s.code(), ErrorCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("units.angle is \"rad\" but this format stores \"deg\""));
}

TEST_F(LoadErrors, UnknownCompensatorIsRefused) {
  const FileStatus s = load_text(replace_once(good_, "compensator = 'exact'", "compensator = 'x'"));
  EXPECT_THAT(s.message(), HasSubstr("compensator is \"x\": expected \"none\", \"paper\" or"));
}

// Out-of-range values are written with a valid checksum (to_toml_text does not validate), so
// the range check, not the checksum, must catch them.
class OutOfRange : public LoadErrors {
 protected:
  void expect_refused(const CalibrationData& d, const std::string& key, const std::string& what) {
    const std::string text = to_toml_text(d);
    const FileStatus s = load_text(text);
    EXPECT_EQ(s.code(), ErrorCode::kOutOfRange) << s.message();
    const int line = key_line(text, key);
    EXPECT_THAT(s.message(), HasSubstr("line " + std::to_string(line) + ": " + key));
    EXPECT_THAT(s.message(), HasSubstr(what));
    // And saving the same data is refused before anything is written.
    const auto out = dir_.path() / "refused.toml";
    const FileStatus saved = save_calibration_file(out, d);
    EXPECT_EQ(saved.code(), ErrorCode::kOutOfRange);
    EXPECT_THAT(saved.message(), HasSubstr(key));
    EXPECT_FALSE(std::filesystem::exists(out));
  }
};

TEST_F(OutOfRange, NegativeScaleFactor) {
  CalibrationData d = table6_data();
  d.sensors[2].scale_v_per_g = -0.500242;
  expect_refused(d, "sensor.3.scale_v_per_g", "= -0.500242: must be in [1e-6, 1e6] V/g");
}

// Finite, positive, and still no scale factor: 1e300 and 1e-300 V/g become inf and 0 in the
// float32 core (whose message said "not a positive finite number" of a positive finite value).
// The bounds are the ones docs/calibration-file.md states; the edges themselves are accepted.
TEST_F(OutOfRange, ScaleFactorsAndLsbTheFloatCoreCannotHold) {
  for (const double sf : {1e300, 1e-300, 1.01e6, 0.99e-6}) {
    CalibrationData d = table6_data();
    d.sensors[1].scale_v_per_g = sf;
    expect_refused(d, "sensor.2.scale_v_per_g", "must be in [1e-6, 1e6] V/g");
  }
  for (const double lsb : {1e-300, 0.99e-12}) {
    CalibrationData d = table6_data();
    d.sensors[3].adc_lsb_v_per_count = lsb;
    expect_refused(d, "sensor.4.adc_lsb_v_per_count", "must be in [1e-12, 1] V/count");
  }
  const auto accepted = [this](const CalibrationData& d) {
    const auto out = dir_.path() / "edge.toml";
    return save_calibration_file(out, d).is_ok() && load_calibration_file(out).is_ok();
  };
  for (const double sf : {1e-6, 1e6}) {
    CalibrationData d = table6_data();
    d.sensors[1].scale_v_per_g = sf;
    EXPECT_TRUE(accepted(d)) << sf;
  }
  CalibrationData d = table6_data();
  d.sensors[3].adc_lsb_v_per_count = 1e-12;
  EXPECT_TRUE(accepted(d));
}

TEST_F(OutOfRange, NaNBias) {
  CalibrationData d = table6_data();
  d.sensors[4].bias_g = std::numeric_limits<double>::quiet_NaN();
  expect_refused(d, "sensor.5.bias_g", "must be a finite number");
}

TEST_F(OutOfRange, AngleBeyondTenDegrees) {
  CalibrationData d = table6_data();
  d.alpha.angle_deg[4] = 10.5;
  expect_refused(d, "orientation.alpha.zx_deg", "= 10.5: must be within ±10 degrees");
}

TEST_F(OutOfRange, NegativeUncertainty) {
  CalibrationData d = table6_data();
  d.beta.angle_sigma_deg[1] = -0.01;
  expect_refused(d, "orientation.beta.xz_sigma_deg", "must not be negative");
}

TEST_F(OutOfRange, InfiniteAdcLsb) {
  CalibrationData d = table6_data();
  d.sensors[0].adc_lsb_v_per_count = std::numeric_limits<double>::infinity();
  expect_refused(d, "sensor.1.adc_lsb_v_per_count", "must be a finite number");
}

TEST_F(OutOfRange, LocationErrorBeyondHalfTheArray) {
  CalibrationData d = table6_data();
  d.sensors[5].location_error_m[1] = 0.06;  // ρ = 0.1 m
  expect_refused(d, "sensor.6.location_error_m", "[1] = 0.06: a location error");
}

TEST_F(OutOfRange, GravityInGInsteadOfMetresPerSecondSquared) {
  CalibrationData d = table6_data();
  d.gravity_mps2 = 1.0;
  expect_refused(d, "gravity.local_mps2", "= 1: must be a local gravity in [9.7, 9.9] m/s²");
}

TEST_F(OutOfRange, CorrelationBeyondOne) {
  CalibrationData d = table6_data();
  d.sensors[1].correlation[0] = 1.5;
  expect_refused(d, "sensor.2.correlation.scale_bias",
                 "= 1.5: a correlation coefficient must be in [-1, 1]");
}

TEST_F(OutOfRange, CorrelationsThatAreNotACorrelationMatrix) {
  // Given coefficients each within [-1, 1] whose matrix is not positive semidefinite: SF fully
  // correlated with b and with angle 1, but b and angle 1 anti-correlated (eigenvalue −1)
  CalibrationData d = table6_data();
  d.sensors[3].correlation = {1.0, 1.0, 0.0, -1.0, 0.0, 0.0};
  const FileStatus s = load_text(to_toml_text(d));
  EXPECT_EQ(s.code(), ErrorCode::kOutOfRange) << s.message();
  EXPECT_THAT(s.message(), HasSubstr("sensor.4.correlation is not a correlation matrix"));
  const FileStatus saved = save_calibration_file(dir_.path() / "refused.toml", d);
  EXPECT_EQ(saved.code(), ErrorCode::kOutOfRange);
}

TEST_F(OutOfRange, BadDeviceIdAndTimestamp) {
  CalibrationData d = table6_data();
  d.device_id = "board 01";
  expect_refused(d, "device_id", "\"board 01\" is not 1 to 64 characters");
  d = table6_data();
  d.created_utc = "2024-13-01T00:00:00Z";
  expect_refused(d, "created_utc", "is not a UTC time YYYY-MM-DDTHH:MM:SSZ");
}

}  // namespace
}  // namespace gfins::calib_file
