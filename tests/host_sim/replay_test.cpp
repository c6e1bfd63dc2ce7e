#include "gfins/host_sim/replay.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "gfins/host_sim/adc_model.hpp"
#include "gfins/host_sim/recording.hpp"
#include "gfins/host_sim/sensor_model.hpp"
#include "gfins/host_sim/trajectory.hpp"
#include "gfins/nav_core/pipeline.hpp"

namespace gfins::sim {
namespace {

constexpr double kRateHz = 1000.0;
constexpr double kRhoM = 0.1;
constexpr std::uint32_t kAlignSamples = 200;
constexpr std::uint32_t kSamples = 1500;  // 0.2 s aligning, 1.3 s navigating

// A recording of the array at rest (tilted, so every axis sees gravity) with QA-1100 class noise
// and Table 6 scale factors and biases, through the default ADC.
struct Fixture {
  ArrayErrors errors;
  AdcModel adc{AdcConfig{}};
  std::vector<RawSample> samples;

  Fixture() {
    errors = SensorArrayModel::paper_table6();
    errors.misalignment = {};
    for (auto& e : errors.sensors) e.noise_g = 1e-4;
    const auto gravity = nav::GravityModel<double>::constant(nav::kStandardGravity);
    SensorArrayModel sensors(nav::table1_geometry(kRhoM), errors, gravity, kRateHz, 2024);
    const auto traj = make_rest(Quatd(Eigen::AngleAxisd(0.2, Vec3d(1, 2, 0).normalized())));
    for (std::uint32_t i = 0; i < kSamples; ++i) {
      samples.push_back(adc.sample(sensors.volts(traj->at(i / kRateHz)), i));
    }
  }

  template <typename T>
  nav::PipelineConfig<T> config() const {
    nav::PipelineConfig<double> c;
    c.nominal = nav::table1_geometry(kRhoM);
    c.sample_rate_hz = kRateHz;
    c.alignment_samples = kAlignSamples;
    for (std::size_t j = 0; j < 6; ++j) {
      c.front_end.volts_per_count[j] = adc.volts_per_count();
      c.front_end.scale_v_per_g[j] = errors.sensors[j].scale_v_per_g;
      c.front_end.bias_g[j] = errors.sensors[j].bias_g;
    }
    nav::PipelineConfig<T> out;
    out.nominal = c.nominal.template cast<T>();
    out.front_end = c.front_end.template cast<T>();
    out.sample_rate_hz = static_cast<T>(c.sample_rate_hz);
    out.alignment_samples = c.alignment_samples;
    return out;
  }

