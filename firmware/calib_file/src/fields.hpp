// The list of values of a calibration file, in the order of the canonical serialisation.
//
// One visitor walks this list to write the TOML table, another to read it, a third to build the
// canonical text the checksum covers and a fourth to validate ranges, so the four can never
// disagree about which keys exist. The key paths are the file's dotted TOML keys.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <string_view>

#include "gfins/calib_file/calibration_data.hpp"

namespace gfins::calib_file::detail {

/// "calibration file 'NAME': ", the start of every message about a file.
inline std::string file_prefix(std::string_view name) {
  return "calibration file '" + std::string(name) + "': ";
}

/// What a value must satisfy (validate()).
enum class Domain : std::uint8_t {
  kAdcLsb,       // finite, 0 < x ≤ kMaxAdcLsbV
  kScale,        // finite, x > 0
  kSigma,        // finite, x ≥ 0
  kBias,         // finite, |x| ≤ kMaxAbsBiasG
  kAngle,        // finite, |x| ≤ kMaxAngleDeg
  kLocation,     // finite, |x| ≤ kMaxLocationErrorOfRho · ρ
  kRho,          // finite, 0 < x ≤ kMaxRhoM
  kPosition,     // finite, |x| ≤ kMaxPositionM
  kAxis,         // finite, unit length within kAxisUnitTolerance
  kDeviceId,     // [A-Za-z0-9._-]{1,64}
  kUtc,          // YYYY-MM-DDTHH:MM:SSZ
  kSource,       // printable ASCII, ≤ kMaxSourceLength
  kGravity,      // finite, kMinGravityMps2 ≤ x ≤ kMaxGravityMps2
  kCorrelation,  // finite, |x| ≤ kMaxAbsCorrelation
};

/// Order of the angle keys: nav::AngleIndex (xy, xz, yx, yz, zx, zy).
inline constexpr std::array<const char*, 6> kAngleNames = {"xy", "xz", "yx", "yz", "zx", "zy"};

/// Units the file states in its [units] table; a reader rejects any other unit.
struct UnitEntry {
  const char* key;
  const char* unit;
};
inline constexpr std::array<UnitEntry, 5> kUnits = {{
    {"units.length", "m"},
    {"units.scale_factor", "V/g"},
    {"units.bias", "g"},
    {"units.angle", "deg"},
    {"units.adc_lsb", "V/count"},
}};

inline const char* to_string_compensator(nav::CompensatorKind k) { return nav::to_string(k); }

/// D is CalibrationData or const CalibrationData. V has the methods
///   text(key, std::string&, Domain), unit(key, const char* unit),
///   geometry_kind(key, GeometryKind&), compensator(key, nav::CompensatorKind&),
///   correlations(key, bool& known), sigma_source(key, SigmaSource&),
///   number(key, double&, Domain), vec3(key, std::array<double, 3>&, Domain).
/// Geometry's kind is visited before the keys that depend on it, so a reader sees it in time.
/// `version` is the file's format version: the keys it defines (version 1 has no [gravity]).
template <typename D, typename V>
void visit_fields(D& d, V& v, std::int64_t version = kFormatVersion) {
  v.text("device_id", d.device_id, Domain::kDeviceId);
  v.text("created_utc", d.created_utc, Domain::kUtc);
  v.text("source", d.source, Domain::kSource);
  for (const UnitEntry& u : kUnits) v.unit(u.key, u.unit);
  v.geometry_kind("geometry.name", d.geometry.kind);
  v.number("geometry.rho_m", d.geometry.rho_m, Domain::kRho);
  if (d.geometry.kind == GeometryKind::kCustom) {
    for (std::size_t j = 0; j < kNumSensors; ++j) {
      const std::string p = "geometry.sensor." + std::to_string(j + 1) + ".";
      v.vec3(p + "position_m", d.geometry.positions_m[j], Domain::kPosition);
      v.vec3(p + "axis", d.geometry.axes[j], Domain::kAxis);
    }
  }
  if (version >= 2) {
    v.number("gravity.local_mps2", d.gravity_mps2, Domain::kGravity);
    v.text("gravity.source", d.gravity_source, Domain::kSource);
  }
  for (std::size_t j = 0; j < kNumSensors; ++j) {
    const std::string p = "sensor." + std::to_string(j + 1) + ".";
    auto& s = d.sensors[j];
    v.number(p + "adc_lsb_v_per_count", s.adc_lsb_v_per_count, Domain::kAdcLsb);
    v.number(p + "scale_v_per_g", s.scale_v_per_g, Domain::kScale);
    v.number(p + "scale_sigma_v_per_g", s.scale_sigma_v_per_g, Domain::kSigma);
    v.number(p + "bias_g", s.bias_g, Domain::kBias);
    v.number(p + "bias_sigma_g", s.bias_sigma_g, Domain::kSigma);
    v.vec3(p + "location_error_m", s.location_error_m, Domain::kLocation);
    v.vec3(p + "location_error_sigma_m", s.location_error_sigma_m, Domain::kSigma);
    if (version >= 3) {
      // sensor.N.correlation.scale_bias, scale_<a1>, scale_<a2>, bias_<a1>, bias_<a2>, <a1>_<a2>
      // with <a1>, <a2> the Table 6 names of the sensor's two angles (sensor_angles()).
      const SensorAngles a = sensor_angles(j);
      const std::string a1 = kAngleNames[a.angle[0]];
      const std::string a2 = kAngleNames[a.angle[1]];
      std::string pair = a1;
      pair += '_';
      pair += a2;
      const std::array<std::string, kNumCorrelations> names = {
          "scale_bias", "scale_" + a1, "scale_" + a2, "bias_" + a1, "bias_" + a2, pair};
      for (std::size_t c = 0; c < kNumCorrelations; ++c) {
        v.number(p + "correlation." + names[c], s.correlation[c], Domain::kCorrelation);
      }
    }
    if (version >= 4) v.sigma_source(p + "sigma_source", s.sigma_source);
  }
  const auto visit_set = [&v](const std::string& p, auto& set) {
    for (std::size_t i = 0; i < 6; ++i) {
      v.number(p + kAngleNames[i] + "_deg", set.angle_deg[i], Domain::kAngle);
      v.number(p + kAngleNames[i] + "_sigma_deg", set.angle_sigma_deg[i], Domain::kSigma);
    }
  };
  visit_set("orientation.beta.", d.beta);
  visit_set("orientation.alpha.", d.alpha);
  // Whether sensor.N.correlation holds the solver's values or zeros standing for "not known"
  // (data first read from a version 1 or 2 file and saved again).
  if (version >= 3) v.correlations("orientation.correlations", d.correlations_known);
  v.compensator("compensator", d.compensator);
}

}  // namespace gfins::calib_file::detail
