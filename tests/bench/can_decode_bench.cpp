// gfins-can decoder throughput on a one-hour candump log of the default 100 Hz output (about
// 902 frames/s, 3.25 million lines): the whole path of `gfins-can decode LOG --view none` —
// line reading, candump parsing, CRC, counters and drop checks, signal decoding into epochs.
// Reports lines/s and the multiple of real time (one hour of bus traffic / decode time).
#include <benchmark/benchmark.h>

#include <cstdio>

#include "decoder.hpp"
#include "generate.hpp"
#include "gfins/can/message_table.hpp"
#include "host_io.hpp"

namespace {

constexpr double kLogSeconds = 3600.0;

/// The one-hour log, written once (by the real Publisher) into an anonymous temporary file.
std::FILE* hour_log() {
  static std::FILE* f = [] {
    std::FILE* t = std::tmpfile();
    if (t == nullptr || !gfins::can_tool::write_synthetic_log(
                            t, kLogSeconds, gfins::can::kDefaultSampleRateHz, 0)) {
      std::fputs("can_decode_bench: cannot write the temporary log\n", stderr);
      std::abort();
    }
    return t;
  }();
  return f;
}

void BM_DecodeOneHourLog(benchmark::State& state) {
  std::FILE* f = hour_log();
  std::uint64_t lines = 0;
  std::uint64_t epochs = 0;
  for (auto _ : state) {
    std::rewind(f);
    gfins::can_tool::StreamDecoder dec(
        [&](const gfins::can_tool::DecodedEpoch& e) { benchmark::DoNotOptimize(e.values.data()); },
        nullptr);
    gfins::can_tool::for_each_line(
        f, [&](std::uint64_t n, std::string_view l) { dec.feed_line(n, l); });
    dec.finish();
    lines = dec.summary().lines;
    epochs = dec.summary().epochs;
    if (dec.summary().total_issues() != 0) state.SkipWithError("the clean log reported problems");
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(lines) * state.iterations());
  state.counters["lines"] = static_cast<double>(lines);
  state.counters["epochs"] = static_cast<double>(epochs);
  // Seconds of bus traffic decoded per second of decoding.
  state.counters["x_real_time"] = benchmark::Counter(
      kLogSeconds * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_DecodeOneHourLog)->Unit(benchmark::kSecond)->Iterations(3);

}  // namespace

BENCHMARK_MAIN();
