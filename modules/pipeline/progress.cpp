// SPDX-License-Identifier: MIT
#include "modules/pipeline/progress.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "modules/mesh/quality.h"

namespace plaf {
inline namespace pipeline {

namespace {

// Seconds to the millisecond (a line's time is for people and plots, not for the report's timings).
double rounded_s(double s) { return std::round(s * 1000) / 1000; }

}  // namespace

Progress::Progress(ProgressMode mode, std::ostream& out, Clock clock, double min_interval_s)
    : mode_(mode), out_(out), clock_(std::move(clock)), min_interval_s_(min_interval_s), run_start_(now()), stage_start_(run_start_) {}

double Progress::now() const {
  if (clock_) return clock_();
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

void Progress::json_line(const char* event, const std::string& stage, double fraction, double elapsed,
                         const std::string& text, const std::string& fields) {
  out_ << "{\"event\": \"" << event << "\", \"stage\": " << json_string(stage)
       << ", \"fraction\": " << json_number(std::round(fraction * 1e4) / 1e4)
       << ", \"elapsed_s\": " << json_number(rounded_s(elapsed)) << ", \"text\": " << json_string(text)
       << (fields.empty() ? "" : ", ") << fields << "}\n";
  out_.flush();
}

void Progress::step(const std::string& stage, double fraction, const std::string& text, const std::string& fields) {
  if (mode_ == ProgressMode::Quiet) return;
  std::lock_guard<std::mutex> lock(mutex_);
  const double t = now();
  current_ = stage;
  const auto [it, fresh] = stages_.try_emplace(stage);
  StageState& st = it->second;
  if (fresh) st.written = stage_start_;
  if (std::isfinite(fraction)) st.fraction = std::max(st.fraction, std::clamp(fraction, 0.0, 1.0));
  if (t - st.written < min_interval_s_) return;
  st.written = t;
  if (mode_ == ProgressMode::Json) {
    json_line("step", stage, st.fraction, t - stage_start_, text, fields);
    return;
  }
  std::ostringstream line;
  line << "[plaf] " << stage << " ... " << static_cast<int>(std::floor(100 * st.fraction)) << " %: " << text << " ("
       << std::fixed << std::setprecision(1) << t - stage_start_ << " s)\n";
  out_ << line.str();
  out_.flush();
}

double Progress::done(const std::string& stage, const std::string& text) {
  std::lock_guard<std::mutex> lock(mutex_);
  const double t = now();
  const double seconds = t - stage_start_;
  stage_start_ = t;
  current_ = stage;
  stages_[stage].fraction = 1;
  if (mode_ == ProgressMode::Json)
    json_line("done", stage, 1, seconds, text, "");
  else if (mode_ == ProgressMode::Text)
    out_ << "[plaf] " << stage << ": " << text << " (" << seconds << " s)\n" << std::flush;
  return seconds;
}

void Progress::note(const std::string& stage, const std::string& text) {
  if (mode_ == ProgressMode::Quiet) return;
  std::lock_guard<std::mutex> lock(mutex_);
  const double t = now();
  const auto it = stages_.find(stage);
  if (mode_ == ProgressMode::Json)
    json_line("note", stage, it == stages_.end() ? 0 : it->second.fraction, t - stage_start_, text, "");
  else
    out_ << "[plaf] " << text << '\n' << std::flush;
}

void Progress::error(const std::string& text) {
  std::lock_guard<std::mutex> lock(mutex_);
  const std::string stage = current_.empty() ? "run" : current_;
  const auto it = stages_.find(stage);
  if (mode_ == ProgressMode::Json)
    json_line("error", stage, it == stages_.end() ? 0 : it->second.fraction, now() - stage_start_, text, "");
  else
    out_ << "plaf: error: " << text << '\n' << std::flush;
}

void Progress::verdict(bool ok, int exit_code, const std::string& text, const std::string& fields) {
  if (mode_ != ProgressMode::Json) return;
  std::lock_guard<std::mutex> lock(mutex_);
  json_line("verdict", "run", 1, now() - run_start_, text,
            std::string("\"ok\": ") + (ok ? "true" : "false") + ", \"exit_code\": " + std::to_string(exit_code) +
                (fields.empty() ? "" : ", " + fields));
}

Progress& silent_progress() {
  // Quiet, and its errors into a stream without a buffer (they go nowhere).
  static std::ostream nowhere(nullptr);
  static Progress silent(ProgressMode::Quiet, nowhere);
  return silent;
}

}  // namespace pipeline
}  // namespace plaf
