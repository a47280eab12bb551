#pragma once
// Small pieces shared by the benchmark harnesses.
#include <sstream>
#include <string>
#include <vector>

#include "pvr/util/error.h"

namespace pvr {

// "a,b,c" -> {"a", "b", "c"} (or split at another separator); throws pvr::Error for an empty list.
inline std::vector<std::string> splitList(const std::string& s, char separator = ',') {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string item; std::getline(ss, item, separator);)
    if (!item.empty()) out.push_back(item);
  if (out.empty()) throw Error("empty list '" + s + "'");
  return out;
}

}  // namespace pvr
