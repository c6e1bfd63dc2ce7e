// TOML text ⇄ CalibrationData with tomlplusplus (Debian's libtomlplusplus, built with
// exceptions: every toml:: call that can throw is inside a try block of this file).
#include <cinttypes>
#include <cstdio>
#include <exception>
#include <set>
#include <sstream>
#include <string>
#include <string_view>

#include "fields.hpp"
#include "gfins/calib_file/calibration_file.hpp"
#include "gfins/drivers/lnx/printable.hpp"
#include "gfins/toml/safe_parse.hpp"
#include "toml_format.hpp"

namespace gfins::calib_file {
namespace {

using detail::Domain;

constexpr std::string_view kChecksumKey = "integrity.checksum";
constexpr std::string_view kChecksumPrefix = "fnv1a64:";

constexpr std::string_view kHeader =
    "# gfins calibration file (docs/calibration-file.md), written by gfins-calibrate.\n"
    "# Units (also in [units]): lengths m, scale factors V/g, biases g, orientation errors\n"
    "# degrees, ADC LSB V/count; every *_sigma_* key is the 1-sigma uncertainty of its value,\n"
    "# sensor.N.correlation the correlation coefficients of that sensor's SF, bias and angles.\n"
    "# g in V/g and in the biases is the local gravity of the calibration site, "
    "gravity.local_mps2\n"
    "# (m/s^2); the firmware converts to m/s^2 with that value.\n"
    "# Sensors are numbered as in Table 1 of Hung, Fang & Lee (2007); orientation sets:\n"
    "# beta = sensors {2, 3, 5}, alpha = sensors {1, 4, 6} (eqs. (14)/(15), Table 6).\n"
    "# Any edit invalidates integrity.checksum: re-save with gfins-calibrate, do not hand-edit.\n"
    "\n";

std::string checksum_text(std::uint64_t h) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016" PRIx64, h);
  return std::string(kChecksumPrefix) + buf;
}

// Splits "a.b.c" at its dots.
std::vector<std::string> split_path(const std::string& path) {
  std::vector<std::string> parts;
  std::string::size_type begin = 0;
  for (;;) {
    const auto dot = path.find('.', begin);
    parts.push_back(path.substr(begin, dot - begin));
    if (dot == std::string::npos) return parts;
    begin = dot + 1;
  }
}

// Builds the toml::table.
class Writer {
 public:
  void text(const std::string& key, const std::string& s, Domain) { put(key, s); }
  void unit(const std::string& key, const char* u) { put(key, std::string(u)); }
  void geometry_kind(const std::string& key, GeometryKind k) {
    put(key, std::string(to_string(k)));
  }
  void compensator(const std::string& key, nav::CompensatorKind k) {
    put(key, std::string(nav::to_string(k)));
  }
  void correlations(const std::string& key, bool known) {
    put(key, std::string(known ? kCorrelationsStated : kCorrelationsUnknown));
  }
  void sigma_source(const std::string& key, const SigmaSource& src) { put(key, to_string(src)); }
  void number(const std::string& key, double x, Domain) { put(key, x); }
  void vec3(const std::string& key, const std::array<double, 3>& v, Domain) {
    put(key, toml::array{v[0], v[1], v[2]});
  }

  toml::table root;

  template <typename V>
  void put(const std::string& key, V&& value) {
    const auto parts = split_path(key);
    toml::table* t = &root;
    for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
      auto [it, inserted] = t->emplace<toml::table>(parts[i]);
      t = it->second.as_table();
    }
    t->insert_or_assign(parts.back(), std::forward<V>(value));
  }
};

// Reads values out of a parsed table; remembers the first problem and the keys it consumed.
class Reader {
 public:
  explicit Reader(const toml::table& root) : root_(root) {}

