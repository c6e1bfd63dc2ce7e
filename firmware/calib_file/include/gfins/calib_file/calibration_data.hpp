// The calibration of one six-accelerometer board, as stored on disk (docs/calibration-file.md)
// and converted to the navigation core's configuration (nav::PipelineConfig parts).
//
// Host/firmware code (not nav_core): std::string and friends are fine here. The values are kept
// in the units of the file so that a save/load round trip is bit-exact:
//   - orientation errors in degrees (the file's unit, as in the paper's Table 6). Radians → degrees
//     → radians is not the identity in binary64 (for roughly 7 % of values no double in degrees
//     maps back to the same double in radians), so the radians the navigation core uses are made
//     only at the conversion to nav::Misalignment<T> (misalignment() below);
//   - lengths in m, scale factors in V/g, biases in g, ADC LSB in V/count, as in the file.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>
#include <optional>
#include <string>

#include "gfins/nav_core/compensator.hpp"
#include "gfins/nav_core/front_end.hpp"
#include "gfins/nav_core/geometry.hpp"
#include "gfins/nav_core/misalignment.hpp"
#include "gfins/nav_core/pipeline.hpp"

namespace gfins::calib_file {

/// The format version this build writes (docs/calibration-file.md, versioning). Version 2 added
/// the local gravity of the calibration site ([gravity]); version 3 the correlations of each
/// sensor's SF, bias and two orientation angles (sensor.N.correlation); version 4 where each
/// sensor's σ came from (sensor.N.sigma_source).
inline constexpr std::int64_t kFormatVersion = 4;
/// The oldest version this build still reads (converted on load: see kVersion1GravitySource).
inline constexpr std::int64_t kOldestFormatVersion = 1;
inline constexpr std::size_t kNumSensors = 6;

/// Acceptance bounds of the values (validate()); the doc lists the same numbers.
inline constexpr double kMaxAngleDeg = 10.0;           // small-angle model of eqs. (14)/(15)
inline constexpr double kMaxAbsBiasG = 1.0;            // a 1 g bias is a broken sensor, not a bias
inline constexpr double kMaxRhoM = 10.0;               // array half-size
inline constexpr double kMaxPositionM = 10.0;          // custom geometry positions
inline constexpr double kMaxLocationErrorOfRho = 0.5;  // |Δρ component| ≤ ρ/2
inline constexpr double kAxisUnitTolerance = 1e-6;     // nominal axes are unit vectors
inline constexpr double kMaxAdcLsbV = 1.0;             // V/count; a 24-bit ADC is ~1e-7
/// Smallest ADC LSB and the scale-factor range: the navigation core runs in float32, whose
/// front-end gain LSB·g/SF must be a normal float (1.2e-38 .. 3.4e38). These bounds keep the gain
/// within 1e-17 .. 1e7 and still admit any real chain: a 32-bit converter with a 1 V reference
/// has 4.7e-10 V/count; a sensor output of 1 µV/g or 1 MV/g is no accelerometer.
inline constexpr double kMinAdcLsbV = 1e-12;
inline constexpr double kMinScaleVPerG = 1e-6;
inline constexpr double kMaxScaleVPerG = 1e6;
inline constexpr std::size_t kMaxDeviceIdLength = 64;
inline constexpr std::size_t kMaxSourceLength = 256;
/// Accepted local gravity, m/s². Normal gravity on the WGS-84 ellipsoid spans 9.7803 (equator) to
/// 9.8322 (poles) and falls by 3.1e-6 m/s² per metre of height (9.755 at 8 km); the bounds admit
/// every real site and refuse a value in another unit (1 "g", 980 Gal).
inline constexpr double kMinGravityMps2 = 9.7;
inline constexpr double kMaxGravityMps2 = 9.9;
/// Values of orientation.correlations (format version 3): the correlations are the solver's, or
/// zeros standing for "not known" (data first read from a version 1 or 2 file).
inline constexpr const char* kCorrelationsStated = "stated";
inline constexpr const char* kCorrelationsUnknown = "unknown: taken as 0";
/// Largest |correlation coefficient| accepted; a coefficient is at most 1 in magnitude.
inline constexpr double kMaxAbsCorrelation = 1.0;
/// gravity.source given to a version-1 file on load: version 1 had no notion of the site, and
/// its front end converted V/g with standard gravity, which the conversion keeps.
inline constexpr const char* kVersion1GravitySource =
    "format version 1 file: standard gravity assumed (calibration site unknown)";
enum class GeometryKind : std::uint8_t {
  kTable1 = 0,  // the paper's Table 1 (Chen's cube) with half-size rho_m
  kCustom = 1,  // positions and axes given explicitly
};

/// Nominal geometry of the array, body frame FRD at the array centre.
struct GeometrySpec {
  GeometryKind kind = GeometryKind::kTable1;
  double rho_m = 0.1;  // cube half-size (Table 1); for a custom array its characteristic size
  std::array<std::array<double, 3>, kNumSensors> positions_m{};  // kCustom only
  std::array<std::array<double, 3>, kNumSensors> axes{};         // kCustom only, unit vectors

