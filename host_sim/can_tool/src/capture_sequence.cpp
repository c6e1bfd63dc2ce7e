#include "capture_sequence.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace gfins::can_tool {
namespace {

constexpr double kInvSqrt2 = 0.70710678118654752440;

// Nominal sensitive axes of Table 1 (body), the same as nav::table1_geometry: written here so
// the host tool does not need the navigation core to recognise a pose.
constexpr std::array<std::array<double, 3>, 6> kTheta{{{kInvSqrt2, kInvSqrt2, 0.0},
                                                       {kInvSqrt2, 0.0, kInvSqrt2},
                                                       {0.0, kInvSqrt2, kInvSqrt2},
                                                       {0.0, -kInvSqrt2, kInvSqrt2},
                                                       {-kInvSqrt2, 0.0, kInvSqrt2},
                                                       {-kInvSqrt2, kInvSqrt2, 0.0}}};

double expected_g(std::size_t sensor, const std::array<double, 3>& f) {
  const auto& t = kTheta[sensor];
  return t[0] * f[0] + t[1] * f[1] + t[2] * f[2];
}

std::string fmt(const char* f, double a) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, a);
  return buf;
}

std::string pose_name(const PlanPose& p) {
  return "pose " + std::to_string(p.attitude) + " (" + p.label + ")";
}

std::string channel_list(std::uint8_t mask) {
  std::string s;
  for (int j = 0; j < 6; ++j) {
    if ((mask & (1u << j)) == 0) continue;
    if (!s.empty()) s += ", ";
    s += "a" + std::to_string(j + 1);
  }
  return s;
}

// Largest |measured − expected| over the channels (g) for the pose f.
double pose_distance_g(const can::CaptureResult& r, const std::array<double, 3>& f,
                       const SequenceOptions& o, std::size_t* worst = nullptr) {
  double d = 0.0;
  for (std::size_t j = 0; j < 6; ++j) {
    const double g =
        static_cast<double>(r.channels[j].mean_counts) * o.adc_lsb_v / o.nominal_sf_v_per_g[j];
    const double e = std::abs(g - expected_g(j, f));
    if (e > d) {
      d = e;
      if (worst != nullptr) *worst = j;
    }
  }
  return d;
}

}  // namespace

std::vector<PlanPose> tables23_plan() {
  const double k = kInvSqrt2;
  // Table 2 (set β: sensors 2, 3, 5) and Table 3 (set α: sensors 1, 4, 6), g = 1, signs as
  // printed: the specific force sensed (docs/calibration.md, step 2).
  const std::array<std::array<double, 3>, 6> t2{
      {{-k, 0, k}, {k, 0, -k}, {k, 0, k}, {-k, 0, -k}, {0, k, k}, {0, -k, -k}}};
  const std::array<std::array<double, 3>, 6> t3{
      {{0, -k, k}, {0, k, -k}, {k, k, 0}, {-k, -k, 0}, {-k, k, 0}, {k, -k, 0}}};
  std::vector<PlanPose> plan;
  for (int t = 0; t < 2; ++t) {
    for (int j = 0; j < 6; ++j) {
      PlanPose p;
      p.attitude = 6 * t + j + 1;
      p.label = "T" + std::to_string(t + 2) + "." + std::to_string(j + 1);
      p.f_b_g = t == 0 ? t2[static_cast<std::size_t>(j)] : t3[static_cast<std::size_t>(j)];
      p.paper_mask = t == 0 ? 0b010110 : 0b101001;  // β = {2, 3, 5}, α = {1, 4, 6}
      p.paper_attitude = j + 1;
      plan.push_back(p);
    }
  }
  return plan;
}

std::vector<PlanPose> plan_from_rows(const std::vector<std::pair<int, std::array<double, 3>>>& rows,
                                     std::string& error) {
  std::vector<PlanPose> plan;
  error.clear();
  if (rows.empty()) {
    error = "the poses file has no poses";
    return {};
  }
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto& [att, f] = rows[i];
    const double n = std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    // At rest the board senses 1 g; 0.8..1.2 allows vectors written in local g or rounded.
    if (!(n > 0.8 && n < 1.2)) {
      error = "pose " + std::to_string(att) + ": |f| = " + fmt("%.3g", n) +
              " g; a pose is the specific force sensed at rest, about 1 g (body axes)";
      return {};
    }
    for (const PlanPose& p : plan) {
      if (p.attitude == att) {
        error = "pose " + std::to_string(att) + " is given twice";
        return {};
      }
    }
    PlanPose p;
    p.attitude = att;
    p.label = "P" + std::to_string(att);
    p.f_b_g = f;
    plan.push_back(p);
  }
  return plan;
}

