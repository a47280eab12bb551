// Shared by the fuzz harnesses: photonvr's loaders read files, so each input is written to a
// private temporary file with the extension that picks the parser.
#pragma once
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <string>
#include <unistd.h>

namespace pvr::fuzz {

// A temporary file holding `data`, removed when this goes out of scope.
class TempInput {
 public:
  TempInput(const uint8_t* data, size_t size, const std::string& extension)
      : path_("/tmp/pvr_fuzz_" + std::to_string(getpid()) + "." + extension) {
    if (FILE* f = std::fopen(path_.c_str(), "wb")) {
      if (size > 0) std::fwrite(data, 1, size, f);
      std::fclose(f);
    }
  }
  ~TempInput() { std::remove(path_.c_str()); }
  TempInput(const TempInput&) = delete;
  TempInput& operator=(const TempInput&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

// The contract under test: bad input ends in an exception the command line turns into one line
// (it catches std::exception); a crash, a sanitizer report, a leak or a hang is a finding.
template <class Load>
void expectCleanFailure(Load&& load) {
  try {
    load();
  } catch (const std::exception&) {
  }
}

}  // namespace pvr::fuzz
