#include "gfins/app/startup.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "gfins/app/can_settings.hpp"
#include "gfins/app/publisher_sink.hpp"
#include "gfins/app/vehicle_frame.hpp"
#include "gfins/calib_file/calibration_file.hpp"

namespace gfins::app {
namespace {
constexpr double kRadPerDeg = std::numbers::pi / 180.0;
}

std::uint32_t calibration_id(const calib_file::CalibrationData& d) {
  return calib_file::cal_id_of(d);  // one rule, shared with gfins-calibrate's report
}

nav::AidingConfig<float> aiding_config(const FwConfig& c, const nav::PipelineConfig<float>& p) {
  constexpr double kUg = 1e-6 * nav::kStandardGravity;  // m/s² per µg
  nav::AidingConfig<float> a;
  a.enabled = c.aiding;
  a.standstill_updates = c.aiding_standstill;
  a.decimation = static_cast<std::uint32_t>(c.aiding_decimation);
  a.filter.sample_rate_hz = static_cast<float>(c.sample_rate_hz);
  a.filter.noise.white_sigma_mps2.fill(static_cast<float>(c.aiding_noise_ug * kUg));
  a.filter.noise.bias_sigma_mps2.fill(static_cast<float>(c.aiding_bias_sigma_ug * kUg));
  a.filter.noise.bias_rw_mps2_sqrt_s.fill(static_cast<float>(c.aiding_bias_rw_ug_sqrt_s * kUg));
  a.filter.zupt_sigma_mps = static_cast<float>(c.aiding_zupt_sigma_mps);
  a.filter.zaru_sigma_rps = static_cast<float>(c.aiding_zaru_sigma_rps);
  a.filter.track_heading_sigma_rad =
      static_cast<float>(c.aiding_track_heading_sigma_deg * 3.14159265358979323846 / 180.0);
  a.filter.gnss_lever_arm_b = nav::Vec3<float>(static_cast<float>(c.aiding_gnss_lever_arm_m[0]),
                                               static_cast<float>(c.aiding_gnss_lever_arm_m[1]),
                                               static_cast<float>(c.aiding_gnss_lever_arm_m[2]));
  a.standstill.white_sigma_mps2 = static_cast<float>(c.aiding_noise_ug * kUg);
  a.standstill.gravity_mps2 = p.gravity.magnitude_at_origin();
  return a;
}

nav::PipelineConfig<float> pipeline_config(const FwConfig& c,
                                           const calib_file::CalibrationData& d) {
  nav::PipelineConfig<float> p;
  calib_file::apply_to(d, p);
  p.compensator = resolve_compensator(c.compensator, d.compensator);
  switch (c.gravity) {
    case GravityChoice::kCalibration:
      // The local gravity the file was calibrated with: its front end's V/g assume it, so the
      // board navigating where it was calibrated sees exactly this magnitude at rest.
      p.gravity = nav::GravityModel<float>::constant(static_cast<float>(d.gravity_mps2));
      break;
    case GravityChoice::kStandard:
      p.gravity = nav::GravityModel<float>::constant(static_cast<float>(nav::kStandardGravity));
      break;
    case GravityChoice::kConstant:
      p.gravity = nav::GravityModel<float>::constant(static_cast<float>(c.gravity_mps2));
      break;
    case GravityChoice::kNormal:
      p.gravity = nav::GravityModel<float>::normal(c.latitude_deg * kRadPerDeg, c.height_m);
      break;
  }
  p.sample_rate_hz = static_cast<float>(c.sample_rate_hz);
  p.alignment_samples =
      static_cast<std::uint32_t>(std::llround(std::max(1.0, c.alignment_s * c.sample_rate_hz)));
  p.heading_rad = static_cast<float>(c.heading_deg * kRadPerDeg);
  p.aiding = aiding_config(c, p);
  p.r0_n =
      nav::Vec3<float>(static_cast<float>(c.position_m[0]), static_cast<float>(c.position_m[1]),
                       static_cast<float>(c.position_m[2]));
  return p;
}

LoopOptions loop_options(const FwConfig& c) {
  LoopOptions o;
  o.sample_rate_hz = c.sample_rate_hz;
  o.node_id = static_cast<std::uint8_t>(c.node_id);
  o.aiding_inputs = c.aiding && c.aiding_inputs;
  o.ids = id_bases(c);
  o.config_dividers = c.dividers;
  o.config_node_id = static_cast<std::uint8_t>(c.node_id);
  o.config_ids = o.ids;
  // The configuration's reader admits 0 <= first <= last <= 0x7FF only (can.reserved_ids).
  for (const std::array<int, 2>& r : c.reserved_ids) {
    o.reserved_ids.push_back({static_cast<std::uint32_t>(r[0]), static_cast<std::uint32_t>(r[1])});
  }
  o.initial_heading_rad = static_cast<float>(c.heading_deg * kRadPerDeg);
  o.initial_position_n =
      nav::Vec3<float>(static_cast<float>(c.position_m[0]), static_cast<float>(c.position_m[1]),
                       static_cast<float>(c.position_m[2]));
  o.q_vb = mounting_rotation(c.mounting_rpy_deg);
  return o;
}

calib_file::CalibrationData nominal_calibration(double volts_per_count) {
  calib_file::CalibrationData d;
  d.device_id = "nominal";
  d.created_utc = "1970-01-01T00:00:00Z";
  d.source = "gfins-fw nominal defaults (no calibration file)";
  d.geometry.kind = calib_file::GeometryKind::kTable1;
  d.geometry.rho_m = 0.1;
  for (auto& s : d.sensors) {
    s.adc_lsb_v_per_count = volts_per_count;
    s.scale_v_per_g = 1.33;  // QA-1100: 1.33 mA/g nominal into a 1 kΩ load resistor
  }
  d.compensator = nav::CompensatorKind::kNone;
  return d;
}

std::array<double, 6> converter_lsb(const calib_file::CalibrationData& d) {
  std::array<double, 6> lsb{};
  for (std::size_t j = 0; j < lsb.size(); ++j) lsb[j] = d.sensors[j].adc_lsb_v_per_count;
  return lsb;
}

std::optional<std::string> calibration_refusal(const FwConfig& c,
                                               const calib_file::CalibrationData& d,
                                               const std::array<double, 6>* board_lsb) {
  // A file of another converter setting (another board's gain, the paper's 20-bit LSB) would
  // scale every count wrongly.
  if (board_lsb != nullptr) {
    if (auto why = calib_file::converter_mismatch(d, *board_lsb, "the board's converter")) {
      return why;
    }
  }
  if (const Status s = nav::NavPipeline<float>::check(pipeline_config(c, d)); !s.is_ok()) {
    return std::string("the navigation core refuses it: ") + s.message();
  }
  return std::nullopt;
}

StartupCalibration load_calibration(const FwConfig& c, const calib_file::CalibrationData& defaults,
                                    const calib_file::CalibrationData* factory) {
  StartupCalibration out;
  std::string why;
  if (c.calibration_file.empty() && factory != nullptr) {
    out.set.config = pipeline_config(c, *factory);
    out.set.cal_id = calib_file::cal_id_of(*factory);
    out.set.calibrated = true;
    out.from_file = true;  // a real calibration, not the flagged defaults
    out.message = "factory calibration of the board (" + factory->source + ")";
    out.device_id = factory->device_id;
    return out;
  }
  if (c.calibration_file.empty()) {
    why = "no calibration file configured (calibration.file is empty)";
  } else {
    auto loaded = calib_file::load_calibration_file(c.calibration_file);
    const std::array<double, 6> board_lsb = converter_lsb(defaults);
    // Refused like any other bad file: the board navigates on its flagged defaults.
    std::optional<std::string> refusal;
    if (loaded.is_ok()) refusal = calibration_refusal(c, loaded.value(), &board_lsb);
    if (loaded.is_ok() && !refusal) {
      out.set.config = pipeline_config(c, loaded.value());
      out.set.cal_id = calib_file::cal_id_of(loaded.value());
      out.set.calibrated = true;
      out.from_file = true;
      out.device_id = loaded.value().device_id;
      char id[16];
      std::snprintf(id, sizeof id, "%08x", out.set.cal_id);
      out.message = "calibration " + c.calibration_file + " (device " + loaded.value().device_id +
                    ", id " + id + ")";
      return out;
    }
    why = refusal ? c.calibration_file + ": " + *refusal : loaded.status().message();
  }
  out.set.config = pipeline_config(c, defaults);
  out.set.cal_id = 0;
  out.set.calibrated = false;
  out.message = "UNCALIBRATED: " + why +
                "; navigating with nominal defaults, the CAN status says uncalibrated";
  return out;
}

ReloadWorker::LoadFn calibration_reloader(const FwConfig& c,
                                          std::optional<std::array<double, 6>> board_lsb,
                                          std::string device_in_use) {
  return [c, board_lsb, in_use = std::move(device_in_use)](
             const ReloadRequest& request) mutable -> ReloadOutcome {
    if (c.calibration_file.empty()) {
      spdlog::error("calibration reload: no calibration file configured");
      return {};
    }
    auto loaded = calib_file::load_calibration_file(c.calibration_file);
    if (!loaded.is_ok()) {
      spdlog::error("calibration reload failed, the calibration in use stays: {}",
                    loaded.status().message());
      return {};
    }
    if (auto why = calibration_refusal(c, loaded.value(), board_lsb ? &*board_lsb : nullptr)) {
      spdlog::error("calibration reload refused, the calibration in use stays: {}: {}",
                    c.calibration_file, *why);
      return {};
    }
    // Another board's file at this path (copied over it, a mixed-up deployment) would scale and
    // align every channel with that board's errors while the navigation runs: refused unless the
    // command says it is meant (forced). A board on its nominal defaults takes its first
    // calibration whatever its id.
    const std::string& id = loaded.value().device_id;
    if (!in_use.empty() && id != in_use) {
      if (!request.forced) {
        spdlog::error(
            "calibration reload refused, the calibration in use stays: {}: device_id \"{}\" is "
            "not this board's (\"{}\"); send ReloadCalibration forced to take it",
            c.calibration_file, printable_text(id), printable_text(in_use));
        ReloadOutcome refused;
        refused.other_device = true;
        return refused;
      }
      spdlog::warn("calibration reload forced: {}: device_id \"{}\" replaces \"{}\"",
                   c.calibration_file, printable_text(id), printable_text(in_use));
    }
    CalibrationSet s;
    s.config = pipeline_config(c, loaded.value());
    s.cal_id = calib_file::cal_id_of(loaded.value());
    s.calibrated = true;
    in_use = id;
    return ReloadOutcome{s, false};
  };
}

}  // namespace gfins::app