  bool operator==(const GeometrySpec&) const = default;
};

/// Where a sensor's σ of SF, bias and its two angles (and their correlations) came from
/// (sensor.N.sigma_source, format version 4; docs/calibration-file.md).
enum class SigmaBasis : std::uint8_t {
  kStated = 0,  // propagated from the σ stated with every mean: Gaussian
  kResiduals,   // from the fit residuals with `dof` degrees of freedom: a Student-t's width
  kNone,        // not estimated (exactly determined, no σ stated): the zeros are not "exact"
  kUnknown,     // read from a file older than version 4, which did not say
};

struct SigmaSource {
  SigmaBasis basis = SigmaBasis::kStated;
  std::int32_t dof = 0;  // kResiduals only: poses the sensor was fitted from, minus 4

  bool operator==(const SigmaSource&) const = default;
};

/// Largest degrees of freedom accepted in a sigma_source (a calibration has tens of poses).
inline constexpr std::int32_t kMaxSigmaDof = 10000;

/// The file's text of a sigma_source: "stated", "residuals, K dof", "none: not estimated",
/// "unknown: older file".
std::string to_string(const SigmaSource& s);
/// The inverse of to_string; false for any other text (or K outside 1..kMaxSigmaDof).
bool parse_sigma_source(const std::string& text, SigmaSource& out);

/// One accelerometer (index j = sensor j+1 of Table 1). Model: P = SF (f·θ + b), paper eq. (21).
struct SensorCalibration {
  double adc_lsb_v_per_count = 0.0;                // V/count of its ADC channel
  double scale_v_per_g = 0.0;                      // SF_aj, V/g
  double scale_sigma_v_per_g = 0.0;                // 1σ
  double bias_g = 0.0;                             // b_aj, g
  double bias_sigma_g = 0.0;                       // 1σ
  std::array<double, 3> location_error_m{};        // Δρ_j, m, body frame (eq. (19))
  std::array<double, 3> location_error_sigma_m{};  // 1σ per component
  /// Correlation coefficients of this sensor's four multi-attitude parameters (SF, b and its two
  /// orientation angles: the row of eq. (14)/(15) it owns, angles 2r and 2r+1 of its set in
  /// nav::AngleIndex order, r = its row; see sensor_angles()), in the order kCorrelationPairs:
  /// (SF,b) (SF,a1) (SF,a2) (b,a1) (b,a2) (a1,a2). Sensors are independent (multi_attitude.hpp),
  /// so with the σ above this is the whole covariance of the orientation calibration (format
  /// version 3; zero, i.e. unknown, when read from an older file: see correlations_known).
  std::array<double, 6> correlation{};
  /// Where the σ above (and the correlations) came from (format version 4; kUnknown when read
  /// from an older file).
  SigmaSource sigma_source{};

  bool operator==(const SensorCalibration&) const = default;
};

/// The six orientation errors of one set, in nav::AngleIndex order: xy, xz, yx, yz, zx, zy
/// (paper eqs. (14)/(15) and Table 6).
struct SetOrientation {
  std::array<double, 6> angle_deg{};
  std::array<double, 6> angle_sigma_deg{};  // 1σ

