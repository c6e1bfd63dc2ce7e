// Validation, canonical serialisation and checksum of CalibrationData.
#include <bit>
#include <cctype>
#include <charconv>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <string>
#include <string_view>

#include <Eigen/Eigenvalues>

#include "fields.hpp"
#include "gfins/calib_file/calibration_data.hpp"

#include "gfins/checksum/fnv1a.hpp"

namespace gfins::calib_file {
namespace {

using detail::Domain;

// Smallest eigenvalue a stored correlation matrix may have. Coefficients computed from a positive
// semidefinite covariance and written with round-trip precision are PSD to rounding (~1e-16); an
// exactly singular one (|ρ| = 1, an angle fixed by SF) may land a few ulps below zero.
constexpr double kCorrelationPsdTolerance = 1e-9;

// Shortest text that reads back to x (as the file prints it).
std::string format_double(double x) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, x);
  return std::string(buf, r.ptr);
}

bool is_device_id(const std::string& s) {
  if (s.empty() || s.size() > kMaxDeviceIdLength) return false;
  for (const char c : s) {
    const bool ok =
        std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '.' || c == '_' || c == '-';
    if (!ok) return false;
  }
  return true;
}

bool is_printable_ascii(const std::string& s) {
  for (const char c : s) {
    if (c < 0x20 || c > 0x7e) return false;
  }
  return true;
}

// "YYYY-MM-DDTHH:MM:SSZ" with plausible field ranges (calendar days are not checked per month).
bool is_utc_timestamp(const std::string& s) {
  static constexpr const char* kPattern = "dddd-dd-ddTdd:dd:ddZ";
  if (s.size() != 20) return false;
  for (std::size_t i = 0; i < 20; ++i) {
    const char p = kPattern[i];
    if (p == 'd' ? std::isdigit(static_cast<unsigned char>(s[i])) == 0 : s[i] != p) return false;
  }
  const auto field = [&s](std::size_t at) { return std::stoi(s.substr(at, 2)); };
  return field(5) >= 1 && field(5) <= 12 && field(8) >= 1 && field(8) <= 31 && field(11) <= 23 &&
         field(14) <= 59 && field(17) <= 60;
}

// Finds the first value outside its domain.
class Validator {
 public:
  explicit Validator(const CalibrationData& d) : rho_m_(d.geometry.rho_m) {}

  void text(const std::string& key, const std::string& s, Domain domain) {
    if (found()) return;
    if (domain == Domain::kDeviceId && !is_device_id(s)) {
      fail(key, "\"" + s + "\" is not 1 to 64 characters of [A-Za-z0-9._-]");
    } else if (domain == Domain::kUtc && !is_utc_timestamp(s)) {
      fail(key, "\"" + s + "\" is not a UTC time YYYY-MM-DDTHH:MM:SSZ");
    } else if (domain == Domain::kSource &&
               (s.size() > kMaxSourceLength || !is_printable_ascii(s))) {
      fail(key, "must be at most 256 printable ASCII characters");
    }
  }
  void unit(const std::string&, const char*) {}
  void geometry_kind(const std::string& key, GeometryKind k) {
    if (!found() && k != GeometryKind::kTable1 && k != GeometryKind::kCustom) {
      fail(key, "unknown geometry kind");
    }
  }
  void correlations(const std::string&, bool) {}
  void sigma_source(const std::string& key, const SigmaSource& src) {
    SigmaSource back;
    if (!found() && !parse_sigma_source(to_string(src), back)) {
      fail(key, "not a sigma source (residuals need 1.." + std::to_string(kMaxSigmaDof) + " dof)");
    }
  }
  void compensator(const std::string& key, nav::CompensatorKind k) {
    if (!found() && k != nav::CompensatorKind::kNone && k != nav::CompensatorKind::kPaper &&
        k != nav::CompensatorKind::kExact) {
      fail(key, "unknown compensator kind");
    }
  }
  void number(const std::string& key, double x, Domain domain) {
    if (found()) return;
    const std::string what = check(x, domain);
    if (!what.empty()) fail(key, "= " + format_double(x) + ": " + what);
  }
  void vec3(const std::string& key, const std::array<double, 3>& v, Domain domain) {
    if (found()) return;
    if (domain == Domain::kAxis) {
      const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      if (!std::isfinite(n) || std::fabs(n - 1.0) > kAxisUnitTolerance) {
        fail(key, "has length " + format_double(n) + ": an axis must be a unit vector");
      }
      return;
    }
    for (std::size_t k = 0; k < 3; ++k) {
      const std::string what = check(v[k], domain);
      if (!what.empty()) {
        fail(key, "[" + std::to_string(k) + "] = " + format_double(v[k]) + ": " + what);
        return;
      }
    }
  }

