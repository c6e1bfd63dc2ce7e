#include "hil.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <deque>
#include <map>
#include <memory>
#include <vector>

#include "decoder.hpp"
#include "gfins/app/config.hpp"
#include "gfins/app/sample_loop.hpp"
#include "gfins/app/startup.hpp"
#include "gfins/app/vehicle_frame.hpp"
#include "gfins/can/aiding_input.hpp"
#include "gfins/can/aiding_offer.hpp"
#include "gfins/drivers/ads131m06.hpp"
#include "gfins/drivers/lnx/hil_link.hpp"
#include "gfins/drivers/qa1100_front_end.hpp"
#include "gfins/host_sim/board/sim_board.hpp"
#include "gfins/host_sim/recording.hpp"
#include "gfins/host_sim/scenario.hpp"
#include "gfins/nav_core/pipeline.hpp"

namespace gfins::can_tool {
namespace {

namespace lnx = drivers::lnx;
constexpr std::int64_t kNsPerMs = 1000000;

// Roll, pitch, yaw (ZYX) of the quaternion as published (docs/can-interface.md): the standard
// formulas on the float quaternion's components, not renormalised (the core keeps |q| = 1 to a
// few float ulps; renormalising here would move an angle by up to ~1e-7 rad, a visible part of
// the 1e-4 rad step).
std::array<double, 3> euler_zyx(const nav::Quat<float>& qf) {
  const auto w = static_cast<double>(qf.w());
  const auto x = static_cast<double>(qf.x());
  const auto y = static_cast<double>(qf.y());
  const auto z = static_cast<double>(qf.z());
  return {std::atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y)),
          std::asin(std::clamp(2.0 * (w * y - z * x), -1.0, 1.0)),
          std::atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))};
}

struct Input {
  std::vector<RawSample> samples;
  std::vector<sim::RecordedFrame> frames;  // a recording's received CAN frames, in order
  std::string what;
  double rate_hz = 1000.0;
};

/// A recorded frame the link carries, with the cycle (sample index) the loop received it in.
struct CycleFrame {
  std::uint32_t cycle = 0;
  hal::CanFrame frame;
};

/// The recorded frames the firmware takes as aiding inputs (GNSS fixes, headings of its node and
/// identifier groups), each in the cycle of the sample it followed (docs/recording-format.md:
/// a frame after `samples_before` samples was handled in the cycle of sample
/// samples_before − 1). The rest (commands, other nodes' frames) stay on the host and are
/// counted in `left_out`: a command carried out on the board has no counterpart in the
/// host-only run.
std::vector<CycleFrame> aiding_frames(const Input& in, const app::LoopOptions& lo,
                                      std::size_t& left_out) {
  std::vector<CycleFrame> out;
  left_out = 0;
  for (const sim::RecordedFrame& r : in.frames) {
    const hal::CanFrame f = sim::can_frame_of(r.frame);
    if (!lo.aiding_inputs || !can::is_input_frame(f, lo.node_id, lo.ids)) {
      ++left_out;
      continue;
    }
    const std::uint64_t before = std::max<std::uint64_t>(r.samples_before, 1);
    out.push_back({static_cast<std::uint32_t>(before - 1), f});
  }
  return out;
}

