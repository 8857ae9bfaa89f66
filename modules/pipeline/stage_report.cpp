// SPDX-License-Identifier: MIT
#include "modules/pipeline/stage_report.h"

namespace plaf {
inline namespace pipeline {

void StageReport::append_to(QualityReport& report) const {
  for (const auto& [key, json] : entries_) report.extra.push_back({section_.empty() ? key : section_ + "." + key, json});
}

void StageReport::print(std::ostream& out) const {
  for (const std::string& l : lines_) out << "  " << l << '\n';
}

std::string json_array(const std::vector<std::string>& values) {
  std::string s = "[";
  for (std::size_t i = 0; i < values.size(); ++i) s += (i ? ", " : "") + values[i];
  return s + "]";
}

}  // namespace pipeline
}  // namespace plaf
