// Two outputs of one run that name the same file: the second would overwrite or interleave with
// the first (`gfins-fw --can-log X --latency-csv X` wrote the latency table over the start of
// the CAN log). Checked before the work, with the options' names in the message.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace gfins::drivers::lnx {

/// An output of a run: what names it (an option, a configuration key, "the run's summary.txt")
/// and its path ("" = not written this run).
struct NamedOutput {
  std::string_view what;
  std::string path;
};

/// What stands at a path that is not a regular file, from its st_mode (stat(2)): "a symbolic
/// link", "a folder", "a device node", "a FIFO", "a socket", "a special file"; nullptr for a
/// regular file. One wording for every tool that refuses such a path (an atomic save would
/// replace it with a regular file; a recording is read by offset).
const char* non_regular_kind(unsigned st_mode);

/// True when `a` and `b` are one file: the same inode when both exist, else the same path once
/// '.', '..' and symbolic links are resolved. A character device (/dev/null) is never a clash:
/// writing two streams to it loses nothing that was not meant to be lost.
bool same_output_file(const std::string& a, const std::string& b);

/// "<what> and <what> name the same file '<path>': each output needs a file of its own" for the
/// first two of `outputs` that are one file; nullopt when every output has its own.
std::optional<std::string> output_clash(std::span<const NamedOutput> outputs);

}  // namespace gfins::drivers::lnx
