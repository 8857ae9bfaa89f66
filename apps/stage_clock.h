// SPDX-License-Identifier: MIT
// The run drivers' stage clock: the time of each numbered step, for the report's timings and a
// progress line on stderr.
#pragma once

#include <chrono>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

namespace plaf {

class StageClock {
 public:
  // quiet: no progress lines (the attenuation study runs many cases).
  explicit StageClock(std::vector<std::pair<std::string, double>>& timings, bool quiet = false)
      : timings_(timings), quiet_(quiet) {}
  // Records the time since the last call under `stage` and prints a progress line.
  void done(const std::string& stage, const std::string& what) {
    const auto now = std::chrono::steady_clock::now();
    const double s = std::chrono::duration<double>(now - last_).count();
    last_ = now;
    timings_.emplace_back(stage, s);
    if (!quiet_) std::cerr << "[plaf] " << stage << ": " << what << " (" << s << " s)\n";
  }

 private:
  std::vector<std::pair<std::string, double>>& timings_;
  bool quiet_;
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

}  // namespace plaf