// Samples of a scenario: host_sim's sample source (trajectory → sensor model) through the
// register-level chip model and the real driver, as on the simulated board; sample k has
// seq = k and t_ns = round(k · 1e9 / rate).
bool scenario_samples(const HilOptions& o, Input& in, std::ostream& err) {
  // Built-in names are found relative to the program unless a folder is given.
  const auto parsed = o.scenario_dir.empty() ? sim::load_scenario(o.scenario)
                                             : sim::load_scenario(o.scenario, o.scenario_dir);
  if (!parsed.is_ok()) {
    err << "gfins-can hil: " << parsed.error().message << "\n";
    return false;
  }
  const sim::Scenario& s = parsed.value();
  auto made = sim_board::make_scenario_stream(s);
  if (!made.is_ok()) {
    err << "gfins-can hil: " << made.error().message << "\n";
    return false;
  }
  auto stream = std::move(made).value();
  sim_board::ChipAdc adc(s.rate_hz);
  if (const Status st = adc.start(); !st.is_ok()) {
    err << "gfins-can hil: simulated ADC start: " << st.message() << "\n";
    return false;
  }
  const double duration = o.duration_s > 0 ? o.duration_s : s.duration_s;
  const auto n = static_cast<std::uint32_t>(std::llround(duration * s.rate_hz)) + 1;
  in.samples.reserve(n);
  for (std::uint32_t k = 0; k < n; ++k) {
    const auto t_ns =
        static_cast<std::int64_t>(std::llround(static_cast<double>(k) * 1e9 / s.rate_hz));
    auto r = adc.convert(stream->volts(k), k, t_ns);
    if (!r.is_ok()) {
      err << "gfins-can hil: sample " << k << ": " << r.status().message() << "\n";
      return false;
    }
    in.samples.push_back(r.value());
  }
  in.rate_hz = s.rate_hz;
  in.what = "scenario " + s.name;
  return true;
}

// The QA-1100 chain's LSB at the sensor, computed as the firmware's hil board does.
double chain_volts_per_count(double rate_hz) {
  drivers::Ads131m06Config adc_cfg;
  adc_cfg.sample_rate_hz = rate_hz;
  const auto fe = drivers::Qa1100FrontEnd::create(drivers::Qa1100FrontEnd::Channels{}, adc_cfg);
  return fe.is_ok() ? fe.value().volts_per_count(0) : 0.0;
}

struct Comparison {
  std::uint64_t epochs = 0;
  std::uint64_t values = 0;
  std::uint64_t mismatches = 0;
  std::uint64_t unknown_epochs = 0;           // SampleCount matching no published sample
  std::map<std::string, double> worst_steps;  // per signal: largest |difference| in steps
};

void compare_epoch(const DecodedEpoch& e, const nav::NavState<float>& n, Comparison& c,
                   std::ostream& out) {
  const auto& cols = columns();
  const auto d = [](float v) { return static_cast<double>(v); };
  const double qsign = n.q_nb.w() < 0 ? -1.0 : 1.0;
  const auto eul = euler_zyx(n.q_nb);
  for (std::size_t i = 0; i < cols.size(); ++i) {
    if (!e.present[i]) continue;
    const can::SignalDef& s = *cols[i].signal;
    double want = 0;
    switch (s.field) {
      case can::Field::kTimeUs:
        want = static_cast<double>(static_cast<std::uint32_t>(n.t_ns / 1000));
        break;
      case can::Field::kQuaternion:
        want = qsign * std::array<double, 4>{d(n.q_nb.w()), d(n.q_nb.x()), d(n.q_nb.y()),
                                             d(n.q_nb.z())}[s.index];
        break;
      case can::Field::kEuler:
        want = eul[s.index];
        break;
      case can::Field::kRate:
        want = d(n.w_b[s.index]);
        break;
      case can::Field::kAngularAccel:
        want = d(n.wdot_b[s.index]);
        break;
      case can::Field::kAccel:
        want = d(n.f_b[s.index]);
        break;
      case can::Field::kVelocity:
        want = d(n.v_n[s.index]);
        break;
      case can::Field::kPosition:
        want = d(n.r_n[s.index]);
        break;
      default:
        continue;  // mode, status and health: the loop's, not the core's
    }
    if (std::isnan(e.values[i])) continue;  // not available: flagged by the decoder
    // Outside the signal's range the encoder saturates at the documented limit (and flags it in
    // the status frame): the core's value as the bus can carry it.
    if (s.max > s.min) want = std::clamp(want, s.min, s.max);
    // Half a quantisation step, 1e-9 of a step for double rounding, 1e-9 rad for the two Euler
    // formulas (same float quaternion, different operation order).
    const double tol = 0.5 * s.factor * (1 + 1e-9) + (s.field == can::Field::kEuler ? 1e-9 : 0.0);
    const double diff = std::abs(e.values[i] - want);
    double& worst = c.worst_steps[std::string(s.name)];
    worst = std::max(worst, diff / s.factor);
    ++c.values;
    if (diff > tol) {
      if (c.mismatches < 20) {
        out << "  differs: " << s.name << " at seq " << n.seq << ": board " << e.values[i]
            << ", core " << want << " (" << diff / s.factor << " steps)\n";
      }
      ++c.mismatches;
    }
  }
}

}  // namespace

