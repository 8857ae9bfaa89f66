// SPDX-License-Identifier: MIT
// The one error channel of plaf: every bad input, bad config and mesher failure is thrown as a
// plaf::Error at the entry of the stage that detects it; the CLI catches it and exits non-zero.
#pragma once

#include <stdexcept>
#include <string>

namespace plaf {
inline namespace base {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A file or geometry the user gave is unusable (names the file, line or element and the reason).
class InputError : public Error {
 public:
  using Error::Error;
};

// A YAML key is unknown, has the wrong type or is out of range (names file, line and key).
class ConfigError : public Error {
 public:
  using Error::Error;
};

// A stage could not produce a valid result from valid input (names the stage and the reason).
class MesherError : public Error {
 public:
  using Error::Error;
};

}  // namespace base
}  // namespace plaf
