// The CAN settings a command changes (node id, dividers), kept across restarts in a small file
// (can.settings_file; docs/can-interface.md, "Stored settings"): versioned, checksummed, saved
// atomically by a writer thread so that the sample loop never touches a file.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>

#include "gfins/app/config.hpp"
#include "gfins/app/ports.hpp"

namespace gfins::app {

/// The settings file's format_version this build writes and reads.
inline constexpr int kSettingsFormatVersion = 1;

/// GfinsCommandCounters.SettingsSource (the message table's kSettingsSourceValues).
enum class SettingsSource : std::uint8_t {
  kConfiguration = 0,  // nothing stored: the configuration's settings
  kStored = 1,         // the stored settings
  kStoredCorrupt = 2,  // the stored settings were unreadable, corrupt or refused: configuration
  kSaveFailed = 3,     // a change could not be stored: it is in use until the board restarts
};

/// The node id and dividers of a configuration.
CanSettings settings_of(const FwConfig& c);
/// Puts `s` into `c` (can.node_id, [output]).
void apply_settings(const CanSettings& s, FwConfig& c);

/// The file's text: format_version, node_id, [output] and [integrity] checksum =
/// 'fnv1a64:<16 hex digits>' of the canonical lines "format_version=1\nnode_id=N\n" and
/// "output.NAME=D\n" per message in the table's order.
std::string settings_text(const CanSettings& s);

struct SettingsParse {
  std::optional<CanSettings> settings;
  std::string error;  // "source[:line]: what is wrong" when !settings
};
/// Reads a settings text: every key present and known, the version this build reads, the
/// checksum right, and the result valid under the configuration's rules with `base` (bus budget,
/// divider rules) — else an error naming the source, the key and the rule.
SettingsParse parse_settings(std::string_view text, const std::string& source,
                             const FwConfig& base);

struct StartupSettings {
  SettingsSource source = SettingsSource::kConfiguration;
  std::string message;  // what happened; empty when no settings file is configured
};
/// Reads c.can_settings_file (when set) and applies a valid one to `c`. Missing: the
/// configuration's settings. Unreadable, corrupt or refused by the rules: the configuration's
/// settings, kStoredCorrupt and a message naming the file and the problem. Never writes.
StartupSettings load_stored_settings(FwConfig& c);

/// Keeps the settings the loop posts in `path` (atomic save; nullopt removes the file), on its
/// own thread. The loop's side (post, source) never blocks or allocates.
class SettingsWriter final : public SettingsPort {
 public:
  SettingsWriter(std::string path, SettingsSource initial);
  ~SettingsWriter() override;
  SettingsWriter(const SettingsWriter&) = delete;
  SettingsWriter& operator=(const SettingsWriter&) = delete;

  bool post(const std::optional<CanSettings>& s) override;
  std::uint8_t source() const override { return source_.load(); }

  /// Host side only (tests, shutdown), blocking: returns once nothing posted waits to be written.
  void wait_settled();

 private:
  void run();
  void write(const std::optional<CanSettings>& s);

  std::string path_;
  std::mutex mutex_;  // guards pending_, has_pending_, stop_; the loop only ever try_locks it
  std::condition_variable wake_;
  std::condition_variable settled_;
  std::optional<CanSettings> pending_;
  bool has_pending_ = false;
  bool busy_ = false;  // the worker is writing
  bool stop_ = false;
  std::atomic<std::uint8_t> source_{0};
  std::thread thread_;
};

}  // namespace gfins::app
