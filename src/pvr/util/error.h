#pragma once
// User-facing errors: bad input, unsupported options, exhausted resources. The command line
// prints what() as one line and exits non-zero; library code never exits by itself.
#include <stdexcept>
#include <string>

namespace pvr {
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};
}  // namespace pvr