const char* to_string(Refusal r) {
  switch (r) {
    case Refusal::kNone:
      return "accepted";
    case Refusal::kIncomplete:
      return "incomplete";
    case Refusal::kSaturated:
      return "saturated";
    case Refusal::kMotion:
      return "moved";
    case Refusal::kWrongPose:
      return "wrong pose";
  }
  return "?";
}

CaptureCheck check_capture(const can::CaptureResult& r, const PlanPose& pose,
                           const std::vector<PlanPose>& plan, const SequenceOptions& o) {
  CaptureCheck c;
  const std::string head = pose_name(pose) + " refused: ";
  std::uint8_t sat = 0, moved = 0, empty = 0;
  for (std::size_t j = 0; j < 6; ++j) {
    const auto bit = static_cast<std::uint8_t>(1u << j);
    if (r.channels[j].saturated) sat |= bit;
    if (r.channels[j].motion) moved |= bit;
    if (r.channels[j].count == 0) empty |= bit;
  }
  if (empty != 0) {
    c.refusal = Refusal::kIncomplete;
    c.channels = empty;
    c.text = head + "no samples on channel(s) " + channel_list(empty) +
             " (every frame failed its CRC, or result frames were lost): repeat the pose";
    return c;
  }
  if (sat != 0) {
    c.refusal = Refusal::kSaturated;
    c.channels = sat;
    c.text = head + "saturated: channel(s) " + channel_list(sat) +
             " reached the converter's full scale during the capture (an input beyond the "
             "range, a shock, or a wiring fault); its mean is not a measurement";
    return c;
  }
  if (moved != 0) {
    c.refusal = Refusal::kMotion;
    c.channels = moved;
    std::string detail;
    for (std::size_t j = 0; j < 6; ++j) {
      if ((moved & (1u << j)) == 0) continue;
      const double mg = static_cast<double>(r.channels[j].std_counts) * o.adc_lsb_v /
                        o.nominal_sf_v_per_g[j] * 1e3;
      detail += (detail.empty() ? "" : ", ") + std::string("a") + std::to_string(j + 1) + " σ " +
                fmt("%.3g", mg) + " mg";
    }
    c.text = head + "the board moved during the capture: " + detail +
             " above the firmware's still limit (2 mg of the scale factor); hold it still, let "
             "it settle and repeat the pose";
    return c;
  }
  std::size_t worst = 0;
  const double d = pose_distance_g(r, pose.f_b_g, o, &worst);
  if (d > o.pose_tolerance_g) {
    c.refusal = Refusal::kWrongPose;
    c.channels = static_cast<std::uint8_t>(1u << worst);
    const double g = static_cast<double>(r.channels[worst].mean_counts) * o.adc_lsb_v /
                     o.nominal_sf_v_per_g[worst];
    double best = 1e9;
    for (std::size_t i = 0; i < plan.size(); ++i) {
      const double di = pose_distance_g(r, plan[i].f_b_g, o);
      if (di <= o.pose_tolerance_g && di < best) {
        best = di;
        c.looks_like = static_cast<int>(i);
      }
    }
    c.text = head + "the board is not in this pose: sensor a" + std::to_string(worst + 1) +
             " reads " + fmt("%+.3f", g) + " g where the pose expects " +
             fmt("%+.3f", expected_g(worst, pose.f_b_g)) + " g (tolerance " +
             fmt("%.2g", o.pose_tolerance_g) + " g); " +
             (c.looks_like >= 0
                  ? "it reads like " + pose_name(plan[static_cast<std::size_t>(c.looks_like)]) +
                        ": wrong pose order?"
                  : std::string("it reads like none of the plan's poses"));
    return c;
  }
  return c;
}

CommandOutcome capture_once(hal::CanBus& bus, std::uint8_t pose, std::uint16_t samples,
                            const SequenceOptions& o, std::uint8_t& token) {
  can::Command c;
  c.opcode = can::Opcode::kStartCapture;
  c.token = token++;
  c.pose = pose;
  c.samples = samples;
  CommandTimeouts t = o.timeouts;
  t.sample_rate_hz = o.sample_rate_hz;
  return run_command(bus, c, o.node_id, t, o.ids);
}

