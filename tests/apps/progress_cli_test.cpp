// SPDX-License-Identifier: MIT
// The run's progress on the command line (modules/pipeline/progress.h, docs/outputs.md): with
// --progress=json every line on stderr is one JSON object with its stage and fraction, a stage's
// fractions never decrease and its last is its end at 1; steps come no more often than once a
// second per stage; --quiet prints errors and the verdict alone.
#include <doctest/doctest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "apps/exit_codes.h"
#include "tests/json_support.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using plaf::test::JsonLine;
using plaf::test::JsonMember;
using plaf::test::TempDir;
using plaf::test::write_text;

namespace {

// A small 3D hybrid: remeshed sphere, six curved layers, TetGen's fill.
const std::string sphere =
    "name: case\norder: 2\ngeometry: {type: sphere, center: [0, 0, 0], radius: 1}\n"
    "metric: {type: wall_power_law, h0: 0.001, growth: 1.3, h_max: 2.0, h_wall_max: 0.3}\n"
    "layers: {max: 6}\nfill: {type: tetgen, farfield: {shape: box, size: [8, 8, 8]}}\n";

struct Run {
  int code = -1;
  std::vector<std::string> out, err;  // lines
};

// `plaf run CONFIG --out DIR/out ARGS`, with `env` before it (PLAF_PROGRESS_INTERVAL_S=0: every step).
Run run(const TempDir& d, const fs::path& cfg, const std::string& args, const std::string& env = "") {
  const fs::path out = d / "stdout.txt", err = d / "stderr.txt";
  const std::string cmd = env + " " + std::string(PLAF_EXE) + " run " + cfg.string() + " --out " +
                          (d / "out").string() + " " + args + " > " + out.string() + " 2> " + err.string();
  const int status = std::system(cmd.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, plaf::test::read_lines(out), plaf::test::read_lines(err)};
}

using Object = std::map<std::string, JsonMember>;

// Every line parsed (a failed CHECK names the line that is not one JSON object).
std::vector<Object> parse_all(const std::vector<std::string>& lines) {
  std::vector<Object> objects;
  for (const std::string& line : lines) {
    INFO("stderr line: " << line);
    const auto m = JsonLine::parse(line);
    CHECK(m.has_value());
    if (m) objects.push_back(*m);
  }
  return objects;
}

// The schema's invariants (docs/outputs.md): event, stage, text strings, fraction in [0, 1],
// elapsed_s >= 0; per stage the fractions non-decreasing and its last event its done at 1; the last
// object the verdict. Returns the events per stage, in order.
std::map<std::string, std::vector<Object>> check_schema(const std::vector<Object>& objects) {
  std::map<std::string, std::vector<Object>> by_stage;
  for (const Object& o : objects) {
    for (const char* key : {"event", "stage", "text"}) {
      REQUIRE(o.count(key) == 1);
      CHECK(o.at(key).kind == JsonMember::String);
    }
    for (const char* key : {"fraction", "elapsed_s"}) {
      REQUIRE(o.count(key) == 1);
      CHECK(o.at(key).kind == JsonMember::Number);
    }
    const double f = o.at("fraction").number;
    CHECK(f >= 0);
    CHECK(f <= 1);
    CHECK(o.at("elapsed_s").number >= 0);
    if (o.at("event").text == "verdict") continue;
    std::vector<Object>& seen = by_stage[o.at("stage").text];
    if (!seen.empty()) {
      INFO("stage " << o.at("stage").text << ": " << o.at("text").text);
      CHECK(f >= seen.back().at("fraction").number);
      CHECK(seen.back().at("event").text != "done");  // nothing after a stage's end
    }
    seen.push_back(o);
  }
  for (const auto& [stage, events] : by_stage) {
    INFO("stage " << stage);
    CHECK(events.back().at("event").text == "done");
    CHECK(events.back().at("fraction").number == 1);
  }
  REQUIRE_FALSE(objects.empty());
  CHECK(objects.back().at("event").text == "verdict");
  return by_stage;
}

std::size_t count_steps(const std::vector<Object>& events, const char* field = nullptr) {
  std::size_t n = 0;
  for (const Object& o : events)
    if (o.at("event").text == "step" && (!field || o.count(field))) ++n;
  return n;
}

}  // namespace

