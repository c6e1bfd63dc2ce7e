// Google Benchmark: replay throughput of the navigation core from a raw-sample recording
// (host_sim/replay.hpp), in samples/s and in multiples of real time at 1 kHz. Goals: ≥ 1000× real
// time on one core (issue "Host simulation", Replay), ≥ 5000× including the decoding of the
// file. Nothing here asserts a time.
//
// The recording is made once, before timing: 10 s at 1 kHz of the manoeuvre trajectory
// (make_maneuver, preceded by 0.5 s at rest for alignment) through SensorArrayModel with Table 6
// errors and QA-1100 class noise and AdcModel, encoded to the file format in memory. Timed:
//   BM_Replay<T>           decoded samples → NavLoop → NavPipeline<T> (exact compensator),
//                          including the per-sample FNV-1a hash of the output;
//   BM_DecodeAndReplay<T>  the same, starting from the file bytes (CRC checks and decoding);
//   BM_Decode              file bytes → samples only;
//   BM_ReplayFile<T>       the whole path of `gfins-replay`: replay_recording() opens the .gfr
//                          file written to the temporary folder at set-up, reads it block by
//                          block, checks every CRC, decodes and navigates (goal: ≥ 5000×
//                          real time at 1 kHz on one core, i.e. ≥ 5 M samples/s);
//   BM_ReadFile            the same file read and decoded block by block, no navigation;
//   BM_ReadFileAndNavigate<T>  the file read and decoded by RecordingReader, each sample handed
//                          to NavPipeline<T>::process() directly: what replay_recording() does
//                          without NavLoop's report and FNV-1a output hash (which is byte-serial
//                          and costs about as much as the navigation itself in double).
//   BM_RecordInLoop        the board recorder's loop side per sample: encode + queue push;
//   BM_RecorderWrites      its writer side: queue → blocks with CRC → file (page cache).
// The file is read from the page cache after the first iteration, as when a recording is
// replayed again; the first read from the disk itself is not what is measured.
//
//   build/<dir>/tests/bench/gfins_replay_bench --benchmark_repetitions=5
#include <benchmark/benchmark.h>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "gfins/app/record_queue.hpp"
#include "gfins/app/recorder.hpp"
#include "gfins/host_sim/adc_model.hpp"
#include "gfins/host_sim/recording.hpp"
#include "gfins/host_sim/replay.hpp"
#include "gfins/host_sim/sensor_model.hpp"
#include "gfins/host_sim/trajectory.hpp"
#include "gfins/nav_core/pipeline.hpp"

namespace gfins::sim {
namespace {

constexpr double kRateHz = 1000.0;
constexpr double kRhoM = 0.1;
constexpr double kRestS = 0.5;
constexpr std::uint32_t kSamples = 10000;  // 10 s of data per iteration
constexpr std::uint32_t kAlignSamples = 400;

struct Data {
  ArrayErrors errors = SensorArrayModel::paper_table6();
  AdcModel adc{AdcConfig{}};
  std::vector<RawSample> samples;
  std::vector<std::uint8_t> file;

  Data() {
    for (auto& e : errors.sensors) e.noise_g = 70e-6;  // QA-1100 class, docs/sensor-model.md
    const auto gravity = nav::GravityModel<double>::constant(nav::kStandardGravity);
    SensorArrayModel sensors(nav::table1_geometry(kRhoM), errors, gravity, kRateHz, 7);
    const auto rest = make_rest(Quatd::Identity());
    const auto moving = make_maneuver(0.3);
    for (std::uint32_t i = 0; i < kSamples; ++i) {
      const double t_s = i / kRateHz;
      const TruthState x = t_s < kRestS ? rest->at(t_s) : moving->at(t_s - kRestS);
      samples.push_back(adc.sample(sensors.volts(x), i));
    }
    RecordingHeader h;
    h.sample_rate_hz = kRateHz;
    h.volts_per_count.fill(adc.volts_per_count());
    h.geometry = nav::table1_geometry(kRhoM);
    file = encode_recording(h, samples).value();
    path = (std::filesystem::temp_directory_path() /
            ("gfins_replay_bench_" + std::to_string(std::random_device{}()) + ".gfr"))
               .string();
    if (!write_recording(path, h, samples).is_ok()) path.clear();
  }
  ~Data() {
    if (!path.empty()) {
      std::error_code ignored;  // a temporary file left behind is not worth a failure
      std::filesystem::remove(path, ignored);
    }
  }
  Data(const Data&) = delete;
  Data& operator=(const Data&) = delete;