  void text(const std::string& key, std::string& s, Domain) {
    if (const toml::node* n = find(key, "a string")) {
      if (const auto v = n->value<std::string>(); n->is_string() && v) {
        s = *v;
      } else {
        wrong_type(key, *n, "a string");
      }
    }
  }
  void unit(const std::string& key, const char* u) {
    std::string s;
    text(key, s, Domain::kSource);
    if (ok() && s != u) {
      fail(ErrorCode::kInvalidArgument, line_of(key),
           key + " is \"" + s + "\" but this format stores \"" + u + "\"");
    }
  }
  void geometry_kind(const std::string& key, GeometryKind& k) {
    std::string s;
    text(key, s, Domain::kSource);
    if (!ok()) return;
    if (s == "table1") {
      k = GeometryKind::kTable1;
    } else if (s == "custom") {
      k = GeometryKind::kCustom;
    } else {
      fail(ErrorCode::kInvalidArgument, line_of(key),
           key + " is \"" + s + "\": expected \"table1\" or \"custom\"");
    }
  }
  void correlations(const std::string& key, bool& known) {
    std::string s;
    text(key, s, Domain::kSource);
    if (!ok()) return;
    if (s == kCorrelationsStated) {
      known = true;
    } else if (s == kCorrelationsUnknown) {
      known = false;
    } else {
      fail(ErrorCode::kInvalidArgument, line_of(key),
           key + " is \"" + s + "\": expected \"" + kCorrelationsStated + "\" or \"" +
               kCorrelationsUnknown + "\"");
    }
  }
  void sigma_source(const std::string& key, SigmaSource& src) {
    std::string s;
    text(key, s, Domain::kSource);
    if (!ok()) return;
    if (!parse_sigma_source(s, src)) {
      fail(ErrorCode::kInvalidArgument, line_of(key),
           key + " is \"" + s + "\": expected \"stated\", \"residuals, K dof\" (K = 1.." +
               std::to_string(kMaxSigmaDof) +
               "), \"none: not estimated\" or \"unknown: older file\"");
    }
  }
  void compensator(const std::string& key, nav::CompensatorKind& k) {
    std::string s;
    text(key, s, Domain::kSource);
    if (!ok()) return;
    if (s == "none") {
      k = nav::CompensatorKind::kNone;
    } else if (s == "paper") {
      k = nav::CompensatorKind::kPaper;
    } else if (s == "exact") {
      k = nav::CompensatorKind::kExact;
    } else {
      fail(ErrorCode::kInvalidArgument, line_of(key),
           key + " is \"" + s + "\": expected \"none\", \"paper\" or \"exact\"");
    }
  }
  void number(const std::string& key, double& x, Domain) {
    if (const toml::node* n = find(key, "a number")) {
      if (!read_number(*n, x)) wrong_type(key, *n, "a number");
    }
  }
  void vec3(const std::string& key, std::array<double, 3>& v, Domain) {
    if (const toml::node* n = find(key, "an array of 3 numbers")) {
      const toml::array* a = n->as_array();
      bool good = a != nullptr && a->size() == 3;
      for (std::size_t k = 0; good && k < 3; ++k) good = read_number(*a->get(k), v[k]);
      if (!good) wrong_type(key, *n, "an array of 3 numbers");
    }
  }

  bool ok() const { return status_.is_ok(); }
  const FileStatus& status() const { return status_; }
  const std::set<std::string>& consumed() const { return consumed_; }
  void fail(ErrorCode code, std::uint32_t line, const std::string& what) {
    if (!ok()) return;
    status_ = FileStatus(code, (line > 0 ? "line " + std::to_string(line) + ": " : "") + what);
  }
  std::uint32_t line_of(const std::string& key) const {
    const toml::node_view<const toml::node> n = root_.at_path(key);
    return n ? n.node()->source().begin.line : 0;
  }

 private:
  static bool read_number(const toml::node& n, double& x) {
    if (const auto* f = n.as_floating_point()) {
      x = f->get();
      return true;
    }
    if (const auto* i = n.as_integer()) {
      x = static_cast<double>(i->get());
      return true;
    }
    return false;
  }
  const toml::node* find(const std::string& key, const char* expected) {
    if (!ok()) return nullptr;
    consumed_.insert(key);
    const toml::node_view<const toml::node> n = root_.at_path(key);
    if (!n) {
      fail(ErrorCode::kInvalidArgument, 0,
           "missing key '" + key + "' (" + expected + " is required)");
      return nullptr;
    }
    return n.node();
  }
  void wrong_type(const std::string& key, const toml::node& n, const char* expected) {
    std::ostringstream got;
    got << n.type();
    fail(ErrorCode::kInvalidArgument, n.source().begin.line,
         key + " must be " + expected + ", found a " + got.str());
  }

  const toml::table& root_;
  FileStatus status_{};
  std::set<std::string> consumed_;
};

// The first key of the file that the format does not define (a typo, or a value the checksum
// would not cover), walking tables depth-first; arrays are values.
const toml::node* find_unknown_key(const toml::table& t, const std::string& prefix,
                                   const std::set<std::string>& known, std::string& path) {
  for (const auto& [k, node] : t) {
    const std::string p =
        prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
    if (const toml::table* sub = node.as_table()) {
      if (const toml::node* n = find_unknown_key(*sub, p, known, path)) return n;
    } else if (known.count(p) == 0) {
      path = p;
      return &node;
    }
  }
  return nullptr;
}

bool ends_with_marker(std::string_view text) {
  const auto end = text.find_last_not_of(" \t\r\n");
  if (end == std::string_view::npos) return false;
  const std::string_view body = text.substr(0, end + 1);
  if (body.size() < kEndMarker.size()) return false;
  const std::size_t at = body.size() - kEndMarker.size();
  return body.substr(at) == kEndMarker && (at == 0 || body[at - 1] == '\n');
}

