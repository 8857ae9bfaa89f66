// SPDX-License-Identifier: MIT
#include "modules/pipeline/config.h"

#include <doctest/doctest.h>

#include <sys/stat.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <limits>
#include <memory>
#include <sstream>
#include <string>

#include "modules/base/error.h"
#include "modules/pipeline/registry.h"
#include "tests/test_support.h"

using namespace plaf;

TEST_CASE("config: values, defaults and nested maps") {
  const ConfigNode c = ConfigNode::load_string(
      "order: 3\nmetric:\n  type: uniform\n  h: 0.25\nflag: true\n"
      "formats: [msh, vtu]\n",
      "run.yaml");
  CHECK(c.get_int("order", 1, 1, 4) == 3);
  CHECK(c.get_bool("flag", false));
  CHECK(c.get_double("missing", 7.5) == 7.5);
  const ConfigNode m = c.child("metric");
  CHECK(m.get_string("type", "") == "uniform");
  CHECK(m.get_positive("h", 1.0) == 0.25);
  CHECK(c.get_string_list("formats", {}, {"msh", "vtu", "png"}) == std::vector<std::string>{"msh", "vtu"});
  CHECK_NOTHROW(c.finish());
}

TEST_CASE("config: an unknown key is an error naming file, line, column and key") {
  const ConfigNode c = ConfigNode::load_string("order: 3\nmetric:\n  type: uniform\n  hh: 0.25\n", "run.yaml");
  c.get_int("order", 1, 1, 4);
  c.child("metric").get_string("type", "");
  CHECK_THROWS_WITH_AS(c.finish(), "run.yaml:4:3: unknown key 'metric.hh' (known here: type)", ConfigError);
}

TEST_CASE("config: wrong types and out-of-range values name the key and the value") {
  const ConfigNode c = ConfigNode::load_string("order: 7\nh: -0.5\nname: [a]\nx: abc\nq: -1\nmode: fast\n", "bad.yaml");
  CHECK_THROWS_WITH_AS(c.get_int("order", 3, 1, 4), "bad.yaml:1:8: order: 7 is outside 1..4", ConfigError);
  CHECK_THROWS_WITH_AS(c.get_positive("h", 1), "bad.yaml:2:4: h: must be positive, got -0.5", ConfigError);
  CHECK_THROWS_WITH_AS(c.get_string("name", ""), "bad.yaml:3:7: name: expected a word, got a list or map", ConfigError);
  CHECK_THROWS_WITH_AS(c.get_double("x", 0), "bad.yaml:4:4: x: expected a number, got 'abc'", ConfigError);
  CHECK_THROWS_WITH_AS(c.get_int("q", 3, 1, 4), "bad.yaml:5:4: q: -1 is outside 1..4", ConfigError);
  CHECK_THROWS_WITH_AS(c.get_choice("mode", "slow", {"slow", "exact"}),
                       "bad.yaml:6:7: mode: unknown value 'fast' (known: slow, exact)", ConfigError);
}

TEST_CASE("config: ranges with open ends, 0 or a range, and ranged lists name the value and the range, and are recorded") {
  KeyRecording rec;
  const ConfigNode c = ConfigNode::load_string("g: 1\nq: 0.5\nr: 0\ns: 1.05\nt: 180\naxes: [1, 0, 2]\nu: 1e12\n", "r.yaml");
  CHECK_THROWS_WITH_AS(c.get_in_range("g", 1.2, 1, 10, Bounds::OpenLow), "r.yaml:1:4: g: 1 is outside (1, 10]", ConfigError);
  CHECK(c.get_in_range("q", 0.2, 0, 1, Bounds::Open) == 0.5);
  CHECK(c.get_zero_or_in_range("r", 1.5, 1.1, 100) == 0);
  CHECK_THROWS_WITH_AS(c.get_zero_or_in_range("s", 1.5, 1.1, 100), "r.yaml:4:4: s: 1.05 is outside 0 or [1.1, 100]",
                       ConfigError);
  CHECK_THROWS_WITH_AS(c.get_in_range("t", 30, 0, 180, Bounds::Open), "r.yaml:5:4: t: 180 is outside (0, 180)", ConfigError);
  CHECK_THROWS_WITH_AS(c.get_double_list("axes", {1, 1, 1}, 0, std::numeric_limits<double>::max(), Bounds::OpenLow),
                       "r.yaml:6:7: axes: 0 is outside > 0", ConfigError);
  CHECK_THROWS_WITH_AS(c.get_in_range("u", 20, 0, 5e11, Bounds::OpenLow), "r.yaml:7:4: u: 1e+12 is outside (0, 5e11]",
                       ConfigError);
  CHECK(c.get_in_range("absent", 0, 0, std::numeric_limits<double>::max()) == 0);
  std::vector<std::string> ranges;
  for (const KeyAsk& a : rec.asks()) ranges.push_back(a.range);
  CHECK(ranges == std::vector<std::string>{"(1, 10]", "(0, 1)", "0 or [1.1, 100]", "0 or [1.1, 100]", "(0, 180)", "> 0",
                                           "(0, 5e11]", ">= 0"});
}