  const Problem& problem() const { return problem_; }

 private:
  bool found() const { return problem_.found(); }
  void fail(const std::string& key, const std::string& what) { problem_ = Problem{key, what}; }

  std::string check(double x, Domain domain) const {
    if (!std::isfinite(x)) return "must be a finite number";
    switch (domain) {
      case Domain::kAdcLsb:
        return x >= kMinAdcLsbV && x <= kMaxAdcLsbV ? "" : "must be in [1e-12, 1] V/count";
      case Domain::kScale:
        return x >= kMinScaleVPerG && x <= kMaxScaleVPerG ? "" : "must be in [1e-6, 1e6] V/g";
      case Domain::kSigma:
        return x >= 0.0 ? "" : "an uncertainty must not be negative";
      case Domain::kBias:
        return std::fabs(x) <= kMaxAbsBiasG ? "" : "must be within ±1 g";
      case Domain::kAngle:
        return std::fabs(x) <= kMaxAngleDeg
                   ? ""
                   : "must be within ±10 degrees (small-angle model of eqs. (14)/(15))";
      case Domain::kLocation:
        return std::fabs(x) <= kMaxLocationErrorOfRho * rho_m_
                   ? ""
                   : "a location error component must be within ±rho/2 (geometry.rho_m)";
      case Domain::kRho:
        return x > 0.0 && x <= kMaxRhoM ? "" : "must be in (0, 10] m";
      case Domain::kPosition:
        return std::fabs(x) <= kMaxPositionM ? "" : "must be within ±10 m";
      case Domain::kGravity:
        return x >= kMinGravityMps2 && x <= kMaxGravityMps2
                   ? ""
                   : "must be a local gravity in [9.7, 9.9] m/s² (not g, not Gal)";
      case Domain::kCorrelation:
        return std::fabs(x) <= kMaxAbsCorrelation ? ""
                                                  : "a correlation coefficient must be in [-1, 1]";
      default:
        return "";
    }
  }

  double rho_m_;
  Problem problem_{};
};

// Builds the canonical text: "key=value\n" per value, doubles as their bit pattern.
class Canonical {
 public:
  void text(const std::string& key, const std::string& s, Domain) { line(key, s); }
  void unit(const std::string& key, const char* u) { line(key, u); }
  void geometry_kind(const std::string& key, GeometryKind k) { line(key, to_string(k)); }
  void compensator(const std::string& key, nav::CompensatorKind k) { line(key, nav::to_string(k)); }
  void correlations(const std::string& key, bool known) {
    line(key, known ? kCorrelationsStated : kCorrelationsUnknown);
  }
  void sigma_source(const std::string& key, const SigmaSource& src) { line(key, to_string(src)); }
  void number(const std::string& key, double x, Domain) { line(key, bits(x)); }
  void vec3(const std::string& key, const std::array<double, 3>& v, Domain) {
    line(key, bits(v[0]) + "," + bits(v[1]) + "," + bits(v[2]));
  }
  std::string out;

 private:
  void line(const std::string& key, const std::string& value) {
    out += key;
    out += '=';
    out += value;
    out += '\n';
  }
  // Every NaN is written "nan": TOML cannot carry a NaN's sign or payload.
  static std::string bits(double x) {
    if (std::isnan(x)) return "nan";
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016" PRIx64, std::bit_cast<std::uint64_t>(x));
    return buf;
  }
};

}  // namespace

std::string to_string(const SigmaSource& s) {
  switch (s.basis) {
    case SigmaBasis::kStated:
      return "stated";
    case SigmaBasis::kResiduals:
      return "residuals, " + std::to_string(s.dof) + " dof";
    case SigmaBasis::kNone:
      return "none: not estimated";
    case SigmaBasis::kUnknown:
      return "unknown: older file";
  }
  return "invalid";
}

