#include "decode_session.hpp"

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <thread>

#include "host_io.hpp"

namespace gfins::can_tool {

DecodeEnd decode_end(const Summary& s, bool input_error, int node) {
  if (input_error) return DecodeEnd::kInputError;
  if (s.total_issues() != 0) return DecodeEnd::kProblems;
  if (s.frames == 0) return DecodeEnd::kNoFrames;
  if (node >= 0 && (s.nodes_seen & (1u << static_cast<unsigned>(node))) == 0) {
    return DecodeEnd::kNoFrames;
  }
  return DecodeEnd::kOk;
}

std::string node_list(std::uint16_t nodes_seen) {
  std::string s;
  for (unsigned n = 0; n < 16; ++n) {
    if ((nodes_seen & (1u << n)) == 0) continue;
    if (!s.empty()) s += ", ";
    s += std::to_string(n);
  }
  return s.empty() ? "none" : s;
}

std::string display_name(std::string_view name) {
  bool plain = !name.empty();
  for (char c : name) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u >= 0x7F || c == ':' || c == '"' || c == '\\') plain = false;
  }
  if (plain) return std::string(name);
  std::string out = "\"";
  for (char c : name) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (c == '\n') {
      out += "\\n";
    } else if (c == '\t') {
      out += "\\t";
    } else if (c == '\r') {
      out += "\\r";
    } else if (u < 0x20 || u >= 0x7F) {
      static constexpr char kHex[] = "0123456789abcdef";
      out += "\\x";
      out += kHex[u >> 4];
      out += kHex[u & 0xFu];
    } else {
      out += c;
    }
  }
  return out + "\"";
}

std::string decode_log(const std::string& path, StreamDecoder& dec) {
  const std::string shown = path == "-" ? std::string("stdin") : "'" + display_name(path) + "'";
  if (path != "-") {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec))
      return shown + " is a directory, not a candump log";
  }
  std::FILE* f = path == "-" ? stdin : std::fopen(path.c_str(), "rb");
  if (f == nullptr) return "cannot open " + shown + ": " + std::strerror(errno);
  errno = 0;
  for_each_line(f, [&](std::uint64_t line, std::string_view text) { dec.feed_line(line, text); });
  std::string error;
  if (std::ferror(f) != 0) {
    error = "read error on " + shown + ": " + std::strerror(errno != 0 ? errno : EIO);
  }
  if (f != stdin && std::fclose(f) != 0 && error.empty()) {
    error = "cannot close " + shown + ": " + std::strerror(errno);
  }
  return error;
}

void print_summary(const Summary& s, std::FILE* out) {
  std::fprintf(
      out,
      "summary: %llu lines, %llu frames (%llu ok), %llu epochs, %llu commands, "
      "%llu responses, %llu problems\n",
      static_cast<unsigned long long>(s.lines), static_cast<unsigned long long>(s.frames),
      static_cast<unsigned long long>(s.frames_ok), static_cast<unsigned long long>(s.epochs),
      static_cast<unsigned long long>(s.commands), static_cast<unsigned long long>(s.responses),
      static_cast<unsigned long long>(s.total_issues()));
  if (s.inputs != 0) {
    std::fprintf(out, "  aiding inputs: %llu frames, %llu fixes/headings decoded\n",
                 static_cast<unsigned long long>(s.inputs),
                 static_cast<unsigned long long>(s.fixes));
  }
  for (std::size_t k = 0; k < s.issues.size(); ++k) {
    if (s.issues[k] == 0) continue;
    std::fprintf(out, "  %-20s %llu\n", to_string(static_cast<IssueKind>(k)),
                 static_cast<unsigned long long>(s.issues[k]));
  }
  if (s.comment_lines != 0 || s.leading_frames != 0 || s.restarts != 0) {
    std::fprintf(out,
                 "  not problems: %llu blank/comment lines skipped, %llu frames of a leading "
                 "partial epoch, %llu restarts\n",
                 static_cast<unsigned long long>(s.comment_lines),
                 static_cast<unsigned long long>(s.leading_frames),
                 static_cast<unsigned long long>(s.restarts));
  }
  std::fprintf(out, "  nodes: %s\n", node_list(s.nodes_seen).c_str());
  std::fprintf(out, "  frames per message:");
  for (std::size_t m = 0; m < s.per_message.size(); ++m) {
    if (s.per_message[m] == 0) continue;
    std::fprintf(out, " %s=%llu", std::string(can::kMessages[m].name).c_str(),
                 static_cast<unsigned long long>(s.per_message[m]));
  }
  std::putc('\n', out);
}

std::uint64_t feed_live(hal::CanBus& bus, StreamDecoder& dec,
                        const std::function<bool()>& keep_going,
                        const std::function<std::int64_t()>& now_us, std::int64_t poll_ns) {
  std::uint64_t n = 0;
  while (keep_going()) {
    bus.service();
    const Result<hal::CanFrame> f = bus.receive(poll_ns);
    if (!f.is_ok()) {
      // kTimeout waited poll_ns already; an interface that is down answers at once, so wait
      // here instead of spinning until it comes back.
      if (f.status().code() != ErrorCode::kTimeout) {
        std::this_thread::sleep_for(std::chrono::nanoseconds(poll_ns));
      }
      continue;
    }
    dec.feed_frame(++n, now_us(), f.value());
  }
  return n;
}

}  // namespace gfins::can_tool
