// Start-up steps that turn the configuration and the calibration file into what the sample loop
// runs with (docs/firmware.md, "Start-up"). Host/Linux side: allocation and file I/O are fine
// here, before the loop starts.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "gfins/app/config.hpp"
#include "gfins/app/reload_worker.hpp"
#include "gfins/app/sample_loop.hpp"
#include "gfins/calib_file/calibration_data.hpp"

namespace gfins::app {

/// The calibration identity published on CAN: calib_file::cal_id_of() (the one the calibration
/// tool prints); 0 is reserved for "uncalibrated defaults".
std::uint32_t calibration_id(const calib_file::CalibrationData& d);

/// The [aiding] section as the navigation core takes it (gravity and rate from `p`).
nav::AidingConfig<float> aiding_config(const FwConfig& c, const nav::PipelineConfig<float>& p);

/// Pipeline configuration from the firmware configuration and a calibration.
nav::PipelineConfig<float> pipeline_config(const FwConfig& c, const calib_file::CalibrationData& d);

/// Loop options (rates, initial heading and position) from the configuration.
LoopOptions loop_options(const FwConfig& c);

struct StartupCalibration {
  CalibrationSet set;
  bool from_file = false;
  std::string message;    // what happened (a loud warning when !from_file)
  std::string device_id;  // of the calibration in use; empty on the nominal defaults
};

/// Reads `c.calibration_file`. Missing, invalid, of another converter setting than `defaults`
/// (the board's ADC LSB) or refused by the navigation core → `defaults` flagged uncalibrated
/// (cal_id 0),
/// and `message` says why; the file is never modified. With no file configured and a `factory`
/// calibration (the simulated board's: its scenario's true parameters), that one is used as a
/// calibration.
StartupCalibration load_calibration(const FwConfig& c, const calib_file::CalibrationData& defaults,
                                    const calib_file::CalibrationData* factory = nullptr);

/// Nominal calibration of a board whose chain has `volts_per_count` at the sensor: Table 1
/// geometry with ρ = 0.1 m, QA-1100 nominal scale factor 1.33 V/g (1.33 mA/g into 1 kΩ), zero
/// bias and misalignment, no compensation.
calib_file::CalibrationData nominal_calibration(double volts_per_count);

/// The ReloadWorker's loader for the configured file: a new set on success; logs and no set on
/// failure (the calibration in use stays). With `board_lsb` (the board's converter, from
/// converter_lsb(defaults)) a file of another converter setting is such a failure too. With
/// `device_in_use` (StartupCalibration::device_id) a file of another device_id is refused
/// (ReloadOutcome::other_device) unless the request is forced; a board on its nominal defaults
/// ("") takes the first file, whose id is then the one in use.
ReloadWorker::LoadFn calibration_reloader(const FwConfig& c,
                                          std::optional<std::array<double, 6>> board_lsb = {},
                                          std::string device_in_use = {});

/// Why the board cannot run with a calibration that loaded: another converter setting than
/// `board_lsb` (when given), or a set the navigation core refuses (a singular custom geometry, a
/// scale factor the float32 core cannot hold). nullopt when it can. The one rule of start-up,
/// reload and --check-config.
std::optional<std::string> calibration_refusal(const FwConfig& c,
                                               const calib_file::CalibrationData& d,
                                               const std::array<double, 6>* board_lsb);

/// The ADC LSB of each sensor in `d`, V/count (for the defaults: the board's converter).
std::array<double, 6> converter_lsb(const calib_file::CalibrationData& d);

}  // namespace gfins::app
