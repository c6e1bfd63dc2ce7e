#include "gfins/app/can_settings.hpp"

#include <spdlog/spdlog.h>

#include <cerrno>
#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <span>

#include "gfins/checksum/fnv1a.hpp"
#include "gfins/drivers/lnx/file_parameter_store.hpp"
#include "gfins/drivers/lnx/text_file.hpp"
#include "gfins/toml/safe_parse.hpp"

namespace gfins::app {
namespace {

/// The lines the checksum covers, in a fixed order (independent of the file's layout).
std::string canonical(const CanSettings& s) {
  std::string out = "format_version=" + std::to_string(kSettingsFormatVersion) +
                    "\nnode_id=" + std::to_string(s.node_id) + "\n";
  for (std::size_t m = 0; m < kNumMessages; ++m) {
    out += "output." + std::string(kMessageNames[m]) + "=" + std::to_string(s.dividers[m]) + "\n";
  }
  return out;
}

std::string checksum_text(const CanSettings& s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "fnv1a64:%016" PRIx64, fnv1a64(canonical(s)));
  return buf;
}

struct ParseError {
  std::string message;
};

/// "source:line: message" for a node of the file.
[[noreturn]] void fail(const std::string& source, const toml::node* n, const std::string& what) {
  std::string m = source;
  if (n != nullptr && n->source().begin.line > 0) {
    m += ":" + std::to_string(n->source().begin.line);
  }
  throw ParseError{m + ": " + what};
}

std::int64_t integer(const toml::table& t, const std::string& source, const std::string& key,
                     std::int64_t lo, std::int64_t hi) {
  const toml::node* n = t.at_path(key).node();
  if (n == nullptr) fail(source, nullptr, key + " is missing");
  const auto* i = n->as_integer();
  if (i == nullptr || i->get() < lo || i->get() > hi) {
    fail(source, n, key + " must be an integer " + std::to_string(lo) + ".." + std::to_string(hi));
  }
  return i->get();
}

/// Every key of the file is one this version writes: a stray key would not be covered by the
/// checksum.
void reject_unknown(const toml::table& root, const std::string& source) {
  for (const auto& [k, node] : root) {
    const std::string_view name = k.str();
    if (name == "format_version" || name == "node_id") continue;
    if (name == "output" && node.is_table()) {
      for (const auto& [mk, mnode] : *node.as_table()) {
        if (message_index(mk.str()) < 0) {
          fail(source, &mnode, "unknown key output." + quote_text(mk.str()).substr(0, 60));
        }
      }
      continue;
    }
    if (name == "integrity" && node.is_table()) {
      for (const auto& [ik, inode] : *node.as_table()) {
        if (ik.str() != "checksum") {
          fail(source, &inode, "unknown key integrity." + quote_text(ik.str()).substr(0, 60));
        }
      }
      continue;
    }
    fail(source, &node, "unknown key " + quote_text(name));
  }
}

}  // namespace

CanSettings settings_of(const FwConfig& c) {
  CanSettings s;
  s.node_id = static_cast<std::uint8_t>(c.node_id);
  s.dividers = c.dividers;
  return s;
}

void apply_settings(const CanSettings& s, FwConfig& c) {
  c.node_id = s.node_id;
  c.dividers = s.dividers;
}

std::string settings_text(const CanSettings& s) {
  std::string out =
      "# gfins CAN settings, written by the board when a command changed them\n"
      "# (docs/can-interface.md, \"Stored settings\"). Do not edit: the checksum covers every "
      "value;\n# a file that does not match it is ignored and the board says so on the bus.\n";
  out += "format_version = " + std::to_string(kSettingsFormatVersion) + "\n";
  out += "node_id = " + std::to_string(s.node_id) + "\n\n[output]\n";
  for (std::size_t m = 0; m < kNumMessages; ++m) {
    out += std::string(kMessageNames[m]) + " = " + std::to_string(s.dividers[m]) + "\n";
  }
  out += "\n[integrity]\nchecksum = '" + checksum_text(s) + "'\n";
  return out;
}

