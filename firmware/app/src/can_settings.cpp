#include "gfins/app/can_settings.hpp"

#include <spdlog/spdlog.h>

#include <cerrno>
#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <span>
#include <system_error>

#include "gfins/checksum/fnv1a.hpp"
#include "gfins/drivers/lnx/file_parameter_store.hpp"
#include "gfins/drivers/lnx/text_file.hpp"
#include "gfins/toml/safe_parse.hpp"

namespace gfins::app {
namespace {

/// A group's key in the file: the configuration's without "can." (data_id_base, ...).
std::string_view id_base_key(std::size_t g) { return kIdBaseKeys[g].substr(4); }

/// The group whose key `name` is, or kIdGroupCount.
std::size_t id_base_group(std::string_view name) {
  for (std::size_t g = 0; g < can::kIdGroupCount; ++g) {
    if (id_base_key(g) == name) return g;
  }
  return can::kIdGroupCount;
}

/// The lines the checksum covers, in a fixed order (independent of the file's layout).
std::string canonical(const CanSettings& s) {
  std::string out = "format_version=" + std::to_string(kSettingsFormatVersion) + "\n";
  if (s.node_id) out += "node_id=" + std::to_string(*s.node_id) + "\n";
  for (std::size_t m = 0; m < kNumMessages; ++m) {
    if (!s.dividers[m]) continue;
    out += "output." + std::string(kMessageNames[m]) + "=" + std::to_string(*s.dividers[m]) + "\n";
  }
  for (std::size_t g = 0; g < can::kIdGroupCount; ++g) {
    if (!s.id_bases[g]) continue;
    out += std::string(id_base_key(g)) + "=" + std::to_string(*s.id_bases[g]) + "\n";
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
    if (name == "format_version" || name == "node_id" || id_base_group(name) < can::kIdGroupCount) {
      continue;
    }
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

std::string settings_text(const CanSettings& s) {
  std::string out =
      "# gfins CAN settings, written by the board when a command changed them\n"
      "# (docs/can-interface.md, \"Stored settings\"): only what a command set; the rest is the\n"
      "# configuration's. Do not edit: the checksum covers every value; a file that does not\n"
      "# match it is ignored and the board says so on the bus.\n";
  out += "format_version = " + std::to_string(kSettingsFormatVersion) + "\n";
  if (s.node_id) out += "node_id = " + std::to_string(*s.node_id) + "\n";
  for (std::size_t g = 0; g < can::kIdGroupCount; ++g) {
    if (s.id_bases[g]) out += std::string(id_base_key(g)) + " = " + hex_id(*s.id_bases[g]) + "\n";
  }
  out += "\n[output]\n";
  for (std::size_t m = 0; m < kNumMessages; ++m) {
    if (!s.dividers[m]) continue;
    out += std::string(kMessageNames[m]) + " = " + std::to_string(*s.dividers[m]) + "\n";
  }
  out += "\n[integrity]\nchecksum = '" + checksum_text(s) + "'\n";
  return out;
}

namespace {

/// `s` put into `c`, except what the command line gave; `overridden` names those.
void apply_stored(const CanSettings& s, FwConfig& c, std::string* overridden) {
  const auto note = [&](const std::string& what) {
    if (overridden != nullptr) *overridden += (overridden->empty() ? "" : ", ") + what;
  };
  if (s.node_id) {
    if (c.node_id_from_cli) {
      note("node_id = " + std::to_string(*s.node_id) + " (--node-id " + std::to_string(c.node_id) +
           ")");
    } else {
      c.node_id = *s.node_id;
    }
  }
  for (std::size_t g = 0; g < can::kIdGroupCount; ++g) {
    if (s.id_bases[g]) c.id_bases[g] = *s.id_bases[g];
  }
  for (std::size_t m = 0; m < kNumMessages; ++m) {
    if (!s.dividers[m]) continue;
    if (((c.dividers_from_cli >> m) & 1u) != 0) {
      note("output." + std::string(kMessageNames[m]) + " = " + std::to_string(*s.dividers[m]) +
           " (--divider " + std::string(kMessageNames[m]) + "=" + std::to_string(c.dividers[m]) +
           ")");
    } else {
      c.dividers[m] = *s.dividers[m];
    }
  }
}

}  // namespace

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
    if (root.get("node_id") != nullptr) {
      s.node_id = static_cast<std::uint8_t>(integer(root, source, "node_id", 0, kMaxNodeId));
    }
    for (std::size_t g = 0; g < can::kIdGroupCount; ++g) {
      const std::string key(id_base_key(g));
      if (root.get(key) == nullptr) continue;
      s.id_bases[g] = static_cast<std::uint16_t>(integer(root, source, key, 0, 0x7FF));
    }
    for (std::size_t m = 0; m < kNumMessages; ++m) {
      const std::string key = "output." + std::string(kMessageNames[m]);
      if (root.at_path(key).node() == nullptr) continue;
      s.dividers[m] = static_cast<std::uint16_t>(integer(root, source, key, 0, kMaxDivider));
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
    apply_stored(s, c, nullptr);
    if (std::optional<ConfigProblem> p = check(c)) {
      fail(source, nullptr,
           "the stored " + p->key + " = " + p->value +
               " breaks the configuration's rules: " + p->allowed);
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
  const std::string shown = quote_text(c.can_settings_file);
  // Only a regular file is read (the board's save only writes one): a FIFO would block the
  // start, a device would never end.
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status st = fs::symlink_status(c.can_settings_file, ec);
  if (st.type() == fs::file_type::not_found) {
    out.message =
        "can.settings_file " + shown +
        ": nothing stored yet, the configuration's node id, dividers and identifier groups are "
        "used";
    return out;
  }
  if (!ec && st.type() != fs::file_type::regular) {
    out.source = SettingsSource::kStoredCorrupt;
    out.message = "stored CAN settings ignored, the configuration's are used: can.settings_file " +
                  shown + " is not a regular file (a folder, link, FIFO, device or socket)";
    return out;
  }
  std::string text;
  constexpr std::size_t kMaxBytes = hal::ParameterStore::kMaxBytes;
  const Status read = drivers::lnx::read_text_file(c.can_settings_file.c_str(), kMaxBytes, text);
  if (!read.is_ok()) {
    out.source = SettingsSource::kStoredCorrupt;
    out.message =
        "stored CAN settings ignored, the configuration's are used: " +
        drivers::lnx::text_file_error(c.can_settings_file, read, kMaxBytes, "a settings file");
    return out;
  }
  const SettingsParse p = parse_settings(text, c.can_settings_file, c);
  if (!p.settings) {
    out.source = SettingsSource::kStoredCorrupt;
    out.message = "stored CAN settings ignored, the configuration's are used: " + p.error;
    return out;
  }
  std::string overridden;
  apply_stored(*p.settings, c, &overridden);
  out.source = SettingsSource::kStored;
  out.stored = *p.settings;
  out.message = "stored CAN settings from " + shown + ": node id " + std::to_string(c.node_id);
  for (std::size_t g = 0; g < can::kIdGroupCount; ++g) {
    if (p.settings->id_bases[g]) {
      out.message += ", " + std::string(kIdBaseKeys[g]) + " " + hex_id(*p.settings->id_bases[g]);
    }
  }
  if (!overridden.empty()) {
    out.message += "; the command line wins over the stored " + overridden;
  }
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

bool SettingsWriter::post(const CanSettings& s) {
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

void SettingsWriter::write(const CanSettings& s) {
  if (s.empty()) {
    // Restore defaults: nothing stored from now on (the removal synced, as a save is).
    if (const Status st = drivers::lnx::remove_file_durably(path_); !st.is_ok()) {
      spdlog::error("can.settings_file {}: cannot remove it: {}", quote_text(path_), st.message());
      source_.store(static_cast<std::uint8_t>(SettingsSource::kSaveFailed));
      return;
    }
    spdlog::info("stored CAN settings removed: the configuration's apply from the next start");
    source_.store(static_cast<std::uint8_t>(SettingsSource::kConfiguration));
    return;
  }
  const std::string text = settings_text(s);
  const Status st = drivers::lnx::save_file_atomically(path_, std::span(text.data(), text.size()));
  if (!st.is_ok()) {
    spdlog::error(
        "can.settings_file {}: the changed settings could not be stored (in use until "
        "the board restarts): {}",
        quote_text(path_), st.message());
    source_.store(static_cast<std::uint8_t>(SettingsSource::kSaveFailed));
    return;
  }
  spdlog::info("CAN settings stored in {}", quote_text(path_));
  source_.store(static_cast<std::uint8_t>(SettingsSource::kStored));
}

void SettingsWriter::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_.wait(lock, [this] { return stop_ || has_pending_; });
    // A change posted just before the stop is still written.
    if (!has_pending_) return;
    const CanSettings s = pending_;
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
