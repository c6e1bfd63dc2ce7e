// libFuzzer target: the CSV tables gfins-calibrate reads (host_sim/tools/src/csv.hpp): mean
// outputs per pose (--means), pose lists (--poses) and voltage recordings (--recording as CSV).
// The first byte picks the reader; the rest is the file, written to an in-memory file so the
// readers run exactly as on disk. Invariants: every accepted row obeys the documented ranges
// (means: sensor 1..6, attitude 1..1000, |mean_v| <= 100 V, 0 <= std_v <= 100 V with a count >= 1,
// no pose twice; poses and recordings: finite numbers), a refusal's message is printable.
#include <sys/mman.h>
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <set>
#include <string>
#include <utility>

#include "csv.hpp"
#include "fuzz_check.hpp"

namespace {

constexpr const char* kTarget = "calibration_tables";

// One in-memory file for the whole run, rewritten per input; its path goes through /proc.
struct MemFile {
  int fd = ::memfd_create("gfins-fuzz.csv", MFD_CLOEXEC);
  std::string path = "/proc/self/fd/" + std::to_string(fd);
  bool write(const std::uint8_t* data, std::size_t size) const {
    if (fd < 0 || ::ftruncate(fd, 0) != 0) return false;
    std::size_t done = 0;
    while (done < size) {
      const ssize_t n = ::pwrite(fd, data + done, size - done, static_cast<off_t>(done));
      if (n <= 0) return false;
      done += static_cast<std::size_t>(n);
    }
    return true;
  }
};

template <typename R>
bool refused(const R& r) {
  if (r.is_ok()) return false;
  gfins::fuzz::check(gfins::fuzz::printable_message(r.error().message), kTarget,
                     "a refusal's message is printable");
  return true;
}

void means(const std::string& path) {
  const auto r = gfins::tools::read_means(path);
  if (refused(r)) return;
  std::set<std::pair<int, int>> seen;
  for (const gfins::tools::MeanRow& m : r.value()) {
    gfins::fuzz::check(m.sensor >= 1 && m.sensor <= 6, kTarget, "sensor within 1..6");
    gfins::fuzz::check(m.attitude >= 1 && m.attitude <= 1000, kTarget, "attitude within 1..1000");
    gfins::fuzz::check(std::isfinite(m.mean_v) && std::fabs(m.mean_v) <= 100.0, kTarget,
                       "mean_v finite within 100 V");
    if (m.count > 0) {
      gfins::fuzz::check(std::isfinite(m.std_v) && m.std_v >= 0.0 && m.std_v <= 100.0, kTarget,
                         "std_v within 0..100 V");
    }
    gfins::fuzz::check(seen.insert({m.sensor, m.attitude}).second, kTarget, "no pose twice");
  }
}

void poses(const std::string& path) {
  const auto r = gfins::tools::read_poses(path);
  if (refused(r)) return;
  for (const gfins::tools::Pose& p : r.value()) {
    for (const double f : p.f_b_g) gfins::fuzz::check(std::isfinite(f), kTarget, "finite pose");
  }
}

void recording(const std::string& path) {
  const auto r = gfins::tools::read_recording(path);
  if (refused(r)) return;
  for (const auto& s : r.value().samples_v) {
    for (const double v : s) gfins::fuzz::check(std::isfinite(v), kTarget, "finite volts");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const MemFile file;
  if (size == 0) return 0;
  if (!file.write(data + 1, size - 1)) gfins::fuzz::fail(kTarget, "cannot write the memfd");
  switch (data[0] % 3) {
    case 0:
      means(file.path);
      break;
    case 1:
      poses(file.path);
      break;
    default:
      recording(file.path);
      break;
  }
  return 0;
}
