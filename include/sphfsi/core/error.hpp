// sphfsi: error types and input-validation helpers.
//
// Every public constructor and setter checks its arguments with these helpers so that a bad input
// produces one clear message naming the parameter, its value and the valid range.
#pragma once

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <string_view>

namespace sphfsi {

/// A parameter outside its valid range (thrown before any computation starts).
class InputError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// The simulation became non-physical while running (NaN, particle left the domain, time step collapse).
class BlowUpError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

namespace detail {
template <class T>
std::string format_value(T v) {
  return fmt::format("{}", v);
}
}  // namespace detail

/// Require lo < value (strict) and value finite.
template <class T>
void require_positive(std::string_view name, T value) {
  if (!(value > T(0)) || !std::isfinite(static_cast<double>(value)))
    throw InputError(fmt::format("{} = {} is invalid: valid range is (0, inf)", name, value));
}

/// Require value finite and >= 0.
template <class T>
void require_non_negative(std::string_view name, T value) {
  if (!(value >= T(0)) || !std::isfinite(static_cast<double>(value)))
    throw InputError(fmt::format("{} = {} is invalid: valid range is [0, inf)", name, value));
}

/// Require lo <= value <= hi.
template <class T>
void require_in_range(std::string_view name, T value, T lo, T hi) {
  if (!(value >= lo && value <= hi))
    throw InputError(fmt::format("{} = {} is invalid: valid range is [{}, {}]", name, value, lo, hi));
}

/// Require lo < value < hi (open interval).
template <class T>
void require_in_open_range(std::string_view name, T value, T lo, T hi) {
  if (!(value > lo && value < hi))
    throw InputError(fmt::format("{} = {} is invalid: valid range is ({}, {})", name, value, lo, hi));
}

/// Require a finite value (any sign).
template <class T>
void require_finite(std::string_view name, T value) {
  if (!std::isfinite(static_cast<double>(value)))
    throw InputError(fmt::format("{} = {} is invalid: it must be a finite number", name, value));
}

}  // namespace sphfsi