  template <typename T>
  NavReport run(const std::vector<RawSample>& s) const {
    nav::NavPipeline<T> p;
    EXPECT_TRUE(p.configure(config<T>()).is_ok());
    return replay(p, std::span<const RawSample>(s));
  }
};

template <typename T>
class ReplayTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(ReplayTest, Scalars);

TYPED_TEST(ReplayTest, SameInputTwiceGivesTheSameHashAndAPerturbationChangesIt) {
  // Given one recorded stream,
  const Fixture f;
  // when it is replayed through two pipeline instances,
  const NavReport a = f.run<TypeParam>(f.samples);
  const NavReport b = f.run<TypeParam>(f.samples);
  // then both navigate for every sample after alignment and their outputs hash the same,
  EXPECT_EQ(a.samples, kSamples);
  EXPECT_EQ(a.navigating, kSamples - kAlignSamples + 1);
  EXPECT_EQ(a.output_hash, b.output_hash);
  EXPECT_NE(a.output_hash, Fnv1a64::kOffsetBasis);  // something was hashed
  EXPECT_TRUE(a.gaps.empty());
  // and one count changed by a single LSB after alignment gives another hash.
  auto perturbed = f.samples;
  perturbed[1000].counts[4] += 1;
  const NavReport c = f.run<TypeParam>(perturbed);
  EXPECT_NE(c.output_hash, a.output_hash);
}

TYPED_TEST(ReplayTest, ReplayFromAFileEqualsReplayFromMemory) {
  // Given the stream written to a recording and read back,
  const Fixture f;
  RecordingHeader h;
  h.sample_rate_hz = kRateHz;
  h.volts_per_count.fill(f.adc.volts_per_count());
  h.geometry = nav::table1_geometry(kRhoM);
  // One file per run and scalar: ctest runs the float and double cases at the same time.
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("gfins_replay_test_" + std::to_string(std::random_device{}()) + "_" +
                             std::to_string(sizeof(TypeParam)) + ".gfr"))
                               .string();
  ASSERT_TRUE(write_recording(path, h, f.samples).is_ok());
  const auto rec = read_recording(path);
  ASSERT_TRUE(rec.is_ok()) << rec.error().message;
  // when both are replayed, and the file once more streamed block by block,
  const NavReport from_file = f.run<TypeParam>(rec.value().samples);
  const NavReport from_memory = f.run<TypeParam>(f.samples);
  nav::NavPipeline<TypeParam> p;
  ASSERT_TRUE(p.configure(f.config<TypeParam>()).is_ok());
  const auto streamed = replay_recording(path, p);
  std::filesystem::remove(path);
  // then the outputs are bit-identical.
  ASSERT_TRUE(streamed.is_ok()) << streamed.error().message;
  EXPECT_EQ(from_file.output_hash, from_memory.output_hash);
  EXPECT_EQ(streamed.value().output_hash, from_memory.output_hash);
  EXPECT_EQ(from_file.navigating, from_memory.navigating);
  EXPECT_EQ(streamed.value().samples, kSamples);
}

TYPED_TEST(ReplayTest, GapsInTheSampleCounterAreReportedWithIndexAndSize) {
  // Given the stream with samples 700..702 and 1200 removed,
  const Fixture f;
  std::vector<RawSample> holes;
  for (const auto& s : f.samples) {
    if ((s.seq >= 700 && s.seq <= 702) || s.seq == 1200) continue;
    holes.push_back(s);
  }
  // when replayed,
  nav::NavPipeline<TypeParam> p;
  ASSERT_TRUE(p.configure(f.config<TypeParam>()).is_ok());
  std::vector<std::uint32_t> gap_states;
  const NavReport r = replay(p, std::span<const RawSample>(holes),
                             [&](std::uint64_t, const nav::NavState<TypeParam>& st) {
                               if (st.status & nav::nav_status::kSampleGap) {
                                 gap_states.push_back(st.seq);
                               }
                             });
  // then two gaps are reported, at the sample indices after each hole, with their sizes,
  ASSERT_EQ(r.gaps.size(), 2u);
  EXPECT_EQ(r.gaps[0].index, 700u);
  EXPECT_EQ(r.gaps[0].expected_seq, 700u);
  EXPECT_EQ(r.gaps[0].seq, 703u);
  EXPECT_EQ(r.gaps[0].missing, 3u);
  EXPECT_EQ(r.gaps[1].index, 1197u);
  EXPECT_EQ(r.gaps[1].missing, 1u);
  EXPECT_EQ(r.missed_samples, 4u);
  // and the pipeline marked the two states after the holes.
  EXPECT_EQ(gap_states, (std::vector<std::uint32_t>{703u, 1201u}));
}

TYPED_TEST(ReplayTest, CrcErrorSamplesArePassedAsInvalid) {
  // Given one sample flagged with a frame CRC error,
  const Fixture f;
  auto s = f.samples;
  s[900].flags |= sample_flags::kCrcError;
  // when replayed,
  nav::NavPipeline<TypeParam> p;
  ASSERT_TRUE(p.configure(f.config<TypeParam>()).is_ok());
  const NavReport r = replay(p, std::span<const RawSample>(s));
  // then the replayer and the pipeline both count it as rejected, and it is not navigated on.
  EXPECT_EQ(r.invalid, 1u);
  EXPECT_EQ(p.counters().rejected, 1u);
  EXPECT_EQ(r.navigating, kSamples - kAlignSamples);
}

TYPED_TEST(ReplayTest, SaturatedFlaggedSamplesAreRejectedLikeCrcErrors) {
  // Given one sample the converter flagged saturated whose counts are NOT on a rail (the flag is
  // the only sign: docs/replay.md says flagged frames are rejected),
  const Fixture f;
  auto s = f.samples;
  constexpr std::size_t kFlagged = 900;
  s[kFlagged].flags |= sample_flags::kSaturated;
  for (const auto c : s[kFlagged].counts) {
    ASSERT_LT(c, kAdcCodeMax);
    ASSERT_GT(c, kAdcCodeMin);
  }
  // when replayed,
  nav::NavPipeline<TypeParam> p;
  ASSERT_TRUE(p.configure(f.config<TypeParam>()).is_ok());
  std::vector<std::uint32_t> seqs;
  const NavReport r =
      replay(p, std::span<const RawSample>(s),
             [&](std::uint64_t, const nav::NavState<TypeParam>& st) { seqs.push_back(st.seq); });
  // then it is counted under its own flag, not as a CRC error, and rejected;
  EXPECT_EQ(r.flagged_saturated, 1u);
  EXPECT_EQ(r.invalid, 0u);
  EXPECT_EQ(r.rejected, 1u);
  EXPECT_EQ(p.counters().rejected, 1u);
  // no state is produced for it (the state before it is followed directly by the one after it),
  EXPECT_EQ(std::count(seqs.begin(), seqs.end(), static_cast<std::uint32_t>(kFlagged)), 0);
  EXPECT_EQ(std::count(seqs.begin(), seqs.end(), static_cast<std::uint32_t>(kFlagged + 1)), 1);
  // exactly as many states as with a CRC-error frame at the same place (the test above),
  EXPECT_EQ(r.navigating, kSamples - kAlignSamples);
  // and no gap is reported: the frame arrived, it only is not a measurement.
  EXPECT_TRUE(r.gaps.empty());
}

}  // namespace
}  // namespace gfins::sim