int run_hil(const HilOptions& o, std::ostream& out, std::ostream& err) {
  // ---- Input --------------------------------------------------------------------------------
  Input in;
  if (o.scenario.empty() == o.recording.empty()) {
    err << "gfins-can hil: give one of --scenario or --recording\n";
    return kHilExitBadInput;
  }
  if (!o.scenario.empty()) {
    if (!scenario_samples(o, in, err)) return kHilExitBadInput;
  } else {
    auto rec = sim::read_recording(o.recording);
    if (!rec.is_ok()) {
      err << "gfins-can hil: " << rec.error().message << "\n";
      return kHilExitBadInput;
    }
    in.samples = rec.value().samples;
    in.frames = rec.value().frames;
    in.rate_hz = rec.value().header.sample_rate_hz;
    in.what = "recording " + o.recording;
  }
  if (in.samples.empty()) {
    err << "gfins-can hil: " << in.what << " holds no sample\n";
    return kHilExitBadInput;
  }

  // ---- Host-only run of the core: the firmware's start-up, then process() per sample ---------
  app::FwConfig fc;
  if (!o.fw_config.empty()) {
    app::ConfigResult r = app::load_config(o.fw_config);
    if (!r.ok()) {
      err << "gfins-can hil: " << r.error << "\n";
      return kHilExitBadInput;
    }
    fc = *r.config;
  }
  if (fc.sample_rate_hz != in.rate_hz) {
    err << "gfins-can hil: " << in.what << " runs at " << in.rate_hz
        << " Hz but the firmware's adc.sample_rate_hz is " << fc.sample_rate_hz << "\n";
    return kHilExitBadInput;
  }
  const app::StartupCalibration cal =
      app::load_calibration(fc, app::nominal_calibration(chain_volts_per_count(fc.sample_rate_hz)));
  const app::LoopOptions lo = app::loop_options(fc);
  nav::PipelineConfig<float> cfg = cal.set.config;  // as SampleLoop::configure
  cfg.sample_rate_hz = static_cast<float>(lo.sample_rate_hz);
  cfg.heading_rad = lo.initial_heading_rad;
  cfg.r0_n = lo.initial_position_n;
  auto pipe = std::make_unique<nav::NavPipeline<float>>();
  if (const Status st = pipe->configure(cfg); !st.is_ok()) {
    err << "gfins-can hil: pipeline configuration: " << st.message() << "\n";
    return kHilExitBadInput;
  }
  std::size_t left_out = 0;
  const std::vector<CycleFrame> link_frames = aiding_frames(in, lo, left_out);
  if (left_out > 0) {
    out << "gfins-can hil: " << left_out << " of the " << in.frames.size()
        << " recorded CAN frames are not aiding inputs of node " << int{lo.node_id}
        << (lo.aiding_inputs ? "" : " (aiding inputs are off in the firmware's configuration)")
        << " and stay here (commands: gfins-fw --replay carries them out)\n";
  }
  const std::uint16_t epoch_div = fc.dividers[0];
  std::vector<nav::NavState<float>> published;  // the core's state of every published sample
  // The aiding inputs as the loop takes them (SampleLoop::step): after the cycle's sample and
  // its epoch, at most kMaxCommandsPerCycle frames from the bus, the rest in later cycles.
  can::InputDecoder inputs(lo.node_id, lo.ids);
  std::deque<hal::CanFrame> bus_queue;
  std::size_t next_frame = 0;
  for (std::size_t k = 0; k < in.samples.size(); ++k) {
    const RawSample& s = in.samples[k];
    pipe->process(s);
    if (epoch_div != 0 && s.seq % epoch_div == 0) {
      nav::NavState<float> n = pipe->state();
      n.t_ns = s.t_ns;  // the epoch refers to the sample just read (SampleLoop::build_epoch)
      n.seq = s.seq;
      if (app::mounted(lo.q_vb)) app::to_vehicle_frame(n, lo.q_vb);  // as published (mounting)
      published.push_back(n);
    }
    for (; next_frame < link_frames.size() && link_frames[next_frame].cycle == k; ++next_frame) {
      bus_queue.push_back(link_frames[next_frame].frame);
    }
    for (int i = 0; i < app::kMaxCommandsPerCycle && !bus_queue.empty(); ++i) {
      const Result<can::InputEvent> ev = inputs.add(bus_queue.front());
      bus_queue.pop_front();
      if (ev.is_ok()) (void)can::offer_input(*pipe, ev.value(), s.t_ns);
    }
  }

  // ---- Replay -------------------------------------------------------------------------------
  auto client = lnx::HilClient::connect(o.address, static_cast<std::uint16_t>(o.port));
  if (!client.is_ok()) {
    err << "gfins-can hil: " << o.address << ":" << o.port << ": " << client.status().message()
        << (client.status().os_error() != 0
                ? std::string(": ") + std::strerror(client.status().os_error())
                : std::string())
        << "\n";
    return kHilExitBadInput;
  }
  lnx::HilClient& link = *client.value();
  std::vector<DecodedEpoch> epochs;
  std::vector<Issue> issues;
  StreamDecoder dec([&](const DecodedEpoch& e) { epochs.push_back(e); },
                    [&](const Issue& i) { issues.push_back(i); });
  dec.set_id_bases(lo.ids);  // the board's identifier groups, from the same configuration
  const auto n_samples = static_cast<std::uint32_t>(in.samples.size());
  std::uint32_t sent = 0, acked = 0, naks = 0;
  std::uint64_t can_frames = 0;
  std::size_t frames_sent = 0, frame_at = 0;  // link_frames sent; the next one to send
  std::string failure;                        // why the stream ended early
  std::vector<lnx::hil::Frame> frames;
  const auto drain = [&](std::int64_t timeout_ns) -> Status {
    frames.clear();
    const Status st = link.receive(timeout_ns, frames);
    for (const auto& f : frames) {
      if (f.type == lnx::hil::FrameType::kAck) {
        if (f.verdict != lnx::hil::AckVerdict::kOk) {
          ++naks;
          out << "  board rejected sample " << f.index << " (bad CRC on the link)\n";
        }
        acked = std::max(acked, f.index + 1);
      } else if (f.type == lnx::hil::FrameType::kCan) {
        ++can_frames;
        dec.feed_frame(can_frames, 0, f.can);
      }
    }
    return st;
  };
  bool aborted = false;
  while (acked < n_samples && failure.empty()) {
    while (sent < n_samples && sent - acked < static_cast<std::uint32_t>(o.window)) {
      if (o.abort_after >= 0 && sent == static_cast<std::uint32_t>(o.abort_after)) {
        link.abort();
        aborted = true;
        break;
      }
      // This cycle's aiding frames go before its sample: the board hands them to the loop once
      // that sample has arrived (docs/hil.md, "Aiding frames").
      for (; frame_at < link_frames.size() && link_frames[frame_at].cycle == sent; ++frame_at) {
        if (o.drop_frame == static_cast<std::int64_t>(frame_at)) continue;
        const auto cw =
            lnx::hil::encode_can(link_frames[frame_at].frame, lnx::hil::FrameType::kCanIn);
        if (const Status st = link.send(cw); !st.is_ok()) {
          failure = "sending aiding frame " + std::to_string(frame_at) + ": " + st.message();
          break;
        }
        ++frames_sent;
      }
      if (!failure.empty()) break;
      auto w = lnx::hil::encode_sample(sent, in.samples[sent], sent + 1 == n_samples);
      if (o.corrupt_at >= 0 && sent == static_cast<std::uint32_t>(o.corrupt_at)) w[20] ^= 0x01;
      if (const Status st = link.send(w); !st.is_ok()) {
        failure = std::string("sending sample ") + std::to_string(sent) + ": " + st.message();
        break;
      }
      ++sent;
    }
    if (aborted) {
      failure = "connection reset by this host after " + std::to_string(sent) + " sample(s)";
      break;
    }
    if (!failure.empty()) break;
    const Status st = drain(o.timeout_ms * kNsPerMs);
    if (st.code() == ErrorCode::kTimeout) {
      failure = "the board sent nothing for " + std::to_string(o.timeout_ms) +
                " ms (last acknowledged sample " + std::to_string(acked) + ")";
    } else if (st.code() == ErrorCode::kUnavailable || st.code() == ErrorCode::kIoError) {
      failure = std::string("connection lost: ") + st.message();
    } else if (st.code() == ErrorCode::kDataLoss) {
      out << "  bad frame from the board: " << st.message() << "\n";
    }
  }
  // After the last sample the board publishes its frames and closes the connection.
  if (failure.empty()) {
    for (;;) {
      const Status st = drain(o.timeout_ms * kNsPerMs);
      if (st.code() == ErrorCode::kUnavailable) break;  // closed: everything arrived
      if (st.code() == ErrorCode::kTimeout || st.code() == ErrorCode::kIoError) {
        failure = std::string("after the last sample: ") + st.message();
        break;
      }
    }
  }
  dec.finish();

  // ---- Comparison ---------------------------------------------------------------------------
  Comparison cmp;
  std::size_t next = 0;  // published[] index of the next expected epoch
  const int sc = column_index("SampleCount");
  for (const DecodedEpoch& e : epochs) {
    ++cmp.epochs;
    if (sc < 0 || !e.present[static_cast<std::size_t>(sc)]) continue;
    const auto count = static_cast<std::uint32_t>(e.values[static_cast<std::size_t>(sc)]);
    // SampleCount carries seq mod 2^16: find the next published sample with that count.
    std::size_t j = next;
    while (j < published.size() && (published[j].seq & 0xFFFFu) != count) ++j;
    if (j == published.size()) {
      ++cmp.unknown_epochs;
      continue;
    }
    compare_epoch(e, published[j], cmp, out);
    next = j + 1;
  }

  const Summary& sum = dec.summary();
  out << "hil: " << in.what << ", " << n_samples << " samples, window " << o.window << "\n";
  out << "  sent " << sent << ", acknowledged " << acked << ", rejected " << naks
      << ", CAN frames received " << can_frames << "\n";
  out << "  aiding frames: " << link_frames.size() << " in the recording, " << frames_sent
      << " sent (the host-only run applies each in its cycle)\n";
  out << "  epochs: expected " << published.size() << ", decoded " << cmp.epochs
      << ", matching no sample " << cmp.unknown_epochs << "\n";
  out << "  values compared " << cmp.values << ", outside quantisation " << cmp.mismatches << "\n";
  out << "  decoder: frames " << sum.frames << ", ok " << sum.frames_ok << ", problems "
      << sum.total_issues() << "\n";
  for (std::size_t k = 0; k < sum.issues.size(); ++k) {
    if (sum.issues[k] != 0) {
      out << "    " << to_string(static_cast<IssueKind>(k)) << ": " << sum.issues[k] << "\n";
    }
  }
  double worst = 0;
  for (const auto& [name, steps] : cmp.worst_steps) worst = std::max(worst, steps);
  out << "  largest difference: " << worst << " quantisation step(s)\n";
  const bool complete = failure.empty() && cmp.epochs == published.size();
  if (!failure.empty()) {
    out << "  INCOMPLETE: " << failure << "; received " << cmp.epochs << " of " << published.size()
        << " epochs (up to sample " << acked << ")\n";
  }
  const bool equal = cmp.mismatches == 0 && cmp.unknown_epochs == 0 && sum.total_issues() == 0;
  out << "  result: "
      << (complete && equal ? "IDENTICAL (within quantisation)"
                            : (equal ? "consistent so far, but incomplete" : "DIFFERENT"))
      << "\n";
  return complete && equal && naks == 0 ? 0 : kHilExitDifferent;
}

}  // namespace gfins::can_tool