SequenceResult run_capture_sequence(hal::CanBus& bus, const std::vector<PlanPose>& plan,
                                    const SequenceOptions& o, const SequenceIo& io) {
  SequenceResult out;
  const auto note = [&io](const std::string& s) {
    if (io.note) io.note(s);
  };
  if (!(o.adc_lsb_v > 0.0) || o.samples == 0 || plan.empty()) {
    out.error = "capture sequence: needs a positive ADC LSB, N >= 1 and at least one pose";
    out.stop = SequenceResult::Stop::kAborted;
    return out;
  }
  std::uint8_t token = o.first_token;
  const auto max_probes = static_cast<long>(
      std::ceil(o.pose_timeout_s * o.sample_rate_hz / std::max<double>(1.0, o.probe_samples)));
  for (std::size_t i = 0; i < plan.size(); ++i) {
    const PlanPose& pose = plan[i];
    // The board numbers captures by pose (0..63): the plan's attitude, wrapped into that range.
    const auto board_pose = static_cast<std::uint8_t>(pose.attitude % 64);
    int refused = 0;
    for (;;) {
      if (o.wait == WaitMode::kAuto) {
        long probes = 0;
        int settled = 0;
        std::string last;
        for (;;) {
          const CommandOutcome p = capture_once(bus, board_pose, o.probe_samples, o, token);
          if (p.kind == CommandOutcome::Kind::kTimeout) {
            // No board on the bus yet (started after the tool) or a lost frame: keep probing,
            // counting the wait against the pose's timeout.
            last = "no answer from node " + std::to_string(o.node_id) + " (" + p.text + ")";
            settled = 0;
            const double waited_s = static_cast<double>(o.timeouts.response.count()) * 1e-3 + 5.0 +
                                    o.probe_samples / o.sample_rate_hz;
            probes += static_cast<long>(
                std::ceil(waited_s * o.sample_rate_hz / std::max<double>(1.0, o.probe_samples)));
            if (probes >= max_probes) {
              out.error = pose_name(pose) + ": " + last;
              out.stop = SequenceResult::Stop::kNoAnswer;
              return out;
            }
            continue;
          }
          if (p.kind == CommandOutcome::Kind::kIncomplete) {
            // Result frames lost on the bus: this probe says nothing; probe again.
            last = p.text;
            settled = 0;
            if (++probes >= max_probes) {
              out.error = pose_name(pose) + ": " + last;
              out.stop = SequenceResult::Stop::kNoAnswer;
              return out;
            }
            continue;
          }
          if (p.kind != CommandOutcome::Kind::kOk) {
            out.error = pose_name(pose) + ": probe capture failed: " + p.text;
            out.stop = SequenceResult::Stop::kNoAnswer;
            return out;
          }
          const CaptureCheck c = check_capture(p.capture, pose, plan, o);
          settled = c.refusal == Refusal::kNone ? settled + 1 : 0;
          if (settled >= std::max(1, o.settle_probes)) break;
          if (c.refusal != Refusal::kNone) last = c.text;
          if (++probes >= max_probes) {
            out.error = pose_name(pose) + " not reached after " + fmt("%.0f", o.pose_timeout_s) +
                        " s of probing; last probe: " + (last.empty() ? "accepted" : last);
            out.stop = SequenceResult::Stop::kNotReached;
            return out;
          }
        }
      } else if (!io.await_pose || !io.await_pose(pose, i, plan.size(), refused > 0)) {
        out.error = pose_name(pose) + ": aborted by the operator";
        out.stop = SequenceResult::Stop::kAborted;
        return out;
      }
      const CommandOutcome r = capture_once(bus, board_pose, o.samples, o, token);
      // kIncomplete (result frames lost) is refused below and the pose repeated.
      if (r.kind != CommandOutcome::Kind::kOk && r.kind != CommandOutcome::Kind::kIncomplete) {
        out.error = pose_name(pose) + ": capture failed: " + r.text;
        out.stop = SequenceResult::Stop::kNoAnswer;
        return out;
      }
      CaptureCheck c = check_capture(r.capture, pose, plan, o);
      if (c.refusal == Refusal::kNone && !r.capture_complete) {
        c.refusal = Refusal::kIncomplete;
        c.text = pose_name(pose) +
                 " refused: some result frames of the capture were lost: repeat the pose";
      }
      if (c.refusal == Refusal::kNone) {
        out.captures.push_back(PoseCapture{pose, r.capture});
        note(pose_name(pose) + ": captured " + std::to_string(r.capture.channels[0].count) +
             " samples (" + std::to_string(i + 1) + " of " + std::to_string(plan.size()) + ")");
        break;
      }
      ++out.refused;
      note(c.text);
      if (++refused > o.retries) {
        out.error = c.text + " (" + std::to_string(refused) + " attempts; giving up)";
        out.stop = SequenceResult::Stop::kRefused;
        return out;
      }
    }
  }
  out.ok = true;
  return out;
}