  bool operator==(const SetOrientation&) const = default;
};

struct CalibrationData {
  std::string device_id;    // [A-Za-z0-9._-], 1..64 characters
  std::string created_utc;  // "YYYY-MM-DDTHH:MM:SSZ"
  std::string source;       // free text: where the data came from (printable ASCII, may be empty)
  GeometrySpec geometry{};
  std::array<SensorCalibration, kNumSensors> sensors{};
  SetOrientation beta{};   // set {2, 3, 5}: Δβ (nav::kSetBeta)
  SetOrientation alpha{};  // set {1, 4, 6}: Δα (nav::kSetAlpha)
  nav::CompensatorKind compensator = nav::CompensatorKind::kExact;
  /// Local gravity magnitude of the calibration site, m/s²: the multi-attitude calibration takes
  /// |f| = 1 g in every pose, so this is the g of every V/g and bias above (format version 2).
  double gravity_mps2 = nav::kStandardGravity;
  /// How gravity_mps2 was obtained (free text, printable ASCII, ≤ 256): "given", or "WGS-84
  /// normal gravity at latitude 24.8 deg, height 50 m".
  std::string gravity_source;
  /// False when read from a file older than format version 3, which carried the σ of SF, b and
  /// the angles but not their correlations: the correlations are then 0 by assumption, and a
  /// version-3 file written from such data says so (orientation.correlations).
  bool correlations_known = true;

