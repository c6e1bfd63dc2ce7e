#include "host_io.hpp"

#include <cstring>

#include "gfins/host_sim/data_paths.hpp"

#if GFINS_CAN_HAVE_SOCKETCAN
#include "gfins/drivers/lnx/socket_can.hpp"
#endif
#if GFINS_CAN_HAVE_SPAWN
#include "gfins/drivers/lnx/spawn.hpp"
#endif

namespace gfins::can_tool {

Result<std::unique_ptr<hal::CanBus>> open_live_bus(const std::string& interface) {
#if GFINS_CAN_HAVE_SOCKETCAN
  drivers::lnx::SocketCanConfig cfg;
  cfg.interface = interface;
  auto bus = drivers::lnx::SocketCan::open(cfg);
  if (!bus.is_ok()) return bus.status();
  return std::unique_ptr<hal::CanBus>(std::move(bus).value());
#else
  (void)interface;
  return Status(ErrorCode::kUnimplemented,
                "this gfins-can was built without the SocketCAN backend (drivers/linux)");
#endif
}

Status run_without_shell(const std::vector<std::string>& argv, std::string* detail) {
#if GFINS_CAN_HAVE_SPAWN
  const auto r = drivers::lnx::run_program(argv);
  if (!r.is_ok()) return r.status();
  if (!r->ok()) {
    if (detail != nullptr) *detail = drivers::lnx::describe(*r);
    return Status(ErrorCode::kFailedPrecondition, "the plot script failed");
  }
  return Status::ok();
#else
  (void)argv;
  if (detail != nullptr) *detail = "built without the process backend (drivers/linux spawn)";
  return Status(ErrorCode::kUnimplemented, "cannot start helper programs in this build");
#endif
}

void for_each_line(std::FILE* f, const std::function<void(std::uint64_t, std::string_view)>& fn,
                   std::size_t max_line) {
  const std::size_t cap = max_line + 1;  // longer lines reach the parser cut here
  std::vector<char> buf(1 << 16);
  std::string cur;  // the unfinished line of the previous chunk (bounded by cap)
  auto append_bounded = [&](std::string_view v) {
    if (cur.size() < cap) cur.append(v.substr(0, cap - cur.size()));
  };
  std::uint64_t line_no = 0;
  bool partial = false;
  std::size_t n = 0;
  while ((n = std::fread(buf.data(), 1, buf.size(), f)) > 0) {
    std::size_t start = 0;
    while (true) {
      const void* nl = std::memchr(buf.data() + start, '\n', n - start);
      if (nl == nullptr) {
        append_bounded(std::string_view(buf.data() + start, n - start));
        partial = partial || start < n;
        break;
      }
      const auto i = static_cast<std::size_t>(static_cast<const char*>(nl) - buf.data());
      const std::string_view piece(buf.data() + start, i - start);
      ++line_no;
      if (!partial) {
        fn(line_no, piece.substr(0, cap));
      } else {
        append_bounded(piece);
        fn(line_no, cur);
        cur.clear();
        partial = false;
      }
      start = i + 1;
    }
  }
  if (partial) fn(++line_no, cur);
}

std::filesystem::path find_script(const std::string& name) {
  // $GFINS_SCRIPTS_DIR, else PREFIX/share/gfins/scripts next to the program (an install, or the
  // build tree's share/gfins, which links to the sources): no build path is compiled in.
  const paths::DataLookup dir = paths::scripts_dir();
  if (!dir.found()) return std::filesystem::path(name);
  return dir.dir / name;
}

}  // namespace gfins::can_tool