  std::string path;  // the recording on disk (empty if it could not be written)

  template <typename T>
  nav::PipelineConfig<T> config() const {
    nav::PipelineConfig<T> c;
    c.nominal = nav::table1_geometry(static_cast<T>(kRhoM));
    c.sample_rate_hz = kRateHz;
    c.alignment_samples = kAlignSamples;
    c.compensator = nav::CompensatorKind::kExact;
    for (std::size_t i = 0; i < 6; ++i) {
      c.misalignment.orientation.beta[i] = static_cast<T>(errors.misalignment.orientation.beta[i]);
      c.misalignment.orientation.alpha[i] =
          static_cast<T>(errors.misalignment.orientation.alpha[i]);
      c.front_end.volts_per_count[i] = static_cast<T>(adc.volts_per_count());
      c.front_end.scale_v_per_g[i] = static_cast<T>(errors.sensors[i].scale_v_per_g);
      c.front_end.bias_g[i] = static_cast<T>(errors.sensors[i].bias_g);
    }
    return c;
  }
};

const Data& data() {
  static const Data d;
  return d;
}

void set_rates(benchmark::State& state, std::uint64_t navigating) {
  const auto n = static_cast<double>(state.iterations()) * kSamples;
  state.SetItemsProcessed(static_cast<std::int64_t>(n));
  state.counters["x_realtime"] = benchmark::Counter(n / kRateHz, benchmark::Counter::kIsRate);
  state.counters["navigating"] = static_cast<double>(navigating);
}

template <typename T>
void BM_Replay(benchmark::State& state) {
  const Data& d = data();
  const auto cfg = d.config<T>();
  std::uint64_t navigating = 0;
  for (auto _ : state) {
    nav::NavPipeline<T> p;
    if (!p.configure(cfg).is_ok()) state.SkipWithError("pipeline configuration failed");
    const NavReport r = replay(p, std::span<const RawSample>(d.samples));
    navigating = r.navigating;
    benchmark::DoNotOptimize(r.output_hash);
  }
  set_rates(state, navigating);
}

template <typename T>
void BM_DecodeAndReplay(benchmark::State& state) {
  const Data& d = data();
  const auto cfg = d.config<T>();
  std::uint64_t navigating = 0;
  for (auto _ : state) {
    const auto rec = decode_recording(d.file);
    if (!rec.is_ok()) state.SkipWithError("decode failed");
    nav::NavPipeline<T> p;
    if (!p.configure(cfg).is_ok()) state.SkipWithError("pipeline configuration failed");
    const NavReport r = replay(p, std::span<const RawSample>(rec.value().samples));
    navigating = r.navigating;
    benchmark::DoNotOptimize(r.output_hash);
  }
  set_rates(state, navigating);
}

void BM_Decode(benchmark::State& state) {
  const Data& d = data();
  for (auto _ : state) {
    const auto rec = decode_recording(d.file);
    benchmark::DoNotOptimize(rec.value().samples.data());
  }
  set_rates(state, 0);
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * d.file.size()));
}

template <typename T>
void BM_ReplayFile(benchmark::State& state) {
  const Data& d = data();
  if (d.path.empty()) {
    state.SkipWithError("could not write the recording to the temporary folder");
    return;
  }
  const auto cfg = d.config<T>();
  std::uint64_t navigating = 0;
  for (auto _ : state) {
    nav::NavPipeline<T> p;
    if (!p.configure(cfg).is_ok()) state.SkipWithError("pipeline configuration failed");
    const auto r = replay_recording(d.path, p);
    if (!r.is_ok()) {
      state.SkipWithError(r.error().message.c_str());
      break;
    }
    navigating = r.value().navigating;
    benchmark::DoNotOptimize(r.value().output_hash);
  }
  set_rates(state, navigating);
}