bool parse_sigma_source(const std::string& text, SigmaSource& out) {
  for (const SigmaBasis b : {SigmaBasis::kStated, SigmaBasis::kNone, SigmaBasis::kUnknown}) {
    if (text == to_string(SigmaSource{b, 0})) {
      out = SigmaSource{b, 0};
      return true;
    }
  }
  // "residuals, K dof" with K a plain decimal 1..kMaxSigmaDof (no sign, no leading zero).
  constexpr std::string_view kHead = "residuals, ";
  constexpr std::string_view kTail = " dof";
  const std::string_view t = text;
  if (t.size() <= kHead.size() + kTail.size() || !t.starts_with(kHead) || !t.ends_with(kTail)) {
    return false;
  }
  const std::string_view digits = t.substr(kHead.size(), t.size() - kHead.size() - kTail.size());
  if (digits.empty() || digits.size() > 5 || digits.front() == '0') return false;
  std::int32_t k = 0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), k);
  if (ec != std::errc() || end != digits.data() + digits.size() || k < 1 || k > kMaxSigmaDof) {
    return false;
  }
  out = SigmaSource{SigmaBasis::kResiduals, k};
  return true;
}

const char* to_string(GeometryKind kind) {
  switch (kind) {
    case GeometryKind::kTable1:
      return "table1";
    case GeometryKind::kCustom:
      return "custom";
  }
  return "unknown";
}

Problem validate(const CalibrationData& data) {
  Validator v(data);
  // ρ first: the location bound depends on it.
  v.number("geometry.rho_m", data.geometry.rho_m, Domain::kRho);
  detail::visit_fields(data, v);
  if (v.problem().found()) return v.problem();
  // Each sensor's correlations must form a correlation matrix (positive semidefinite), or the
  // covariance they rebuild with the σ could give a negative variance to a derived quantity.
  for (std::size_t j = 0; j < kNumSensors; ++j) {
    const auto& c = data.sensors[j].correlation;
    Eigen::Matrix4d r = Eigen::Matrix4d::Identity();
    const std::array<std::array<int, 2>, kNumCorrelations> at = {
        {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}}};
    for (std::size_t k = 0; k < kNumCorrelations; ++k) {
      r(at[k][0], at[k][1]) = c[k];
      r(at[k][1], at[k][0]) = c[k];
    }
    const double smallest =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d>(r, Eigen::EigenvaluesOnly).eigenvalues()(0);
    if (!(smallest >= -kCorrelationPsdTolerance)) {
      return Problem{"sensor." + std::to_string(j + 1) + ".correlation",
                     "is not a correlation matrix (not positive semidefinite: smallest "
                     "eigenvalue " +
                         format_double(smallest) + ")"};
    }
  }
  return Problem{};
}

std::string canonical_serialisation(const CalibrationData& data, std::int64_t version) {
  Canonical c;
  c.out = "format_version=" + std::to_string(version) + "\n";
  detail::visit_fields(data, c, version);
  return c.out;
}

std::uint64_t fnv1a64(const std::string& bytes) { return gfins::fnv1a64(bytes); }

std::uint64_t checksum(const CalibrationData& data, std::int64_t version) {
  return fnv1a64(canonical_serialisation(data, version));
}

std::optional<std::string> converter_mismatch(
    const CalibrationData& data, const std::array<double, kNumSensors>& volts_per_count,
    const std::string& what) {
  for (std::size_t j = 0; j < kNumSensors; ++j) {
    const double a = data.sensors[j].adc_lsb_v_per_count;
    const double b = volts_per_count[j];
    if (!(std::fabs(a - b) <= kLsbMismatchRel * std::fabs(b))) {
      char buf[256];
      std::snprintf(buf, sizeof buf,
                    "sensor a%zu has an ADC LSB of %.9g V/count, %s %.9g: the calibration is of "
                    "another converter setting",
                    j + 1, a, what.c_str(), b);
      return std::string(buf);
    }
  }
  return std::nullopt;
}

std::uint32_t cal_id_of(const CalibrationData& data) {
  const std::uint64_t h = checksum(data);
  const auto id = static_cast<std::uint32_t>((h ^ (h >> 32)) & 0xFFFFFFFFu);
  return id == 0 ? 1u : id;
}

std::string utc_now_iso8601() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

}  // namespace gfins::calib_file