TEST_CASE("config: syntax errors, non-map documents and missing files") {
  CHECK_THROWS_AS(ConfigNode::load_string("a: [1, 2\n", "broken.yaml"), ConfigError);
  CHECK_THROWS_WITH_AS(ConfigNode::load_string("- 1\n- 2\n", "list.yaml"),
                       "list.yaml:1:1: the top level must be a map of keys", ConfigError);
  CHECK_THROWS_AS(ConfigNode::load_file("/nonexistent/run.yaml"), InputError);
}

TEST_CASE("registry: plugins by name, an unknown name lists the known ones") {
  Registry<std::unique_ptr<int>(int)> r("widget");
  r.add("double", [](int x) { return std::make_unique<int>(2 * x); });
  r.add("square", [](int x) { return std::make_unique<int>(x * x); });
  CHECK(*r.create("square", "here", 5) == 25);
  CHECK_THROWS_WITH_AS(r.create("cube", "run.yaml:3:9: metric.type", 2),
                       "run.yaml:3:9: metric.type: unknown widget 'cube' (known: double, square)", ConfigError);
  CHECK_THROWS_AS(r.add("double", [](int x) { return std::make_unique<int>(x); }), Error);
}

TEST_CASE("config: asking for an absent key does not create it") {
  const ConfigNode c = ConfigNode::load_string("a: 1\n", "run.yaml");
  CHECK(c.get_double("b", 2.0) == 2.0);
  CHECK_FALSE(c.has("b"));
  CHECK(c.get_double("a", 0.0) == 1.0);
  CHECK_NOTHROW(c.finish());
}