void BM_ReadFile(benchmark::State& state) {
  const Data& d = data();
  if (d.path.empty()) {
    state.SkipWithError("could not write the recording to the temporary folder");
    return;
  }
  std::vector<RawSample> block;
  for (auto _ : state) {
    auto reader = RecordingReader::open(d.path);
    if (!reader.is_ok()) {
      state.SkipWithError(reader.error().message.c_str());
      break;
    }
    std::uint64_t sum = 0;
    for (;;) {
      const auto more = reader.value().next_block(block);
      if (!more.is_ok() || !more.value()) break;
      for (const auto& x : block) sum += static_cast<std::uint32_t>(x.counts[0]);
    }
    benchmark::DoNotOptimize(sum);
  }
  set_rates(state, 0);
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * d.file.size()));
}

template <typename T>
void BM_ReadFileAndNavigate(benchmark::State& state) {
  const Data& d = data();
  if (d.path.empty()) {
    state.SkipWithError("could not write the recording to the temporary folder");
    return;
  }
  const auto cfg = d.config<T>();
  std::vector<RawSample> block;
  std::uint64_t navigating = 0;
  for (auto _ : state) {
    nav::NavPipeline<T> p;
    if (!p.configure(cfg).is_ok()) state.SkipWithError("pipeline configuration failed");
    auto reader = RecordingReader::open(d.path);
    if (!reader.is_ok()) {
      state.SkipWithError(reader.error().message.c_str());
      break;
    }
    navigating = 0;
    for (;;) {
      const auto more = reader.value().next_block(block);
      if (!more.is_ok() || !more.value()) break;
      for (const auto& x : block) {
        navigating += p.process(x) == nav::PipelinePhase::kNavigating ? 1 : 0;
      }
    }
    benchmark::DoNotOptimize(p.state());
  }
  set_rates(state, navigating);
}

// The board's recorder (gfins-fw --record, firmware/app/recorder.hpp), per sample: what the loop
// pays (encode the 32-byte record, push it into the queue; the pop stands for the writer thread)
// and what the writer thread does (pop, assemble blocks with their CRC, write them to a file in the
// temporary folder).
void BM_RecordInLoop(benchmark::State& state) {
  const Data& d = data();
  auto q = std::make_unique<app::RecordQueue>();
  app::RecordSlot slot;
  for (auto _ : state) {
    for (const RawSample& s : d.samples) {
      benchmark::DoNotOptimize(app::record_sample(*q, s));
      benchmark::DoNotOptimize(q->pop(slot));
    }
  }
  set_rates(state, 0);
}

void BM_RecorderWrites(benchmark::State& state) {
  const Data& d = data();
  const std::string path =
      (std::filesystem::temp_directory_path() / "gfins_bench_recorder.gfr").string();
  recording::Header h;
  h.volts_per_count.fill(1e-6);
  h.geometry = nav::table1_geometry(kRhoM);
  for (auto _ : state) {
    app::Recorder::Opened opened = app::Recorder::open(path, h);
    if (!opened.recorder) {
      state.SkipWithError(opened.error.c_str());
      break;
    }
    for (std::size_t i = 0; i < d.samples.size(); ++i) {
      (void)app::record_sample(opened.recorder->queue(), d.samples[i]);
      if ((i & 1023u) == 1023u) opened.recorder->drain();
    }
    if (!opened.recorder->stop().empty()) state.SkipWithError("recorder write failed");
  }
  std::filesystem::remove(path);
  set_rates(state, 0);
}

BENCHMARK(BM_Replay<float>)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Replay<double>)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DecodeAndReplay<float>)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DecodeAndReplay<double>)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Decode)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ReplayFile<float>)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ReplayFile<double>)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ReadFile)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ReadFileAndNavigate<float>)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ReadFileAndNavigate<double>)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RecordInLoop)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_RecorderWrites)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace gfins::sim

BENCHMARK_MAIN();
