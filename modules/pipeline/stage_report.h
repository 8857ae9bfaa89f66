// SPDX-License-Identifier: MIT
// StageReport: what one stage did, as a section of the run's JSON report (`layers.*`, `fill.*`,
// `surface.*`), human lines for stdout, and an optional failure verdict. Every stage fills its own;
// the driver appends them to the quality report and decides what is fatal (STYLE.md rule 9:
// degradation is data).
#pragma once

#include <cstddef>
#include <ostream>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "modules/mesh/quality.h"

namespace plaf {
inline namespace pipeline {

class StageReport {
 public:
  explicit StageReport(std::string section = "") : section_(std::move(section)) {}
  const std::string& section() const { return section_; }
  // A stage may file its keys under another section (the 3D geometry's input under `surface`).
  void set_section(std::string section) { section_ = std::move(section); }

  // Keys are relative to the section and may hold dots (nested objects in the JSON).
  void add(const std::string& key, double value) { add_json(key, json_number(value)); }
  template <class Int>
    requires(std::is_integral_v<Int> && !std::is_same_v<Int, bool>)
  void add(const std::string& key, Int value) {
    add_json(key, std::to_string(value));
  }
  void add(const std::string& key, bool value) { add_json(key, value ? "true" : "false"); }
  void add(const std::string& key, const std::string& value) { add_json(key, json_string(value)); }
  void add(const std::string& key, const char* value) { add_json(key, json_string(value)); }
  // A value that is JSON text already (an object or an array).
  void add_json(const std::string& key, std::string json) { entries_.emplace_back(key, std::move(json)); }
  // A line for stdout, printed indented under the run's progress.
  void line(std::string text) { lines_.push_back(std::move(text)); }
  // A failure the run must report with exit code 2 (the mesh is written for inspection).
  void fail(std::string why) { failure_ = std::move(why); }
  // The same, with where it happened: the failed run's picture looks there (QualityReport::focus,
  // apps/run.cpp) unless an invalid cell is worse.
  struct Place {
    std::vector<double> point;  // Dim coordinates
    double radius = 0;          // of the region to show
    std::string label;          // what is there ("first folded triangle")
  };
  void fail(std::string why, Place where) {
    failure_ = std::move(why);
    failure_place_ = std::move(where);
  }

  const std::vector<std::pair<std::string, std::string>>& entries() const { return entries_; }
  const std::vector<std::string>& lines() const { return lines_; }
  const std::string& failure() const { return failure_; }
  const Place& failure_place() const { return failure_place_; }  // point empty: none given

  // The section's keys into report.extra as "section.key".
  void append_to(QualityReport& report) const;
  void print(std::ostream& out) const;

 private:
  std::string section_;
  std::vector<std::pair<std::string, std::string>> entries_;
  std::vector<std::string> lines_;
  std::string failure_;
  Place failure_place_;
};

// JSON array text of a list of JSON values.
std::string json_array(const std::vector<std::string>& values);

}  // namespace pipeline
}  // namespace plaf