FileResult<CalibrationData> parse_table(const toml::table& root, const std::string& prefix) {
  const auto fail = [&prefix](ErrorCode code, const std::string& what) {
    return FileResult<CalibrationData>(FileStatus(code, prefix + what));
  };
  // 1. Format version first: a later version may change everything below, checksum included.
  const toml::node* version = root.get("format_version");
  if (version == nullptr) return fail(ErrorCode::kInvalidArgument, "missing key 'format_version'");
  const auto* version_int = version->as_integer();
  const std::string version_line = "line " + std::to_string(version->source().begin.line) + ": ";
  if (version_int == nullptr) {
    return fail(ErrorCode::kInvalidArgument, version_line + "format_version must be an integer");
  }
  const std::int64_t file_version = version_int->get();
  if (file_version < kOldestFormatVersion || file_version > kFormatVersion) {
    return fail(ErrorCode::kUnimplemented, version_line + "format version " +
                                               std::to_string(file_version) +
                                               " is not supported (this build reads versions " +
                                               std::to_string(kOldestFormatVersion) + " to " +
                                               std::to_string(kFormatVersion) + ")");
  }
  // 2. Every value of that version present with the right type and unit; nothing unknown.
  CalibrationData d;
  if (file_version == 1) {
    // Version 1 had no calibration site; its front end converted with standard gravity, which
    // is what these values keep doing (docs/calibration-file.md, versioning).
    d.gravity_mps2 = nav::kStandardGravity;
    d.gravity_source = kVersion1GravitySource;
  }
  // Versions 1 and 2 stated σ but not the correlations of SF, b and the angles: 0 by assumption,
  // and said so (docs/calibration-file.md, versioning).
  if (file_version < 3) d.correlations_known = false;
  // Before version 4 a file did not say where its σ came from.
  if (file_version < 4) {
    for (auto& sensor : d.sensors) sensor.sigma_source = SigmaSource{SigmaBasis::kUnknown, 0};
  }
  Reader reader(root);
  detail::visit_fields(d, reader, file_version);
  if (!reader.ok()) return FileStatus(reader.status().code(), prefix + reader.status().message());
  std::set<std::string> known = reader.consumed();
  known.insert("format_version");
  known.insert(std::string(kChecksumKey));
  std::string unknown;
  if (const toml::node* n = find_unknown_key(root, "", known, unknown)) {
    return fail(ErrorCode::kInvalidArgument, "line " + std::to_string(n->source().begin.line) +
                                                 ": unknown key '" + unknown + "'");
  }
  // 3. Checksum over the values as read.
  const toml::node_view<const toml::node> sum = root.at_path(kChecksumKey);
  if (!sum || !sum.is_string()) {
    return fail(ErrorCode::kDataLoss,
                "missing key 'integrity.checksum' (a string \"fnv1a64:<16 "
                "hex digits>\"): the file's integrity cannot be checked");
  }
  const std::string stored = sum.value<std::string>().value_or("");
  const std::string computed = checksum_text(checksum(d, file_version));
  if (stored != computed) {
    return fail(ErrorCode::kDataLoss, "line " + std::to_string(sum.node()->source().begin.line) +
                                          ": checksum mismatch: integrity.checksum is \"" + stored +
                                          "\" but the values give \"" + computed +
                                          "\"; the file is corrupted or was edited by hand");
  }
  // 4. Ranges.
  const Problem p = validate(d);
  if (p.found()) {
    return fail(ErrorCode::kOutOfRange, reader.line_of(p.key) > 0
                                            ? "line " + std::to_string(reader.line_of(p.key)) +
                                                  ": " + p.key + " " + p.problem
                                            : p.key + " " + p.problem);
  }
  return d;
}

}  // namespace

std::string to_toml_text(const CalibrationData& data) {
  Writer w;
  w.root.insert_or_assign("format_version", kFormatVersion);
  detail::visit_fields(data, w);
  w.put(std::string(kChecksumKey), checksum_text(checksum(data)));
  std::ostringstream out;
  out << kHeader << detail::toml_text_of(w.root) << "\n\n" << kEndMarker << "\n";
  return out.str();
}

FileResult<CalibrationData> parse_calibration_text(std::string_view text,
                                                   std::string_view file_name) {
  const std::string prefix = detail::file_prefix(file_name);
  if (!ends_with_marker(text)) {
    return FileStatus(ErrorCode::kDataLoss, prefix + "truncated: it does not end with the line \"" +
                                                std::string(kEndMarker) + "\" (" +
                                                std::to_string(text.size()) + " bytes read)");
  }
  try {
    const toml::table root = toml_text::safe_parse(text, file_name);
    return parse_table(root, prefix);
  } catch (const toml::parse_error& e) {
    const auto& at = e.source().begin;
    return FileStatus(ErrorCode::kDataLoss,
                      prefix + "line " + std::to_string(at.line) + ", column " +
                          std::to_string(at.column) +
                          ": TOML syntax error: " + drivers::lnx::printable_text(e.description()));
  } catch (const std::exception& e) {
    return FileStatus(ErrorCode::kInvalidArgument, prefix + "cannot be read: " + e.what());
  }
}

}  // namespace gfins::calib_file
