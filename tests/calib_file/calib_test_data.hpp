// Shared fixtures of the calibration-file tests: a CalibrationData carrying the paper's Table 6
// and helpers for temporary directories.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "gfins/calib_file/calibration_data.hpp"
#include "support/temp_dir.hpp"

namespace gfins::calib_file::testing {

/// Table 6 of the paper (SF V/g, bias g, angles deg) with made-up uncertainties, LSB and Δρ.
inline CalibrationData table6_data() {
  CalibrationData d;
  d.device_id = "gfins-test-01";
  d.created_utc = "2024-05-01T12:34:56Z";
  d.source = "paper Table 6";
  d.geometry.kind = GeometryKind::kTable1;
  d.geometry.rho_m = 0.1;
  const double sf[6] = {0.509874, 0.332572, 0.500242, 2.493301, 0.339215, 2.476663};
  const double b[6] = {-0.000731, -0.000242, 0.000867, -0.007977, -0.000891, -0.004691};
  for (std::size_t j = 0; j < 6; ++j) {
    SensorCalibration& s = d.sensors[j];
    s.adc_lsb_v_per_count = 2.5 / 8388608.0;  // ±2.5 V over 24 bits
    s.scale_v_per_g = sf[j];
    s.scale_sigma_v_per_g = 1e-6;
    s.bias_g = b[j];
    s.bias_sigma_g = 2e-6;
    s.location_error_m = {1e-4 * static_cast<double>(j), -2e-4, 0.0};
    s.location_error_sigma_m = {5e-5, 5e-5, 5e-5};
    // (SF,b) (SF,a1) (SF,a2) (b,a1) (b,a2) (a1,a2): made up, a valid correlation matrix.
    s.correlation = {0.25, -0.125, 0.5, 0.0625, -0.375, 0.1875};
  }
  d.beta.angle_deg = {1.117319, -0.175730, -0.581196, -0.738742, 2.454457, 2.482135};
  d.alpha.angle_deg = {-2.654967, 2.596778, -0.838703, -0.737387, 0.119537, -1.451107};
  d.beta.angle_sigma_deg = {0.04, 0.05, 0.06, 0.07, 0.08, 0.04};
  d.alpha.angle_sigma_deg = {0.05, 0.06, 0.07, 0.08, 0.04, 0.05};
  d.compensator = nav::CompensatorKind::kExact;
  d.gravity_mps2 = 9.7894;  // WGS-84 normal gravity at 24.8° latitude, m/s²
  d.gravity_source = "test site at 24.8 deg";
  return d;
}

// The shared temporary folder and file helpers (tests/support/temp_dir.hpp).
using gfins::testing::read_text;
using gfins::testing::write_text;
/// A temporary folder named for these tests.
class TempDir : public gfins::testing::TempDir {
 public:
  TempDir() : gfins::testing::TempDir("gfins-calib") {}
};

}  // namespace gfins::calib_file::testing