SettingsParse parse_settings(std::string_view text, const std::string& source,
                             const FwConfig& base) {
  SettingsParse out;
  try {
    const toml::table root = toml_text::safe_parse(text, source);
    reject_unknown(root, source);
    const toml::node* version = root.get("format_version");
    const std::int64_t v = integer(root, source, "format_version", 0, INT32_MAX);
    if (v != kSettingsFormatVersion) {
      fail(source, version,
           "format_version = " + std::to_string(v) + ": this build reads version " +
               std::to_string(kSettingsFormatVersion));
    }
    CanSettings s;
    s.node_id = static_cast<std::uint8_t>(integer(root, source, "node_id", 0, kMaxNodeId));
    for (std::size_t m = 0; m < kNumMessages; ++m) {
      s.dividers[m] = static_cast<std::uint16_t>(
          integer(root, source, "output." + std::string(kMessageNames[m]), 0, kMaxDivider));
    }
    const toml::node* sum = root.at_path("integrity.checksum").node();
    if (sum == nullptr || !sum->is_string()) {
      fail(source, sum, "integrity.checksum is missing (a string 'fnv1a64:...')");
    }
    const std::string stored = sum->value<std::string>().value_or("");
    const std::string computed = checksum_text(s);
    if (stored != computed) {
      fail(source, sum,
           "integrity.checksum = " + quote_text(stored) + " but the values give '" + computed +
               "': the file was changed or damaged");
    }
    FwConfig c = base;
    apply_settings(s, c);
    if (std::optional<ConfigProblem> p = check(c)) {
      fail(source, nullptr,
           "the stored " + p->key + " = " + p->value + " breaks the configuration's rules: " +
               p->allowed);
    }
    out.settings = s;
  } catch (const toml::parse_error& e) {
    out.error = source + ":" + std::to_string(e.source().begin.line) +
                ": TOML syntax: " + printable_text(e.description());
  } catch (const ParseError& e) {
    out.error = e.message;
  } catch (const std::exception& e) {
    out.error = source + ": " + e.what();
  }
  return out;
}

StartupSettings load_stored_settings(FwConfig& c) {
  StartupSettings out;
  if (c.can_settings_file.empty()) return out;
  std::string text;
  constexpr std::size_t kMaxBytes = hal::ParameterStore::kMaxBytes;
  const Status st = drivers::lnx::read_text_file(c.can_settings_file.c_str(), kMaxBytes, text);
  if (!st.is_ok()) {
    if (st.code() == ErrorCode::kIoError && st.os_error() == ENOENT) {
      out.message = "can.settings_file " + quote_text(c.can_settings_file) +
                    ": nothing stored yet, the configuration's node id and dividers are used";
      return out;
    }
    out.source = SettingsSource::kStoredCorrupt;
    out.message = "stored CAN settings ignored, the configuration's are used: " +
                  drivers::lnx::text_file_error(c.can_settings_file, st, kMaxBytes,
                                                "a settings file");
    return out;
  }
  const SettingsParse p = parse_settings(text, c.can_settings_file, c);
  if (!p.settings) {
    out.source = SettingsSource::kStoredCorrupt;
    out.message = "stored CAN settings ignored, the configuration's are used: " + p.error;
    return out;
  }
  apply_settings(*p.settings, c);
  out.source = SettingsSource::kStored;
  out.message = "stored CAN settings from " + quote_text(c.can_settings_file) + ": node id " +
                std::to_string(p.settings->node_id);
  return out;
}

SettingsWriter::SettingsWriter(std::string path, SettingsSource initial)
    : path_(std::move(path)), source_(static_cast<std::uint8_t>(initial)) {
  thread_ = std::thread([this] { run(); });
}

SettingsWriter::~SettingsWriter() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
    wake_.notify_all();
  }
  thread_.join();
}

bool SettingsWriter::post(const std::optional<CanSettings>& s) {
  // try_lock: the worker holds the mutex only while taking a request, never while writing.
  if (!mutex_.try_lock()) return false;
  pending_ = s;
  has_pending_ = true;
  wake_.notify_one();
  mutex_.unlock();
  return true;
}

void SettingsWriter::wait_settled() {
  std::unique_lock<std::mutex> lock(mutex_);
  settled_.wait(lock, [this] { return !has_pending_ && !busy_; });
}

void SettingsWriter::write(const std::optional<CanSettings>& s) {
  if (!s) {
    // Restore defaults: nothing stored from now on.
    if (std::remove(path_.c_str()) != 0 && errno != ENOENT) {
      spdlog::error("can.settings_file {}: cannot remove it: {}", quote_text(path_),
                    std::strerror(errno));
      source_.store(static_cast<std::uint8_t>(SettingsSource::kSaveFailed));
      return;
    }
    spdlog::info("stored CAN settings removed: the configuration's apply from the next start");
    source_.store(static_cast<std::uint8_t>(SettingsSource::kConfiguration));
    return;
  }
  const std::string text = settings_text(*s);
  const Status st = drivers::lnx::save_file_atomically(path_, std::span(text.data(), text.size()));
  if (!st.is_ok()) {
    spdlog::error("can.settings_file {}: the changed settings could not be stored (in use until "
                  "the board restarts): {}",
                  quote_text(path_), st.message());
    source_.store(static_cast<std::uint8_t>(SettingsSource::kSaveFailed));
    return;
  }
  spdlog::info("CAN settings stored in {} (node id {} from the next start)", quote_text(path_),
               s->node_id);
  source_.store(static_cast<std::uint8_t>(SettingsSource::kStored));
}

void SettingsWriter::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_.wait(lock, [this] { return stop_ || has_pending_; });
    // A change posted just before the stop is still written.
    if (!has_pending_) return;
    const std::optional<CanSettings> s = pending_;
    has_pending_ = false;
    busy_ = true;
    lock.unlock();
    write(s);
    lock.lock();
    busy_ = false;
    settled_.notify_all();
  }
}

}  // namespace gfins::app