std::string means_csv(const std::vector<PoseCapture>& captures, double adc_lsb_v,
                      bool paper_layout) {
  std::string s = "sensor,attitude,mean_v,std_v,count\n";
  char line[160];
  for (std::size_t j = 0; j < 6; ++j) {
    for (const PoseCapture& c : captures) {
      if (paper_layout && (c.pose.paper_mask & (1u << j)) == 0) continue;
      const auto& ch = c.result.channels[j];
      std::snprintf(line, sizeof line, "%zu,%d,%.10g,%.6g,%u\n", j + 1,
                    paper_layout ? c.pose.paper_attitude : c.pose.attitude,
                    static_cast<double>(ch.mean_counts) * adc_lsb_v,
                    static_cast<double>(ch.std_counts) * adc_lsb_v, ch.count);
      s += line;
    }
  }
  return s;
}

std::string poses_csv(const std::vector<PlanPose>& plan) {
  std::string s = "attitude,fx_g,fy_g,fz_g\n";
  char line[160];
  for (const PlanPose& p : plan) {
    std::snprintf(line, sizeof line, "%d,%.17g,%.17g,%.17g\n", p.attitude, p.f_b_g[0], p.f_b_g[1],
                  p.f_b_g[2]);
    s += line;
  }
  return s;
}

// ---- Location runs ---------------------------------------------------------------------------

namespace {

constexpr double kMaxTableRateRadS = 100.0;  // beyond any rate table a board survives (955 rpm)

std::string trim(const std::string& t) {
  const auto b = t.find_first_not_of(" \t\r");
  if (b == std::string::npos) return {};
  return t.substr(b, t.find_last_not_of(" \t\r") - b + 1);
}

}  // namespace

std::vector<RateTableRun> rate_table_plan(const std::string& csv_text, std::string& error) {
  std::vector<RateTableRun> plan;
  std::size_t line_no = 0;
  std::size_t pos = 0;
  bool header = true;
  while (pos <= csv_text.size()) {
    const std::size_t end = std::min(csv_text.find('\n', pos), csv_text.size());
    const std::string line = trim(csv_text.substr(pos, end - pos));
    pos = end + 1;
    ++line_no;
    if (line.empty()) continue;
    if (header) {  // the first non-empty line names the columns
      header = false;
      if (line != "mounting,axis_x,axis_y,axis_z,rate_rad_s") {
        error = "line " + std::to_string(line_no) + ": header '" + line +
                "': expected mounting,axis_x,axis_y,axis_z,rate_rad_s";
        return {};
      }
      continue;
    }
    std::vector<std::string> f;
    std::size_t a = 0;
    while (true) {
      const std::size_t c = line.find(',', a);
      f.push_back(trim(line.substr(a, c == std::string::npos ? std::string::npos : c - a)));
      if (c == std::string::npos) break;
      a = c + 1;
    }
    const std::string where = "line " + std::to_string(line_no) + " ('" + line + "')";
    if (f.size() != 5) {
      error = where + ": " + std::to_string(f.size()) + " fields, expected 5";
      return {};
    }
    std::array<double, 5> v{};
    for (std::size_t i = 0; i < 5; ++i) {
      char* e = nullptr;
      v[i] = std::strtod(f[i].c_str(), &e);
      if (f[i].empty() || e == nullptr || *e != '\0' || !std::isfinite(v[i])) {
        error = where + ": field " + std::to_string(i + 1) + " '" + f[i] + "' is not a number";
        return {};
      }
    }
    RateTableRun r;
    r.mounting = static_cast<int>(v[0]);
    if (static_cast<double>(r.mounting) != v[0] || r.mounting < 0 || r.mounting > 255) {
      error = where + ": mounting must be an integer 0..255";
      return {};
    }
    const double n = std::sqrt(v[1] * v[1] + v[2] * v[2] + v[3] * v[3]);
    if (!(n > 1e-9)) {
      error = where + ": the axis pointing up must be a non-zero vector";
      return {};
    }
    r.up_b = {v[1] / n, v[2] / n, v[3] / n};
    r.rate_rad_s = v[4];
    if (!(r.rate_rad_s > 0.0 && r.rate_rad_s <= kMaxTableRateRadS)) {
      error = where + ": rate_rad_s must be in (0, 100] rad/s";
      return {};
    }
    plan.push_back(r);
  }
  if (plan.empty()) error = "no runs (expected rows mounting,axis_x,axis_y,axis_z,rate_rad_s)";
  return plan;
}

