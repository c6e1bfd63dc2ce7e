// End to end on the simulated board: the NavState stream the sample loop hands to the publisher
// equals, bit for bit, a host-only run of the navigation core (NavPipeline<float> driven directly
// with the same RawSamples). The reference core is configured HERE, field by field, from the
// documented meaning of the configuration keys (docs/firmware.md) and of the calibration file
// (docs/calibration-file.md), never through the firmware's own mapping (pipeline_config,
// loop_options, calib_file::apply_to): any difference means the firmware changed, reordered,
// dropped or duplicated a sample, or configured the core differently from what the
// configuration and calibration say. Non-default configurations (a calibration file written
// here, every navigation key changed) make a mapping bug visible.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <numbers>
#include <sstream>

#include "gfins/calib_file/calibration_file.hpp"
#include "gfins/host_sim/nav_loop.hpp"
#include "sim_rig.hpp"
#include "support/temp_dir.hpp"

namespace gfins::app {
namespace {

using testing::SimRig;

std::uint32_t bits(float x) { return std::bit_cast<std::uint32_t>(x); }

// Compares the navigation values bit for bit; reports the first difference.
::testing::AssertionResult same_values(const nav::NavState<float>& a,
                                       const nav::NavState<float>& b) {
  const auto cmp = [&](const char* what, const float* x, const float* y, int n) {
    for (int i = 0; i < n; ++i) {
      if (bits(x[i]) != bits(y[i])) {
        return ::testing::AssertionFailure() << what << "[" << i << "] differs at seq " << a.seq
                                             << ": " << x[i] << " vs " << y[i];
      }
    }
    return ::testing::AssertionSuccess();
  };
  for (auto r :
       {cmp("q_nb", a.q_nb.coeffs().data(), b.q_nb.coeffs().data(), 4),
        cmp("w_b", a.w_b.data(), b.w_b.data(), 3),
        cmp("wdot_b", a.wdot_b.data(), b.wdot_b.data(), 3),
        cmp("f_b", a.f_b.data(), b.f_b.data(), 3), cmp("a_n", a.a_n.data(), b.a_n.data(), 3),
        cmp("v_n", a.v_n.data(), b.v_n.data(), 3), cmp("r_n", a.r_n.data(), b.r_n.data(), 3)}) {
    if (!r) return r;
  }
  return ::testing::AssertionSuccess();
}

// ---- The reference configuration, from the documents -------------------------------------

// The one unit conversion the documents state: degrees → radians, one multiplication by π/180
// in double, then rounded to float (docs/calibration-file.md, "Why degrees in memory too").
float rad(double deg) { return static_cast<float>(deg * (std::numbers::pi / 180.0)); }

// calibration geometry name = 'table1': the paper's Table 1 with half-size rho_m (positions
// ρ_j and sensitive axes θ_j written out from the paper, Hung, Fang & Lee 2007, Table 1).
nav::ArrayGeometry<float, 6> paper_table1(double rho_m) {
  const double r = rho_m;
  const double k = 0.70710678118654752;  // 1/√2
  const std::array<std::array<double, 3>, 6> pos = {
      {{0, 0, -r}, {0, -r, 0}, {-r, 0, 0}, {r, 0, 0}, {0, r, 0}, {0, 0, r}}};
  const std::array<std::array<double, 3>, 6> axis = {
      {{k, k, 0}, {k, 0, k}, {0, k, k}, {0, -k, k}, {-k, 0, k}, {-k, k, 0}}};
  nav::ArrayGeometry<float, 6> g;
  for (std::size_t j = 0; j < 6; ++j) {
    g.rho_b[j] = nav::Vec3<double>(pos[j][0], pos[j][1], pos[j][2]).cast<float>();
    g.theta_b[j] = nav::Vec3<double>(axis[j][0], axis[j][1], axis[j][2]).cast<float>();
  }
  return g;
}

// The calibration part, key by key (docs/calibration-file.md): sensor.N.adc_lsb_v_per_count,
// scale_v_per_g and bias_g feed the front end of sensor N (paper eq. (21)); gravity.local_mps2
// is the g of V/g and of the biases; orientation.{beta,alpha}.*_deg are the six angles of each
// set in degrees (eqs. (14)/(15)); sensor.N.location_error_m is Δρ_N (eq. (19)).
void calibration_part(const calib_file::CalibrationData& d, nav::PipelineConfig<float>& e) {
  EXPECT_EQ(d.geometry.kind, calib_file::GeometryKind::kTable1);  // the only one used here
  e.nominal = paper_table1(d.geometry.rho_m);
  for (std::size_t j = 0; j < 6; ++j) {
    e.front_end.volts_per_count[j] = static_cast<float>(d.sensors[j].adc_lsb_v_per_count);
    e.front_end.scale_v_per_g[j] = static_cast<float>(d.sensors[j].scale_v_per_g);
    e.front_end.bias_g[j] = static_cast<float>(d.sensors[j].bias_g);
    const auto& dr = d.sensors[j].location_error_m;
    e.misalignment.drho_b[j] = nav::Vec3<double>(dr[0], dr[1], dr[2]).cast<float>();
  }
  e.front_end.gravity_mps2 = static_cast<float>(d.gravity_mps2);
  for (std::size_t i = 0; i < 6; ++i) {
    e.misalignment.orientation.beta[i] = rad(d.beta.angle_deg[i]);
    e.misalignment.orientation.alpha[i] = rad(d.alpha.angle_deg[i]);
  }
}

// What the loop ended up with, field by field against the reference: a readable first failure
// before the bit-for-bit stream comparison.
void expect_same_config(const nav::PipelineConfig<float>& got,
                        const nav::PipelineConfig<float>& want) {
  const auto same = [](const nav::Vec3<float>& a, const nav::Vec3<float>& b) {
    return bits(a.x()) == bits(b.x()) && bits(a.y()) == bits(b.y()) && bits(a.z()) == bits(b.z());
  };
  for (std::size_t j = 0; j < 6; ++j) {
    EXPECT_TRUE(same(got.nominal.rho_b[j], want.nominal.rho_b[j])) << "rho_b " << j;
    EXPECT_TRUE(same(got.nominal.theta_b[j], want.nominal.theta_b[j])) << "theta_b " << j;
    EXPECT_EQ(bits(got.front_end.volts_per_count[j]), bits(want.front_end.volts_per_count[j]))
        << "volts_per_count " << j;
    EXPECT_EQ(bits(got.front_end.scale_v_per_g[j]), bits(want.front_end.scale_v_per_g[j]))
        << "scale_v_per_g " << j;
    EXPECT_EQ(bits(got.front_end.bias_g[j]), bits(want.front_end.bias_g[j])) << "bias_g " << j;
    EXPECT_TRUE(same(got.misalignment.drho_b[j], want.misalignment.drho_b[j])) << "drho " << j;
    EXPECT_EQ(bits(got.misalignment.orientation.beta[j]),
              bits(want.misalignment.orientation.beta[j]))
        << "beta " << j;
    EXPECT_EQ(bits(got.misalignment.orientation.alpha[j]),
              bits(want.misalignment.orientation.alpha[j]))
        << "alpha " << j;
  }
  EXPECT_EQ(bits(got.front_end.gravity_mps2), bits(want.front_end.gravity_mps2));
  EXPECT_EQ(got.compensator, want.compensator);
  EXPECT_EQ(got.gravity.kind(), want.gravity.kind());
  EXPECT_EQ(bits(got.gravity.magnitude_at_origin()), bits(want.gravity.magnitude_at_origin()));
  EXPECT_EQ(bits(got.gravity.g_down(-1000.0f)), bits(want.gravity.g_down(-1000.0f)));
  EXPECT_EQ(bits(got.max_condition), bits(want.max_condition));
  EXPECT_EQ(bits(got.sample_rate_hz), bits(want.sample_rate_hz));
  EXPECT_EQ(got.alignment_samples, want.alignment_samples);
  EXPECT_EQ(bits(got.heading_rad), bits(want.heading_rad));
  EXPECT_TRUE(same(got.r0_n, want.r0_n)) << "r0_n";
}

// The host-only reference: the core configured with `want`, the same samples, the core's one
// entry per sample.
std::vector<nav::NavState<float>> host_only_run(const SimRig& rig,
                                                const nav::PipelineConfig<float>& want) {
  auto p = std::make_unique<nav::NavPipeline<float>>();
  EXPECT_TRUE(p->configure(want).is_ok());
  std::vector<nav::NavState<float>> out;
  out.reserve(rig.tap->samples().size());
  for (const RawSample& s : rig.tap->samples()) {
    p->process(s);
    out.push_back(p->state());
  }
  return out;
}

void expect_bit_exact(SimRig& rig, const nav::PipelineConfig<float>& want) {
  expect_same_config(rig.loop->pipeline().config(), want);
  const auto& epochs = rig.recording->epochs();
  const auto reference = host_only_run(rig, want);
  ASSERT_EQ(epochs.size(), reference.size());
  ASSERT_EQ(rig.recording->overflow(), 0u);
  const auto& samples = rig.tap->samples();
  std::size_t stepped = 0;
  for (std::size_t i = 0; i < epochs.size(); ++i) {
    const nav::NavState<float>& e = epochs[i].nav;
    // Every epoch is stamped with the sample just read ...
    ASSERT_EQ(e.seq, samples[i].seq) << "epoch " << i;
    ASSERT_EQ(e.t_ns, samples[i].t_ns) << "epoch " << i;
    // ... and carries the core's values after that sample, bit for bit.
    ASSERT_TRUE(same_values(e, reference[i])) << "epoch " << i;
    if (reference[i].seq == samples[i].seq) {
      // The core stepped on this sample: its status too.
      ASSERT_EQ(e.status, reference[i].status) << "epoch " << i;
      ++stepped;
    } else {
      // The core held its state (aligning, or a rejected sample, flagged as such).
      const bool rejected = (samples[i].flags & sample_flags::kCrcError) != 0 ||
                            (samples[i].flags & sample_flags::kSaturated) != 0;
      ASSERT_EQ((e.status & nav::nav_status::kInputInvalid) != 0, rejected) << "epoch " << i;
    }
  }
  // Alignment takes alignment_samples; every later valid sample is a step (a few are rejected
  // in the faulty run: at most 100 there).
  EXPECT_GT(stepped + want.alignment_samples + 100, epochs.size());
}

// The defaults of docs/firmware.md on the simulated board with calibration.file = "": the
// factory calibration (the scenario's true parameters) and its compensator
// (navigation.compensator = "calibration"), the calibration's local gravity (navigation.gravity =
// "calibration": the scenario's g at its origin), 1000 Hz, alignment 1 s = 1000 samples, heading
// 0, position [0, 0, 0].
nav::PipelineConfig<float> documented_defaults(const calib_file::CalibrationData& factory) {
  nav::PipelineConfig<float> e;
  calibration_part(factory, e);
  e.compensator = factory.compensator;
  e.gravity = nav::GravityModel<float>::constant(static_cast<float>(factory.gravity_mps2));
  e.max_condition = 100.0f;  // not configurable: the core's documented default
  e.sample_rate_hz = 1000.0f;
  e.alignment_samples = 1000;
  e.heading_rad = 0.0f;
  e.r0_n = nav::Vec3<float>::Zero();
  return e;
}

TEST(EndToEnd, RestScenarioNavStreamEqualsHostOnlyCoreBitForBit) {
  // Given the rest scenario (alignment, then 4 s of navigation) on the simulated board
  SimRig rig("rest", 5.0);
  rig.configure();
  // When the firmware loop runs it to the end
  rig.run();
  // Then every sample was read and handed on once, in order
  ASSERT_EQ(rig.tap->samples().size(), rig.samples);
  EXPECT_EQ(rig.loop->health().samples, rig.samples);
  EXPECT_EQ(rig.loop->mode(), can::Mode::kNavigating);
  // and the navigation states equal the core's own run on the same samples
  EXPECT_EQ(rig.factory.compensator, nav::CompensatorKind::kPaper);  // rest.toml [compensator]
  expect_bit_exact(rig, documented_defaults(rig.factory));
}

TEST(EndToEnd, FaultyRunStillEqualsHostOnlyCoreOnTheSamplesRead) {
  // Faults change which samples arrive and which are rejected; the core must still see exactly
  // what it would see when driven directly with those samples.
  sim_board::FaultPlan f;
  f.crc_error_at = {1500, 2500};
  f.missing_edges = {1800, 1801};
  f.saturated_channel = 4;
  f.saturated_from = 3000;
  f.saturated_until = 3010;
  SimRig rig("rest", 4.0, f);
  rig.configure();
  rig.run();
  EXPECT_EQ(rig.tap->samples().size(), rig.samples - 2);
  expect_bit_exact(rig, documented_defaults(rig.factory));
}

TEST(EndToEnd, FlaggedSaturatedFramesAreRejectedAsTheHostLoopRejectsThem) {
  // A frame its producer flagged saturated (an input beyond range, clipped) whose counts are not
  // on a rail: no chip of the simulated board makes one, a recording can hold one. The board's
  // loop and the host's loop (gfins-sim, gfins-replay) must reject the same samples.
  SimRig rig("rest", 3.0);
  rig.configure();
  rig.run_cycles(1500);  // aligned and navigating
  ASSERT_EQ(rig.loop->mode(), can::Mode::kNavigating);
  constexpr std::uint32_t kFlagged = 5;
  rig.faulty->add_flags(kFlagged, sample_flags::kSaturated);
  rig.run();
  const auto& samples = rig.tap->samples();
  std::uint32_t flagged_off_rails = 0;
  for (const RawSample& s : samples) {
    if ((s.flags & sample_flags::kSaturated) == 0) continue;
    bool on_rail = false;
    for (const std::int32_t c : s.counts) on_rail = on_rail || c >= kAdcCodeMax || c <= kAdcCodeMin;
    if (!on_rail) ++flagged_off_rails;
  }
  ASSERT_EQ(flagged_off_rails, kFlagged);  // the case the rails alone would let through
  // The host loop over the same samples (oracle: its report, which counts the flagged frames by
  // their flag) ...
  nav::NavPipeline<float> host;
  ASSERT_TRUE(host.configure(rig.loop->pipeline().config()).is_ok());
  const sim::NavReport report = sim::run_samples<float>(host, samples);
  EXPECT_EQ(report.flagged_saturated, kFlagged);
  EXPECT_EQ(report.rejected, kFlagged);
  // ... and the board's loop reject exactly those, and say so on the bus.
  EXPECT_EQ(rig.loop->health().rejected_samples, kFlagged);
  EXPECT_EQ(rig.loop->pipeline().counters().rejected, kFlagged);
  std::uint32_t invalid_epochs = 0;
  for (const can::Epoch& e : rig.recording->epochs()) {
    if ((e.nav.status & nav::nav_status::kInputInvalid) != 0) ++invalid_epochs;
  }
  EXPECT_EQ(invalid_epochs, kFlagged);
  // The navigation equals the host-only core's, bit for bit, sample by sample.
  expect_bit_exact(rig, documented_defaults(rig.factory));
}

// A calibration of this board written out here (plausible QA-1100 values, none equal to the
// scenario's truth, so that taking the factory calibration instead of the file shows).
calib_file::CalibrationData written_calibration() {
  calib_file::CalibrationData d;
  d.device_id = "e2e-board-7";
  d.created_utc = "2026-11-23T12:00:00Z";
  d.source = "end_to_end_test: written by hand";
  d.geometry.kind = calib_file::GeometryKind::kTable1;
  d.geometry.rho_m = 0.1;
  // ADS131M06 LSB at the sensor: Vref 1.2 V / (gain 1 · 2^23) at the pins (datasheet §8.3.2),
  // times 8.33 for the load-resistor divider of the QA-1100 front end.
  const double lsb = 1.2 / 8388608.0 * 8.33;
  const std::array<double, 6> scale = {1.331, 1.328, 1.335, 1.329, 1.332, 1.327};      // V/g
  const std::array<double, 6> bias = {1.0e-4, -2.0e-4, 3.0e-4, 0.0, -1.5e-4, 2.5e-4};  // g
  for (std::size_t j = 0; j < 6; ++j) {
    d.sensors[j].adc_lsb_v_per_count = lsb;
    d.sensors[j].scale_v_per_g = scale[j];
    d.sensors[j].bias_g = bias[j];
  }
  d.sensors[1].location_error_m = {0.001, 0.0, -0.0005};
  d.sensors[4].location_error_m = {0.0, -0.0008, 0.0};
  d.beta.angle_deg = {0.10, -0.05, 0.08, 0.02, -0.07, 0.03};
  d.alpha.angle_deg = {-0.04, 0.06, 0.01, -0.09, 0.05, -0.02};
  d.compensator = nav::CompensatorKind::kPaper;
  d.gravity_mps2 = 9.7893;
  d.gravity_source = "given";
  return d;
}

// "table.key" → value text of a TOML file as written (comments and indentation stripped): to
// read back under which documented key each number of the reference sits.
std::map<std::string, std::string> keys_of(const std::string& text) {
  std::map<std::string, std::string> out;
  std::istringstream in(text);
  std::string table;
  for (std::string line; std::getline(in, line);) {
    if (const auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
    const auto b = line.find_first_not_of(' ');
    if (b == std::string::npos) continue;
    line = line.substr(b, line.find_last_not_of(' ') + 1 - b);
    if (line.front() == '[') {
      table = line.substr(1, line.size() - 2);
      continue;
    }
    const auto eq = line.find(" = ");
    if (eq != std::string::npos) {
      out[(table.empty() ? "" : table + ".") + line.substr(0, eq)] = line.substr(eq + 3);
    }
  }
  return out;
}

// Loads the configuration text through the firmware's reader and the calibration through its
// start-up, exactly as gfins-fw does, into the rig.
void configure_from(SimRig& rig, const std::string& toml) {
  const ConfigResult parsed = parse_config(toml, "e2e.toml");
  ASSERT_TRUE(parsed.ok()) << parsed.error;
  rig.config = *parsed.config;
  const StartupCalibration cal = load_calibration(rig.config, rig.factory, &rig.factory);
  ASSERT_TRUE(cal.from_file) << cal.message;
  rig.cal = cal.set;
  rig.configure();
}

TEST(EndToEnd, NonDefaultConfigurationAndCalibrationFileReachTheCoreAsDocumented) {
  // Given a calibration file and a configuration that changes every navigation key
  const testing::TempDir dir("gfins-e2e");
  const std::string cal_path = (dir.path() / "board7.toml").string();
  const calib_file::CalibrationData cal = written_calibration();
  ASSERT_TRUE(calib_file::save_calibration_file(cal_path, cal).is_ok());
  // The file carries the values under the keys calibration_part() reads them from
  // (docs/calibration-file.md): the reference is tied to the documented keys, not to the struct.
  std::ifstream saved(cal_path);
  const auto keys = keys_of(std::string(std::istreambuf_iterator<char>(saved), {}));
  EXPECT_EQ(keys.at("compensator"), "'paper'");
  EXPECT_EQ(keys.at("gravity.local_mps2"), "9.7893");
  EXPECT_EQ(keys.at("orientation.beta.xy_deg"), "0.1");
  EXPECT_EQ(keys.at("orientation.beta.xz_deg"), "-0.05");
  EXPECT_EQ(keys.at("orientation.alpha.yz_deg"), "-0.09");
  EXPECT_EQ(keys.at("sensor.2.location_error_m"), "[ 0.001, 0.0, -5e-04 ]");
  EXPECT_EQ(keys.at("sensor.5.location_error_m"), "[ 0.0, -8e-04, 0.0 ]");
  EXPECT_EQ(keys.at("sensor.3.scale_v_per_g"), "1.335");
  EXPECT_EQ(keys.at("sensor.3.bias_g"), "3e-04");
  EXPECT_EQ(keys.at("sensor.6.adc_lsb_v_per_count"), "1.1916160583496094e-06");
  EXPECT_EQ(keys.at("geometry.name"), "'table1'");
  EXPECT_EQ(keys.at("geometry.rho_m"), "0.1");
  SimRig rig("rest", 3.0);
  configure_from(rig,
                 "[board]\nkind = \"sim\"\n"
                 "[calibration]\nfile = \"" +
                     cal_path +
                     "\"\n"
                     "[navigation]\n"
                     "compensator = \"exact\"\n"  // overrides the file's "paper"
                     "gravity = \"constant\"\n"
                     "gravity_mps2 = 9.79\n"
                     "heading_deg = 30\n"
                     "position_m = [10, -5, 2.5]\n"
                     "alignment_s = 0.5\n");
  // When the firmware loop runs the scenario
  rig.run();
  ASSERT_EQ(rig.tap->samples().size(), rig.samples);
  // Then the core was configured as the documents say and its stream is the reference's
  nav::PipelineConfig<float> e;
  calibration_part(cal, e);  // the file's values, not the factory's
  e.compensator = nav::CompensatorKind::kExact;
  e.gravity = nav::GravityModel<float>::constant(9.79f);
  e.max_condition = 100.0f;
  e.sample_rate_hz = 1000.0f;
  e.alignment_samples = 500;  // 0.5 s at 1000 Hz
  e.heading_rad = rad(30.0);
  e.r0_n = nav::Vec3<float>(10.0f, -5.0f, 2.5f);
  expect_bit_exact(rig, e);
  // The calibration identity on the bus is the file's (its checksum, docs/calibration-file.md).
  EXPECT_EQ(rig.recording->epochs().back().cal_id, calib_file::cal_id_of(cal));
  // alignment_s = 0.5: the 500th sample (index 499) completes the alignment.
  EXPECT_EQ(rig.recording->epochs()[498].mode, can::Mode::kAligning);
  EXPECT_EQ(rig.recording->epochs()[499].mode, can::Mode::kNavigating);
}

TEST(EndToEnd, NormalGravityNoCompensatorAndHeadingReachTheCore) {
  // Given the factory calibration, the compensator switched off, WGS-84 normal gravity
  SimRig rig("rest", 2.0);
  configure_from(rig,
                 "[board]\nkind = \"sim\"\n[calibration]\nfile = \"\"\n"
                 "[navigation]\ncompensator = \"none\"\ngravity = \"normal\"\n"
                 "latitude_deg = 45\nheight_m = 100\nheading_deg = -90\n");
  rig.run();
  nav::PipelineConfig<float> e = documented_defaults(rig.factory);
  e.compensator = nav::CompensatorKind::kNone;
  // navigation.latitude_deg / height_m: geodetic latitude in degrees, ellipsoidal height in m
  e.gravity = nav::GravityModel<float>::normal(45.0 * std::numbers::pi / 180.0, 100.0);
  e.heading_rad = rad(-90.0);
  // The model so configured is WGS-84 normal gravity at 45°, 100 m: γ(45°) = 9.806199 m/s²
  // (Somigliana, NIMA TR8350.2 eq. 4-1) less the free-air 3.086e-6 m/s² per m, = 9.805890.
  constexpr double kGravityAt45Deg100M = 9.805890;
  constexpr double kGravityTolerance = 2e-6;  // the 7 digits above; float32 ulp at 9.8 is 1e-6
  EXPECT_NEAR(e.gravity.magnitude_at_origin(), kGravityAt45Deg100M, kGravityTolerance);
  expect_bit_exact(rig, e);
}

TEST(EndToEnd, EpochCarriesCalibrationIdentityAndMode) {
  SimRig rig("rest", 2.0);
  rig.configure();
  rig.run();
  const auto& epochs = rig.recording->epochs();
  ASSERT_FALSE(epochs.empty());
  // Alignment lasts alignment_s = 1 s = 1000 samples: aligning before, navigating after.
  EXPECT_EQ(epochs.front().mode, can::Mode::kAligning);
  EXPECT_EQ(epochs.front().status_bits & status_bits::kAligned, 0u);
  EXPECT_EQ(epochs.back().mode, can::Mode::kNavigating);
  EXPECT_NE(epochs.back().status_bits & status_bits::kAligned, 0u);
  EXPECT_EQ(epochs.back().status_bits & status_bits::kNominalCalibration, 0u);
  EXPECT_EQ(epochs.back().cal_id, calib_file::cal_id_of(rig.factory));
  EXPECT_NE(epochs.back().cal_id, 0u);
}

}  // namespace
}  // namespace gfins::app
