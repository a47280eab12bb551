// libFuzzer harness: the command line (CLI11 parsing of every command, then the render options'
// conversion and checks, settings files included) through runCli in CheckOnly mode, so that no
// scene is loaded and nothing is rendered or written. The input is the argument list, one
// argument per line, after "photonvr".
#include <cstdint>
#include <string>
#include <vector>

#include "pvr/app/cli.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  // Paths into /dev, /proc or /sys can name endless or blocking files (/dev/stdin): what a user
  // may ask for, not a parser's finding.
  for (const char* special : {"/dev", "/proc", "/sys"})
    if (text.find(special) != std::string::npos) return 0;
  std::vector<std::string> args = {"photonvr"};
  for (size_t start = 0; start <= text.size() && args.size() < 64;) {
    const size_t end = std::min(text.find('\n', start), text.size());
    args.push_back(text.substr(start, end - start));
    start = end + 1;
  }
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pvr::runCli(int(args.size()), argv.data(), pvr::CliRun::CheckOnly);
  return 0;
}