TEST_CASE("progress: --progress=json: every stderr line of a 3D run is a JSON object, fractions rising to 1 per stage") {
  const TempDir d("progress_json");
  const fs::path cfg = write_text(d / "case.yaml", sphere);
  // Every step written (no rate limit): the long stages' steps are all there.
  const Run r = run(d, cfg, "--progress=json", "PLAF_PROGRESS_INTERVAL_S=0");
  REQUIRE(r.code == 0);
  const std::vector<Object> objects = parse_all(r.err);
  REQUIRE(objects.size() == r.err.size());
  const auto by_stage = check_schema(objects);
  for (const char* stage : {"config", "geometry", "metric", "surface", "layers", "fill", "mesh", "quality", "write"}) {
    INFO("stage " << stage);
    CHECK(by_stage.count(stage) == 1);
  }
  // The long stages' steps: the remesher's rounds, each layer accepted with its row, the fill's
  // passes and the quality stage's share of cells.
  CHECK(count_steps(by_stage.at("surface"), "round") >= 1);
  CHECK(count_steps(by_stage.at("layers"), "layer") >= 6);  // six layers, and a closing one if any
  for (const Object& o : by_stage.at("layers"))
    if (o.at("event").text == "step")
      for (const char* column : {"cells", "transition_cells", "max_clipped_over_height", "height_min", "coverage"})
        CHECK(o.count(column) == 1);
  CHECK(count_steps(by_stage.at("fill")) >= 2);  // TetGen, then the passes
  CHECK(count_steps(by_stage.at("quality")) >= 1);
  const Object& verdict = objects.back();
  CHECK(verdict.at("ok").text == "true");
  CHECK(verdict.at("exit_code").number == 0);
  CHECK(verdict.at("invalid_cells").number == 0);
  // stdout keeps the human summary.
  CHECK_FALSE(r.out.empty());

  // At the default rate, no stage writes more than one step per second of its time.
  {
    const Run slow = run(d, cfg, "--progress=json");
    REQUIRE(slow.code == 0);
    const std::vector<Object> all = parse_all(slow.err);
    REQUIRE(all.size() == slow.err.size());
    for (const auto& [stage, events] : check_schema(all)) {
      INFO("stage " << stage << ": " << events.back().at("elapsed_s").number << " s");
      // Steps are written from a second after the stage's start, a second apart.
      CHECK(static_cast<double>(count_steps(events)) <= std::floor(events.back().at("elapsed_s").number + 1e-3));
    }
  }
}

TEST_CASE("progress: --quiet prints no stage lines: nothing on stderr and the verdict alone on stdout") {
  const TempDir d("progress_quiet");
  const fs::path cfg = write_text(d / "case.yaml", sphere);
  const Run r = run(d, cfg, "--quiet", "PLAF_PROGRESS_INTERVAL_S=0");
  REQUIRE(r.code == 0);
  CHECK(r.err.empty());
  REQUIRE(r.out.size() == 1);
  CHECK(r.out[0].rfind("case: valid, ", 0) == 0);
  CHECK(r.out[0].find(" 0 invalid") != std::string::npos);
  // Errors still come, and only they (a bad key: exit 1 before anything runs).
  const fs::path bad = write_text(d / "bad.yaml", sphere + "layerz: {max: 2}\n");
  const Run b = run(d, bad, "--quiet");
  CHECK(b.code == plaf::exit_code::bad_input);
  REQUIRE(b.err.size() == 1);
  CHECK(b.err[0].rfind("plaf: error: ", 0) == 0);
  CHECK(b.out.empty());
  // One of the two.
  CHECK(run(d, cfg, "--quiet --progress=json").code == plaf::exit_code::bad_input);
  CHECK(run(d, cfg, "--progress=xml").code == plaf::exit_code::bad_input);
}

TEST_CASE("progress: --progress=json: a run refused on bad input ends in a JSON error and verdict, exit 1") {
  const TempDir d("progress_json_error");
  const fs::path bad = write_text(d / "bad.yaml", sphere + "layerz: {max: 2}\n");
  const Run r = run(d, bad, "--progress=json");
  CHECK(r.code == plaf::exit_code::bad_input);
  const std::vector<Object> objects = parse_all(r.err);
  REQUIRE(objects.size() == r.err.size());
  REQUIRE(objects.size() >= 2);
  CHECK(objects[objects.size() - 2].at("event").text == "error");
  CHECK(objects[objects.size() - 2].at("text").text.find("layerz") != std::string::npos);
  CHECK(objects.back().at("event").text == "verdict");
  CHECK(objects.back().at("exit_code").number == plaf::exit_code::bad_input);
}