  bool operator==(const CalibrationData&) const = default;
};

/// The key suffixes of SensorCalibration::correlation, in its order ("1" and "2" are the
/// sensor's two angles, named in the file by their Table 6 names: "scale_xy", "xy_xz", ...).
inline constexpr std::size_t kNumCorrelations = 6;

/// The set of sensor j (0-based) and its two angles (indices into that set's six, nav::AngleIndex
/// order): the sensor at row r of its set owns row r of C (eqs. (14)/(15)), angles 2r and 2r+1.
struct SensorAngles {
  bool alpha = false;  // set α {1, 4, 6}; else set β {2, 3, 5}
  std::array<std::size_t, 2> angle{};
};
inline SensorAngles sensor_angles(std::size_t j) {
  SensorAngles a;
  for (std::size_t r = 0; r < 3; ++r) {
    if (static_cast<std::size_t>(nav::kSetAlpha[r]) == j) {
      a.alpha = true;
      a.angle = {2 * r, 2 * r + 1};
    }
    if (static_cast<std::size_t>(nav::kSetBeta[r]) == j) a.angle = {2 * r, 2 * r + 1};
  }
  return a;
}

/// The first value outside its documented domain: `key` is its path in the file
/// ("sensor.3.scale_v_per_g"), `problem` says what is wrong. Empty key means none.
struct Problem {
  std::string key;
  std::string problem;
  bool found() const { return !key.empty(); }
};
Problem validate(const CalibrationData& data);

/// The canonical serialisation the checksum covers (docs/calibration-file.md): one line
/// "key=value\n" per value in a fixed order, doubles as the 16 hex digits of their IEEE-754
/// binary64 bit pattern, so it is the same on every machine and for every text formatting.
/// `version` selects the key list of that format version (1 has no [gravity]).
std::string canonical_serialisation(const CalibrationData& data,
                                    std::int64_t version = kFormatVersion);
/// FNV-1a 64-bit over canonical_serialisation(data, version).
std::uint64_t checksum(const CalibrationData& data, std::int64_t version = kFormatVersion);
/// The identity of a calibration on the bus (the status frame's cal_id, can::Epoch::cal_id):
/// checksum(data) folded to 32 bits (h ^ h >> 32, the rule gfins-fw uses), with 0 (reserved
/// for "nominal parameters, no file") mapped to 1. Two files with the same values have the same
/// identity.
std::uint32_t cal_id_of(const CalibrationData& data);

/// Relative difference of two ADC LSBs that still counts as one converter setting (the file
/// prints the shortest text that reads back exactly; 1e-6 leaves room for a value typed by hand
/// to 7 digits, far below the smallest real change: a gain step of the ADS131M06 is 2×).
inline constexpr double kLsbMismatchRel = 1e-6;

/// Why `data` cannot be used with a converter of `volts_per_count` per sensor ("sensor a1 has an
/// ADC LSB of 1.192e-06 V/count, <what> 1.43051147e-07: the calibration is of another converter
/// setting"): every count would be scaled by their ratio, |f| with it. nullopt when they agree.
std::optional<std::string> converter_mismatch(
    const CalibrationData& data, const std::array<double, kNumSensors>& volts_per_count,
    const std::string& what);
/// FNV-1a 64-bit of arbitrary bytes (offset basis 0xcbf29ce484222325, prime 0x100000001b3).
std::uint64_t fnv1a64(const std::string& bytes);

/// Current time as "YYYY-MM-DDTHH:MM:SSZ" (UTC).
std::string utc_now_iso8601();

const char* to_string(GeometryKind kind);

// --- Conversion to the navigation core's configuration ------------------------------------

inline constexpr double kRadPerDeg = std::numbers::pi / 180.0;

template <typename T>
nav::ArrayGeometry<T, 6> nominal_geometry(const CalibrationData& d) {
  if (d.geometry.kind == GeometryKind::kTable1) {
    return nav::table1_geometry<double>(d.geometry.rho_m).cast<T>();
  }
  nav::ArrayGeometry<T, 6> g;
  for (std::size_t j = 0; j < kNumSensors; ++j) {
    const auto& p = d.geometry.positions_m[j];
    const auto& a = d.geometry.axes[j];
    g.rho_b[j] = nav::Vec3<T>(static_cast<T>(p[0]), static_cast<T>(p[1]), static_cast<T>(p[2]));
    g.theta_b[j] = nav::Vec3<T>(static_cast<T>(a[0]), static_cast<T>(a[1]), static_cast<T>(a[2]));
  }
  return g;
}

template <typename T>
nav::FrontEndParams<T, 6> front_end_params(const CalibrationData& d) {
  nav::FrontEndParams<T, 6> p;
  for (std::size_t j = 0; j < kNumSensors; ++j) {
    p.volts_per_count[j] = static_cast<T>(d.sensors[j].adc_lsb_v_per_count);
    p.scale_v_per_g[j] = static_cast<T>(d.sensors[j].scale_v_per_g);
    p.bias_g[j] = static_cast<T>(d.sensors[j].bias_g);
  }
  p.gravity_mps2 = static_cast<T>(d.gravity_mps2);  // the g of V/g: calibration site
  return p;
}

/// Orientation errors in radians (computed in double, then rounded to T) and location errors.
template <typename T>
nav::Misalignment<T> misalignment(const CalibrationData& d) {
  nav::Misalignment<T> m;
  for (std::size_t i = 0; i < 6; ++i) {
    m.orientation.beta[i] = static_cast<T>(d.beta.angle_deg[i] * kRadPerDeg);
    m.orientation.alpha[i] = static_cast<T>(d.alpha.angle_deg[i] * kRadPerDeg);
  }
  for (std::size_t j = 0; j < kNumSensors; ++j) {
    const auto& e = d.sensors[j].location_error_m;
    m.drho_b[j] = nav::Vec3<T>(static_cast<T>(e[0]), static_cast<T>(e[1]), static_cast<T>(e[2]));
  }
  return m;
}

/// Fills the calibration parts of a pipeline configuration (nominal geometry, front end,
/// misalignment, compensator); the rest (gravity, rates, alignment) is left as it was.
template <typename T>
void apply_to(const CalibrationData& d, nav::PipelineConfig<T>& config) {
  config.nominal = nominal_geometry<T>(d);
  config.front_end = front_end_params<T>(d);
  config.misalignment = misalignment<T>(d);
  config.compensator = d.compensator;
}

}  // namespace gfins::calib_file
