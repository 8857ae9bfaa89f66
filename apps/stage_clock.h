// SPDX-License-Identifier: MIT
// The run drivers' stage clock: the time of each numbered step, for the report's timings, and the
// step's end told to the run's progress sink (modules/pipeline/progress.h), which keeps the time.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "modules/pipeline/progress.h"

namespace plaf {

class StageClock {
 public:
  StageClock(std::vector<std::pair<std::string, double>>& timings, Progress& progress)
      : timings_(timings), progress_(progress) {}
  // Records the time since the last call under `stage` and ends the stage in the progress.
  void done(const std::string& stage, const std::string& what) { timings_.emplace_back(stage, progress_.done(stage, what)); }

 private:
  std::vector<std::pair<std::string, double>>& timings_;
  Progress& progress_;
};

}  // namespace plaf