TEST_CASE("config: a key given twice is an error naming both places, at any depth") {
  const auto error = [](const std::string& yaml) {
    try {
      plaf::ConfigNode::load_string(yaml, "d.yaml");
    } catch (const plaf::ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  // The first value would win and the second never be checked (issue: h: 0.3 then h: -1).
  CHECK(error("metric:\n  h: 0.3\n  h: -1\n") == "d.yaml:3:3: metric.h: the key is given twice (first at d.yaml:2:3)");
  CHECK(error("order: 2\norder: 3\n") == "d.yaml:2:1: order: the key is given twice (first at d.yaml:1:1)");
  CHECK(error("geometry:\n  bodies:\n    - {file: a.dat, file: b.dat}\n") ==
        "d.yaml:3:21: geometry.bodies[0].file: the key is given twice (first at d.yaml:3:8)");
  CHECK(error("metric: {h: 0.3}\nlayers: {h: 0.3}\n") == "no error");  // the same key in two maps
}

TEST_CASE("config: a directory, a device or a FIFO is not a config file") {
  const plaf::test::TempDir d("config_not_regular");
  CHECK_THROWS_WITH_AS(plaf::ConfigNode::load_file(d.path),
                       (d.path.string() + ": not a regular file (a config is a YAML file)").c_str(), plaf::InputError);
  CHECK_THROWS_WITH_AS(plaf::ConfigNode::load_file("/dev/zero"), "/dev/zero: not a regular file (a config is a YAML file)",
                       plaf::InputError);
  const std::filesystem::path fifo = d / "fifo.yaml";
  REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
  CHECK_THROWS_AS(plaf::ConfigNode::load_file(fifo), plaf::InputError);  // does not block
  CHECK_THROWS_WITH_AS(plaf::ConfigNode::load_file(d / "missing.yaml"),
                       ((d / "missing.yaml").string() + ": cannot open the config file").c_str(), plaf::InputError);
}

TEST_CASE("config: nested aliases (a billion laughs) are read in linear time") {
  // Nine levels of ten aliases each: 10^9 leaves if every alias were walked again.
  std::string yaml = "a0: &a0 [x, x, x, x, x, x, x, x, x, x]\n";
  const char* const names[] = {"a0", "a1", "a2", "a3", "a4", "a5", "a6", "a7", "a8", "a9"};
  for (int i = 1; i <= 9; ++i) {
    std::ostringstream line;
    line << names[i] << ": &" << names[i] << " [";
    for (int k = 0; k < 10; ++k) line << (k ? ", *" : "*") << names[i - 1];
    line << "]\n";
    yaml += line.str();
  }
  const plaf::ConfigNode c = plaf::ConfigNode::load_string(yaml, "laughs.yaml");
  CHECK_THROWS_WITH_AS(c.finish(), doctest::Contains("unknown key 'a0'"), plaf::ConfigError);
}

TEST_CASE("config: a recording keeps every key asked with its type, default and range, list items as []") {
  const std::string yaml = "a: 2\nlist: [{w: x}, {w: y}]\nsub: {flag: true}\n";
  {
    // Without a recording nothing is kept, and a recording started later does not see old nodes.
    const ConfigNode before = ConfigNode::load_string(yaml, "r.yaml");
    KeyRecording late;
    before.get_double("a", 1);
    CHECK(late.asks().empty());
  }
  KeyRecording rec;
  const ConfigNode c = ConfigNode::load_string(yaml, "r.yaml");
  CHECK(c.get_in_range("a", 0.5, 0, 10) == 2);  // recording changes no value
  c.get_positive("p", 1e-9);
  c.get_int("n", 24, 0, 10000);
  c.get_choice("shape", "sphere", {"sphere", "box"});
  c.get_double_list("size", {0, 20000000});
  CHECK(c.child("sub").get_bool("flag", false));
  for (const ConfigNode& item : c.child_list("list")) item.get_string("w", "");
  const bool given = c.has("opt");
  if (!given) c.get_path("opt", "");
  c.raw("pass");
  CHECK_NOTHROW(c.finish());
  const std::vector<KeyAsk>& a = rec.asks();
  REQUIRE(a.size() == 13);
  auto check = [&](std::size_t i, const std::string& path, KeyAsk::Kind kind, const std::string& fallback,
                   const std::string& range) {
    INFO(i << " " << a[i].path);
    CHECK(a[i].path == path);
    CHECK(a[i].kind == kind);
    CHECK(a[i].fallback == fallback);
    CHECK(a[i].range == range);
  };
  // One record per getter, the outer one: get_positive is a number > 0, not also a plain number.
  check(0, "a", KeyAsk::Kind::Number, "0.5", "[0, 10]");
  check(1, "p", KeyAsk::Kind::Number, "1e-9", "> 0");
  check(2, "n", KeyAsk::Kind::Integer, "24", "0..10000");
  check(3, "shape", KeyAsk::Kind::Choice, "sphere", "");
  CHECK(a[3].choices == std::vector<std::string>{"sphere", "box"});
  check(4, "size", KeyAsk::Kind::NumberList, "[0, 2e7]", "");
  check(5, "sub", KeyAsk::Kind::Section, "", "");
  check(6, "sub.flag", KeyAsk::Kind::Bool, "false", "");
  check(7, "list", KeyAsk::Kind::SectionList, "", "");
  check(8, "list[].w", KeyAsk::Kind::Text, "", "");
  check(9, "list[].w", KeyAsk::Kind::Text, "", "");
  check(10, "opt", KeyAsk::Kind::Presence, "", "");
  check(11, "opt", KeyAsk::Kind::Path, "", "");
  check(12, "pass", KeyAsk::Kind::Raw, "", "");
  // A key read after its presence was tested is read only when given: its fallback is no default.
  CHECK(a[11].after_presence_test);
  CHECK_FALSE(a[4].after_presence_test);
  CHECK(std::string(kind_name(KeyAsk::Kind::SectionList)) == "list of sections");
}
