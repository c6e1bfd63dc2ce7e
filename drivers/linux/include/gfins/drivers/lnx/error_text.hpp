// Turning a backend's Status into the one-line message a person reads.
//
// A gfins::Status carries a static message and the errno of the failed call (os_error()) so the
// per-sample path never allocates. The names that make a message useful (the interface, the
// device path) are known to whoever opened the backend; this helper joins the three at the
// place where the error is reported, which is start-up or a log thread, never the loop.
#pragma once

#include <string>
#include <string_view>

#include "gfins/status/status.hpp"

namespace gfins::drivers::lnx {

/// "<subject>: <message>: <strerror(os_error)> (errno N)", or without the errno part when the
/// status did not come from the OS. Example: "can0: socket(PF_CAN, SOCK_RAW, CAN_RAW) failed:
/// Address family not supported by protocol (errno 97)".
std::string describe(std::string_view subject, const Status& status);

}  // namespace gfins::drivers::lnx
