#include "gfins/app/logger.hpp"

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cstdio>

namespace gfins::app {

std::string format_record(const LogRecord& r) {
  std::string out;
  std::size_t arg = 0;
  // "{}" prints the argument in decimal, "{:#x}" in hexadecimal with 0x.
  for (const char* p = r.format; *p != '\0'; ++p) {
    if (p[0] != '{') {
      out += *p;
      continue;
    }
    const char* close = p;
    while (*close != '\0' && *close != '}') ++close;
    if (*close == '\0') {
      out += p;
      break;
    }
    const std::string spec(p + 1, close);
    if (arg >= LogRecord::kMaxArgs) {
      out += "?";
    } else if (spec.find('x') != std::string::npos) {
      char buf[24];
      std::snprintf(buf, sizeof buf, "0x%llx", static_cast<unsigned long long>(r.args[arg++]));
      out += buf;
    } else {
      out += std::to_string(r.args[arg++]);
    }
    p = close;
  }
  return out;
}

LogDrain::LogDrain(FwLogQueue& queue, LineFn line) : queue_(queue), line_(std::move(line)) {}

LogDrain::~LogDrain() { stop(); }

void LogDrain::start() {
  if (thread_.joinable()) return;
  stop_.store(false);
  thread_ = std::thread([this] {
    while (!stop_.load(std::memory_order_relaxed)) {
      drain();
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    drain();
  });
}

void LogDrain::stop() {
  if (!thread_.joinable()) return;
  stop_.store(true);
  thread_.join();
}

std::size_t LogDrain::drain() {
  std::size_t n = 0;
  LogRecord r;
  while (queue_.pop(r)) {
    const std::string text = "t=" + std::to_string(r.t_ns / 1000000) + "ms " + format_record(r);
    if (line_) {
      line_(r.level, text);
    } else {
      static constexpr spdlog::level::level_enum kLevels[] = {
          spdlog::level::trace, spdlog::level::debug, spdlog::level::info, spdlog::level::warn,
          spdlog::level::err};
      spdlog::log(kLevels[static_cast<int>(r.level)], "{}", text);
    }
    ++n;
  }
  return n;
}

void init_spdlog(const std::string& level) {
  auto logger = spdlog::stderr_color_mt("gfins-fw");
  logger->set_pattern("[%Y-%m-%d %H:%M:%S.%e] [%^%l%$] %v");
  logger->set_level(spdlog::level::from_str(level));
  spdlog::set_default_logger(logger);
}

}  // namespace gfins::app
