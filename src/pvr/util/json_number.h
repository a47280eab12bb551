#pragma once
// A JSON number as a C++ arithmetic type, checked before it is converted: nlohmann's get<T>()
// casts, and a cast of a value outside T's range is undefined (the mesh fuzzer found a glTF
// texCoord of 1e20 read as uint32_t). The readers of users' JSON (glTF extensions and accessors,
// scene files, settings files, controller profiles) take their numbers through here.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <string>
#include <type_traits>

#include <nlohmann/json.hpp>

#include "pvr/util/error.h"

namespace pvr {

// Whether `j` is a number that T holds: for an integral T a whole number within its range (3 or
// 3.0, as JSON Schema counts integers; not 2.5, not 1e20 for an int), for a floating-point T a
// finite value within its range.
template <class T>
bool jsonNumberFits(const nlohmann::json& j) {
  static_assert((std::is_integral_v<T> && !std::is_same_v<T, bool>) || std::is_same_v<T, float> || std::is_same_v<T, double>);
  if constexpr (std::is_integral_v<T>) {
    constexpr uint64_t most = uint64_t(std::numeric_limits<T>::max());
    if (j.is_number_unsigned()) return j.get<uint64_t>() <= most;
    if (j.is_number_integer()) {
      const int64_t v = j.get<int64_t>();
      return v < 0 ? std::is_signed_v<T> && v >= int64_t(std::numeric_limits<T>::min()) : uint64_t(v) <= most;
    }
    if (!j.is_number_float()) return false;
    // Bounds as powers of two, exact in a double (double(INT64_MAX) would round up past it).
    const double v = j.get<double>(), limit = std::ldexp(1.0, std::numeric_limits<T>::digits);
    return std::trunc(v) == v && v < limit && (std::is_signed_v<T> ? v >= -limit : v >= 0.0);
  } else {
    if (!j.is_number()) return false;
    const double v = j.get<double>();
    return std::abs(v) <= double(std::numeric_limits<T>::max());  // false for NaN
  }
}

// `j` as T; a number T does not hold is a pvr::Error naming `what` and T's range ("k must be an
// integer from -2147483648 to 2147483647", "exposure must be a finite number of magnitude at most
// 3.40282e+38").
template <class T>
T jsonNumber(const nlohmann::json& j, const std::string& what) {
  if (!jsonNumberFits<T>(j)) {
    if constexpr (std::is_integral_v<T>)
      throw Error(what + " must be an integer from " + std::to_string(std::numeric_limits<T>::min()) + " to " +
                  std::to_string(std::numeric_limits<T>::max()));
    char most[32];
    std::snprintf(most, sizeof most, "%g", double(std::numeric_limits<T>::max()));
    throw Error(what + " must be a finite number of magnitude at most " + most);
  }
  return j.get<T>();
}

}  // namespace pvr
