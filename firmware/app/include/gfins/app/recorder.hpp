// The board's raw-sample recorder (docs/replay.md, "Recording on the board"; byte layout in
// docs/recording-format.md, version 2): every sample the loop read and every CAN frame it
// received, in the order the loop handled them, so that `gfins-fw --replay` runs the same loop
// over the same input and publishes the same navigation.
//
// The loop encodes each record (32 bytes, the codec of nav_core/recording) and pushes it into a
// RecordQueue, never waiting; the recorder's thread drains the queue every few milliseconds and
// writes blocks with their CRC to the file. A full queue drops records and counts them
// (HealthCounters::record_dropped): a recording with a hole is reported as such at the end.
#pragma once

#include <atomic>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "gfins/app/record_queue.hpp"
#include "gfins/recording/codec.hpp"

namespace gfins::app {

class Recorder {
 public:
  struct Opened {
    std::unique_ptr<Recorder> recorder;
    std::string error;  // "" when opened
  };
  /// Creates `path` and writes the header (record count "unknown" until stop()).
  static Opened open(const std::string& path, const recording::Header& header);
  ~Recorder();
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  RecordQueue& queue() { return queue_; }
  /// The writer thread (10 ms period).
  void start();
  /// Joins the thread, writes what is queued and the last block, patches the record count into
  /// the header and closes the file. "" when every record reached the file, else what failed or
  /// how many records were lost.
  std::string stop();
  /// Writes what is queued now (the thread calls it; tests may call it directly).
  void drain();
  std::uint64_t records_written() const { return records_; }

 private:
  Recorder(std::FILE* file, std::string path, const recording::Header& header);
  void write_block();

  std::FILE* file_;
  std::string path_;
  recording::Header header_;
  RecordQueue queue_;
  std::vector<std::uint8_t> block_;  // records of the block being filled, then its CRC
  std::uint64_t records_ = 0;        // records in the file or in block_
  std::string error_;                // the first write error; nothing written after it
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace gfins::app
