// SPDX-License-Identifier: MIT
// Progress: what a run says while it runs, to the one sink the command line chose (`plaf run`,
// `--quiet`, `--progress=json`; the schema in docs/outputs.md). Four kinds of message:
//   step:    a long stage's news as it goes: a remeshing round, a layer accepted with its row of
//            the layer table, the quality stage's share of cells certified, a fill pass; a
//            fraction of the stage done;
//   done:    a stage ended (apps/stage_clock.h: the driver's numbered steps), with its seconds;
//   note:    a remark of a stage the user should see (a repair of the input surface);
//   error:   what made the run fail, and the verdict: the run's last message.
// Modes:
//   Text:  on stderr, "[plaf] STAGE ... 40 %: TEXT (ELAPSED s)" per step, "[plaf] STAGE: TEXT
//          (SECONDS s)" per done (unchanged from before steps existed), "[plaf] TEXT" per note,
//          "plaf: error: TEXT" per error; the verdict is the summary on stdout (apps/run.cpp);
//   Json:  one JSON object per line, every one with "event", "stage", "fraction", "elapsed_s" and
//          "text" (and the verdict's "ok" and "exit_code");
//   Quiet: errors and the verdict only (text).
// Rate: a stage's steps are written at most once per min_interval_s (kMinInterval_s; the plaf
// command takes another from PLAF_PROGRESS_INTERVAL_S, for tests), counted from the stage's
// start (the previous done) and from its last step written, so that a stage shorter than that
// writes its done alone; done, note, error and verdict are always written. A stage's fraction
// never decreases (a smaller one is raised to the last) and is in [0, 1]; its done is 1.
// Thread-safe: the quality stage reports from its worker threads (modules/base/parallel.h).
#pragma once

#include <functional>
#include <map>
#include <mutex>
#include <ostream>
#include <string>

namespace plaf {
inline namespace pipeline {

enum class ProgressMode { Text, Json, Quiet };

class Progress {
 public:
  static constexpr double kMinInterval_s = 1.0;
  // Seconds on any origin, non-decreasing; empty: std::chrono::steady_clock (a test injects its own).
  using Clock = std::function<double()>;

  explicit Progress(ProgressMode mode, std::ostream& out, Clock clock = {}, double min_interval_s = kMinInterval_s);
  ProgressMode mode() const { return mode_; }

  // fraction: of the stage done, in [0, 1]; text: what was done ("remesh round 3 of 8");
  // fields: more members of the JSON object as JSON text without braces ("\"round\": 3").
  void step(const std::string& stage, double fraction, const std::string& text, const std::string& fields = "");
  // Ends `stage`; the next stage starts now. Returns the stage's seconds.
  double done(const std::string& stage, const std::string& text);
  void note(const std::string& stage, const std::string& text);
  void error(const std::string& text);
  // The run's last message: Json only (Text and Quiet leave the verdict to the summary on stdout).
  void verdict(bool ok, int exit_code, const std::string& text, const std::string& fields = "");

 private:
  struct StageState {
    double fraction = 0;
    double written = 0;  // when its last step was written (or it started)
  };
  double now() const;
  // The JSON line of an event (the caller holds the lock).
  void json_line(const char* event, const std::string& stage, double fraction, double elapsed, const std::string& text,
                 const std::string& fields);

  ProgressMode mode_;
  std::ostream& out_;
  Clock clock_;
  double min_interval_s_;
  std::mutex mutex_;
  double run_start_, stage_start_;
  std::string current_;  // the stage that ran last (errors are filed under it)
  std::map<std::string, StageState> stages_;
};

// A sink that writes nothing (RunState's default, for stages run outside a command: tests, the
// attenuation study).
Progress& silent_progress();

}  // namespace pipeline
}  // namespace plaf