std::uint16_t whole_revolution_samples(double rate_rad_s, double sample_rate_hz,
                                       double target_samples) {
  constexpr double kMaxSamples = 65535.0;  // the capture's sample count is 16 bits
  const double per_rev = 2.0 * M_PI / rate_rad_s * sample_rate_hz;
  double turns = std::max(1.0, std::round(target_samples / per_rev));
  while (turns > 1.0 && std::round(turns * per_rev) > kMaxSamples) turns -= 1.0;
  return static_cast<std::uint16_t>(std::min(kMaxSamples, std::round(turns * per_rev)));
}

bool check_rate_table_capture(const can::CaptureResult& r, std::uint16_t samples, std::string& why,
                              std::string* note) {
  std::string moved;
  for (std::size_t j = 0; j < 6; ++j) {
    const auto& ch = r.channels[j];
    const std::string name = "channel " + std::to_string(j + 1);
    if (ch.saturated) {
      why = name + " saturated during the run: its mean is not the sensor's (lower the rate)";
      return false;
    }
    if (ch.count != samples) {
      why = name + " counted " + std::to_string(ch.count) + " of " + std::to_string(samples) +
            " samples: repeat the run";
      return false;
    }
    if (ch.motion) moved += (moved.empty() ? "" : ", ") + std::to_string(j + 1);
  }
  if (note != nullptr && !moved.empty()) {
    *note = "channel(s) " + moved +
            " vary more than a static pose allows: a table axis off the vertical, or a rate "
            "that changed; the mean over whole turns is kept";
  }
  why.clear();
  return true;
}

std::string location_runs_header() {
  return "mounting,axis_x,axis_y,axis_z,rate_rad_s,mean_v1,mean_v2,mean_v3,mean_v4,mean_v5,"
         "mean_v6,std_v1,std_v2,std_v3,std_v4,std_v5,std_v6,count\n";
}

std::string location_run_row(const can::CaptureResult& r, int mounting,
                             const std::array<double, 3>& up_b, double rate_rad_s,
                             double adc_lsb_v) {
  const double n = std::sqrt(up_b[0] * up_b[0] + up_b[1] * up_b[1] + up_b[2] * up_b[2]);
  char buf[96];
  std::snprintf(buf, sizeof buf, "%d,%.9g,%.9g,%.9g,%.9g", mounting, up_b[0] / n, up_b[1] / n,
                up_b[2] / n, rate_rad_s);
  std::string s = buf;
  for (const auto& ch : r.channels) {
    std::snprintf(buf, sizeof buf, ",%.12g", static_cast<double>(ch.mean_counts) * adc_lsb_v);
    s += buf;
  }
  for (const auto& ch : r.channels) {
    std::snprintf(buf, sizeof buf, ",%.6g", static_cast<double>(ch.std_counts) * adc_lsb_v);
    s += buf;
  }
  s += "," + std::to_string(r.channels[0].count) + "\n";
  return s;
}

RateTableCapture capture_rate_table_run(hal::CanBus& bus, const RateTableRun& run,
                                        const SequenceOptions& o, std::uint8_t& token) {
  RateTableCapture c;
  char name[96];
  std::snprintf(name, sizeof name, "mounting %d at %g rad/s", run.mounting, run.rate_rad_s);
  c.samples = whole_revolution_samples(run.rate_rad_s, o.sample_rate_hz, o.samples);
  const CommandOutcome r =
      capture_once(bus, static_cast<std::uint8_t>(run.mounting), c.samples, o, token);
  if (r.kind != CommandOutcome::Kind::kOk && r.kind != CommandOutcome::Kind::kIncomplete) {
    c.error = std::string(name) + ": capture failed: " + r.text;
    return c;
  }
  if (!r.capture_complete) {
    c.error = std::string(name) + ": some result frames of the capture were lost: repeat the run";
    return c;
  }
  c.result = r.capture;
  std::string why;
  if (!check_rate_table_capture(r.capture, c.samples, why, &c.note)) {
    c.error = std::string(name) + " refused: " + why;
    return c;
  }
  if (!c.note.empty()) c.note = std::string(name) + ": " + c.note;
  c.row = location_run_row(r.capture, run.mounting, run.up_b, run.rate_rad_s, o.adc_lsb_v);
  c.ok = true;
  return c;
}

}  // namespace gfins::can_tool
