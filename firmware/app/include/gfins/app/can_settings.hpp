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

/// The file's text: format_version, node_id (when set), [output] (the dividers set) and
/// [integrity] checksum = 'fnv1a64:<16 hex digits>' of the canonical lines "format_version=1\n",
/// "node_id=N\n" (when set) and "output.NAME=D\n" per divider set, in the table's order.
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
  CanSettings stored;   // what the file holds (empty when it is missing or refused)
  std::string message;  // what happened; empty when no settings file is configured
};
/// Reads c.can_settings_file (when set) and applies a valid one to `c`: each stored value
/// replaces the configuration's, except those the command line gave (c.node_id_from_cli,
/// c.dividers_from_cli), which win and are named in the message. Missing: the configuration's
/// settings. Not a regular file, unreadable, corrupt or refused by the rules: the configuration's
/// settings, kStoredCorrupt and a message naming the file and the problem. Never writes.
StartupSettings load_stored_settings(FwConfig& c);

/// Keeps the settings the loop posts in `path` (atomic save; empty settings remove the file, its
/// folder synced), on its own thread. The loop's side (post, source) never blocks or allocates.
class SettingsWriter final : public SettingsPort {
 public:
  SettingsWriter(std::string path, SettingsSource initial);
  ~SettingsWriter() override;
  SettingsWriter(const SettingsWriter&) = delete;
  SettingsWriter& operator=(const SettingsWriter&) = delete;

  bool post(const CanSettings& s) override;
  std::uint8_t source() const override { return source_.load(); }

  /// Host side only (tests, shutdown), blocking: returns once nothing posted waits to be written.
  void wait_settled();

 private:
  void run();
  void write(const CanSettings& s);

  std::string path_;
  std::mutex mutex_;  // guards pending_, has_pending_, stop_; the loop only ever try_locks it
  std::condition_variable wake_;
  std::condition_variable settled_;
  CanSettings pending_;
  bool has_pending_ = false;
  bool busy_ = false;  // the worker is writing
  bool stop_ = false;
  std::atomic<std::uint8_t> source_{0};
  std::thread thread_;
};

}  // namespace gfins::app
