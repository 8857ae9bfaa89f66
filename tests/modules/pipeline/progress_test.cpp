// SPDX-License-Identifier: MIT
// The progress sink (modules/pipeline/progress.h), on an injected clock: a stage's steps at most
// once per interval counted from its start, its end always; fractions non-decreasing in [0, 1];
// the JSON mode's lines one object each; the quiet mode's errors alone.
#include "modules/pipeline/progress.h"

#include <doctest/doctest.h>

#include <sstream>
#include <string>
#include <vector>

#include "tests/json_support.h"

namespace {

using plaf::Progress;
using plaf::ProgressMode;
using plaf::test::JsonLine;

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

}  // namespace

TEST_CASE("progress: a stage's steps are written at most once a second from its start, its end always") {
  double now = 100;
  std::ostringstream out;
  Progress p(ProgressMode::Text, out, [&now] { return now; });
  // A stage shorter than the interval: its end alone.
  now = 100.25;
  p.step("surface", 0.5, "remesh round 4 of 8");
  now = 100.75;
  p.done("surface", "remesh");
  CHECK(lines_of(out.str()) == std::vector<std::string>{"[plaf] surface: remesh (0.75 s)"});
  out.str("");
  // A long stage: steps every 0.25 s for 5 s, written at 1.0, 2.0, ... from its start (the
  // interval counted from the last line written), and its end.
  std::size_t written = 0;
  for (int k = 1; k <= 20; ++k) {
    now = 100.75 + 0.25 * k;  // (binary fractions: exact)
    p.step("layers", k / 20.0, "layer " + std::to_string(k) + " of 20 accepted");
    const std::size_t lines = lines_of(out.str()).size();
    CHECK(lines == static_cast<std::size_t>(k / 4));  // one per full second
    written = lines;
  }
  CHECK(written == 5);
  CHECK(lines_of(out.str()).front() == "[plaf] layers ... 20 %: layer 4 of 20 accepted (1.0 s)");
  p.done("layers", "20 layers");
  CHECK(lines_of(out.str()).back() == "[plaf] layers: 20 layers (5 s)");
  // A second stage starts at the first one's end: its first step a second after that.
  out.str("");
  now += 0.99;
  p.step("quality", 0.3, "300 of 1000 cells certified");
  CHECK(out.str().empty());
  now += 0.02;
  p.step("quality", 0.4, "400 of 1000 cells certified");
  CHECK(out.str() == "[plaf] quality ... 40 %: 400 of 1000 cells certified (1.0 s)\n");
}

TEST_CASE("progress: a stage's fraction never decreases and stays in [0, 1], its end is 1") {
  double now = 0;
  std::ostringstream out;
  Progress p(ProgressMode::Json, out, [&now] { return now; });
  const double asked[] = {0.25, 0.1, 0.6, -3, 7, 0.5};
  const double written[] = {0.25, 0.25, 0.6, 0.6, 1, 1};
  std::size_t k = 0;
  for (double f : asked) {
    now += 1;
    p.step("fill", f, "pass");
    const std::vector<std::string> lines = lines_of(out.str());
    REQUIRE(lines.size() == k + 1);
    const auto m = JsonLine::parse(lines.back());
    REQUIRE(m);
    CHECK(m->at("fraction").number == doctest::Approx(written[k++]));
  }
  p.done("fill", "done");
  const auto end = JsonLine::parse(lines_of(out.str()).back());
  REQUIRE(end);
  CHECK(end->at("event").text == "done");
  CHECK(end->at("fraction").number == 1);
}

TEST_CASE("progress: JSON mode writes one object per line with event, stage, fraction, elapsed_s and text") {
  double now = 0;
  std::ostringstream out;
  Progress p(ProgressMode::Json, out, [&now] { return now; });
  now = 2;
  p.step("surface", 0.125, "remesh round 1 of 8 \"quoted\"\tand tabbed", "\"round\": 1, \"rounds\": 8");
  p.note("geometry", "repaired: 2 triangles\nflipped");
  now = 3.5;
  p.done("surface", "remesh");
  p.error("case.yaml: the run FAILED");
  p.verdict(false, 2, "case: FAILED", "\"cells\": 10");
  const std::vector<std::string> lines = lines_of(out.str());
  REQUIRE(lines.size() == 5);
  const char* events[] = {"step", "note", "done", "error", "verdict"};
  for (std::size_t i = 0; i < lines.size(); ++i) {
    INFO(lines[i]);
    const auto m = JsonLine::parse(lines[i]);
    REQUIRE(m);
    CHECK(m->at("event").text == events[i]);
    for (const char* key : {"stage", "text"}) CHECK(m->at(key).kind == plaf::test::JsonMember::String);
    for (const char* key : {"fraction", "elapsed_s"}) CHECK(m->at(key).kind == plaf::test::JsonMember::Number);
  }
  const auto step = JsonLine::parse(lines[0]);
  CHECK(step->at("text").text == "remesh round 1 of 8 \"quoted\"\tand tabbed");
  CHECK(step->at("round").number == 1);
  CHECK(step->at("elapsed_s").number == 2);
  CHECK(JsonLine::parse(lines[2])->at("elapsed_s").number == 3.5);
  CHECK(JsonLine::parse(lines[3])->at("stage").text == "surface");  // filed under the last stage
  const auto verdict = JsonLine::parse(lines[4]);
  CHECK(verdict->at("ok").text == "false");
  CHECK(verdict->at("exit_code").number == 2);
  CHECK(verdict->at("cells").number == 10);
  // The reader refuses what is not one JSON object.
  for (const char* bad : {"[plaf] surface: remesh (1 s)", "{\"a\": 1} {\"b\": 2}", "{\"a\": 01}", "{\"a\": \"x\ty\"}",
                          "{\"a\": 1, \"a\": 2}", "{a: 1}"})
    CHECK_FALSE(JsonLine::parse(bad));
}

TEST_CASE("progress: quiet mode writes errors only, text mode notes and errors as lines") {
  std::ostringstream quiet, text;
  double now = 0;
  Progress q(ProgressMode::Quiet, quiet, [&now] { return now; });
  Progress t(ProgressMode::Text, text, [&now] { return now; });
  now = 5;
  for (Progress* p : {&q, &t}) {
    p->step("surface", 0.5, "remesh round 4 of 8");
    p->note("geometry", "repaired: 2 triangles");
    p->done("surface", "remesh");
    p->error("case.yaml: the run FAILED");
    p->verdict(false, 2, "case: FAILED");
  }
  CHECK(quiet.str() == "plaf: error: case.yaml: the run FAILED\n");
  CHECK(lines_of(text.str()) == std::vector<std::string>{"[plaf] surface ... 50 %: remesh round 4 of 8 (5.0 s)",
                                                          "[plaf] repaired: 2 triangles",
                                                          "[plaf] surface: remesh (5 s)",
                                                          "plaf: error: case.yaml: the run FAILED"});
}
