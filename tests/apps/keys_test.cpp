// SPDX-License-Identifier: MIT
// The key reference (apps/keys.h): docs/config.md is exactly what `plaf keys --markdown` prints
// now and the reference is complete (no warning); every key a shipped configuration uses is in
// it; a key outside it is refused with one line naming it; the reference is true: the parse
// accepts inside each range and choice it prints and refuses just outside (plaf keys --probes).
#include <doctest/doctest.h>
#include <sys/wait.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <optional>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "apps/exit_codes.h"
#include "modules/base/error.h"
#include "modules/pipeline/run_config.h"
#include "tests/published_data.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using plaf::test::PlafOutput;
using plaf::test::read_text;
using plaf::test::run_plaf_output;
using plaf::test::TempDir;
using plaf::test::write_text;

namespace {

const fs::path root = fs::path(PLAF_CONFIGS).parent_path();

// The first line where a and b differ, for the message of a stale docs/config.md.
std::string first_difference(const std::string& a, const std::string& b) {
  std::istringstream sa(a), sb(b);
  std::string la, lb;
  for (int line = 1;; ++line) {
    const bool ga = static_cast<bool>(std::getline(sa, la)), gb = static_cast<bool>(std::getline(sb, lb));
    if (!ga && !gb) return "none";
    if (!ga || !gb || la != lb)
      return "line " + std::to_string(line) + ":\n  docs/config.md: " + (ga ? la : "(end)") + "\n  plaf keys:      " + (gb ? lb : "(end)");
  }
}

// The reference's rows: (document, key) -> type, read from its Markdown (the tables' first two
// columns; the study file's section is "## Study files").
std::map<std::pair<std::string, std::string>, std::string> reference_keys(const std::string& markdown) {
  std::map<std::pair<std::string, std::string>, std::string> out;
  std::string document = "run";
  std::istringstream in(markdown);
  const std::regex row("^\\| `([^`]+)` \\| ([^|]+) \\|");
  std::smatch m;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("## ", 0) == 0) document = line == "## Study files" ? "study" : "run";
    if (std::regex_search(line, m, row)) out[{document, m[1]}] = m[2];
  }
  return out;
}

// Every key path a YAML document uses: maps' keys, list items as "[]". A study's sections passed on
// to its runs (type "YAML, passed on") hold run configuration keys: they are checked as such, under
// the path without "cases[].".
void collect_paths(const YAML::Node& map, const std::string& document, const std::string& prefix,
                   const std::map<std::pair<std::string, std::string>, std::string>& ref,
                   std::set<std::pair<std::string, std::string>>& out) {
  for (const auto& kv : map) {
    const std::string path = (prefix.empty() ? "" : prefix + ".") + kv.first.Scalar();
    out.insert({document, path});
    std::string doc = document, inner = path;
    const auto it = ref.find({document, path});
    if (document == "study" && it != ref.end() && it->second == "YAML, passed on") {
      doc = "run";
      inner = path.substr(std::string("cases[].").size());
    }
    if (kv.second.IsMap()) collect_paths(kv.second, doc, inner, ref, out);
    if (kv.second.IsSequence())
      for (const YAML::Node& item : kv.second)
        if (item.IsMap()) collect_paths(item, doc, inner + "[]", ref, out);
  }
}

// Every map of a YAML document with its dotted path as the parser names it ("geometry.bodies[0]").
void collect_maps(const YAML::Node& map, const std::string& path, std::vector<std::string>& out) {
  out.push_back(path);
  for (const auto& kv : map) {
    const std::string p = (path.empty() ? "" : path + ".") + kv.first.Scalar();
    if (kv.second.IsMap()) collect_maps(kv.second, p, out);
    if (kv.second.IsSequence())
      for (std::size_t i = 0; i < kv.second.size(); ++i)
        if (kv.second[i].IsMap()) collect_maps(kv.second[i], p + "[" + std::to_string(i) + "]", out);
  }
}

// The document with `key: 1` added to the map at path (as collect_maps names it).
std::string with_key(const std::string& text, const std::string& path, const std::string& key) {
  YAML::Node document = YAML::Load(text);
  YAML::Node cur = document;
  std::stringstream parts(path);
  for (std::string part; std::getline(parts, part, '.');) {
    const std::size_t bracket = part.find('[');
    YAML::Node next = cur[part.substr(0, bracket)];
    if (bracket != std::string::npos) next.reset(next[std::stoul(part.substr(bracket + 1))]);
    cur.reset(next);
  }
  cur[key] = 1;
  YAML::Emitter e;
  e << document;
  return std::string(e.c_str()) + "\n";
}

std::vector<fs::path> shipped_configs() {
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(PLAF_CONFIGS))
    if (e.path().extension() == ".yaml") out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

bool is_study(const YAML::Node& config) { return static_cast<bool>(config["cases"]); }

}  // namespace

TEST_CASE("keys: docs/config.md is what plaf keys --markdown prints, and the reference is complete") {
  TempDir dir("keys_doc");
  const PlafOutput o = run_plaf_output("keys --markdown", dir);
  REQUIRE(o.code == 0);
  // A warning is a hole in the reference: a registered type no configuration selects, a key only
  // tested for presence, a key without a description (apps/keys.cpp says how each is found).
  CHECK_MESSAGE(o.err.empty(), o.err);
  const std::string doc = read_text(root / "docs" / "config.md");
  CHECK_MESSAGE(doc == o.out, "docs/config.md is stale: regenerate it with `plaf keys --markdown > docs/config.md`; first "
                              "difference at " << first_difference(doc, o.out));
  // Every key has a type, a default and a description, and each registered stage section is there.
  const auto keys = reference_keys(o.out);
  CHECK(keys.size() > 100);
  for (const char* section : {"geometry", "metric", "surface", "extrude", "layers", "fill", "limits", "validity", "output"})
    CHECK_MESSAGE(o.out.find("\n## `" + std::string(section) + "`\n") != std::string::npos, section);
  const std::regex empty_cell("\\|\\s*\\|");
  std::istringstream in(o.out);
  for (std::string line; std::getline(in, line);)
    if (line.rfind("| `", 0) == 0) CHECK_MESSAGE(!std::regex_search(line, empty_cell), line);
}

TEST_CASE("keys: the example configuration of docs/config.md parses") {
  const std::string doc = read_text(root / "docs" / "config.md");
  const std::size_t from = doc.find("```yaml\n"), to = doc.find("```\n", from + 8);
  REQUIRE(from != std::string::npos);
  REQUIRE(to != std::string::npos);
  const plaf::RunConfig c = plaf::parse_run_config(doc.substr(from + 8, to - from - 8), (root / "docs" / "example.yaml").string());
  CHECK(c.dim == 3);
  CHECK(c.layers.type == "extrude");
  CHECK(c.fill.type == "tetgen");
}

TEST_CASE("keys: plaf keys SECTION prints that section, an unknown one is one error line and exit 1") {
  TempDir dir("keys_section");
  const PlafOutput layers = run_plaf_output("keys layers", dir);
  REQUIRE(layers.code == 0);
  CHECK(layers.out.rfind("layers: ", 0) == 0);
  CHECK(layers.out.find("  layers.f_atten  (number in [0, 1]; default 0.2; read by extrude)") != std::string::npos);
  CHECK(layers.out.find("geometry.") == std::string::npos);
  const PlafOutput bad = run_plaf_output("keys nosuch", dir);
  CHECK(bad.code == plaf::exit_code::bad_input);
  CHECK(bad.out.empty());
  CHECK(bad.err.find("unknown section 'nosuch' (known: top, geometry, metric,") != std::string::npos);
  CHECK(bad.err.find("study)") != std::string::npos);
  CHECK(std::count(bad.err.begin(), bad.err.end(), '\n') == 1);
  CHECK(run_plaf_output("--help", dir).out.find("plaf keys [SECTION]") != std::string::npos);
  const PlafOutput empty = run_plaf_output("keys ''", dir);
  CHECK(empty.code == plaf::exit_code::bad_input);
  CHECK(empty.out.empty());
  CHECK(empty.err.find("unknown section '' (known: top,") != std::string::npos);
  // One section in Markdown: a usage error (the usage printed), before any collecting.
  const PlafOutput markdown = run_plaf_output("keys layers --markdown", dir);
  CHECK(markdown.code == plaf::exit_code::bad_input);
  CHECK(markdown.out.empty());
  CHECK(markdown.err.find("keys --markdown prints the whole reference") != std::string::npos);
  CHECK(markdown.err.find("usage: plaf run") != std::string::npos);
}

TEST_CASE("keys: every key a shipped config uses is in the reference, and a key outside it is refused naming it") {
  TempDir dir("keys_configs");
  const PlafOutput o = run_plaf_output("keys --markdown", dir);
  REQUIRE(o.code == 0);
  const auto ref = reference_keys(o.out);
  int used = 0, refused = 0;
  for (const fs::path& file : shipped_configs()) {
    INFO(file.filename().string());
    const YAML::Node config = YAML::LoadFile(file.string());
    const std::string document = is_study(config) ? "study" : "run";
    std::set<std::pair<std::string, std::string>> paths;
    collect_paths(config, document, "", ref, paths);
    for (const auto& p : paths) {
      INFO(p.first << " key " << p.second);
      CHECK(ref.count(p) == 1);
      ++used;
    }
    if (document == "study") continue;  // its unknown keys: below, through the command
    // An unknown key in any map of the configuration: one line naming it as the YAML writes it.
    std::vector<std::string> maps;
    collect_maps(config, "", maps);
    const std::string text = read_text(file);
    for (const std::string& m : maps) {
      const std::string key = (m.empty() ? "" : m + ".") + "plaf_unknown_key";
      INFO("added " << key);
      try {
        plaf::parse_run_config(with_key(text, m, "plaf_unknown_key"), file.string());
        FAIL("accepted");
      } catch (const plaf::MissingDataError&) {
        plaf::test::request_skip("a shipped config's published file is in no data root");
        break;
      } catch (const plaf::ConfigError& e) {
        const std::string what = e.what();
        CHECK(what.find("unknown key '" + key + "'") != std::string::npos);
        CHECK(what.find('\n') == std::string::npos);
        ++refused;
      }
    }
  }
  CHECK(used > 300);
  CHECK(refused > 100);
}

TEST_CASE("keys: plaf run and compare-attenuation refuse a key outside the reference with one line, exit 1, nothing written") {
  TempDir dir("keys_unknown");
  const fs::path run = write_text(dir / "run.yaml", "order: 2\ngeometry: {type: annulus}\nlayers: {type: extrude, f_aten: 0.3}\n");
  const PlafOutput r = run_plaf_output("run " + run.string() + " --out " + (dir / "out").string(), dir);
  CHECK(r.code == plaf::exit_code::bad_input);
  CHECK(r.err.find("unknown key 'layers.f_aten' (known here: ") != std::string::npos);
  CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  CHECK_FALSE(fs::exists(dir / "out"));
  // The shipped study, with a key added to each map its own parser reads (its cases' run sections
  // are checked by the runs' parse, above).
  const fs::path study = fs::path(PLAF_CONFIGS) / "attenuation_study.yaml";
  const YAML::Node config = YAML::LoadFile(study.string());
  const auto ref = reference_keys(run_plaf_output("keys --markdown", dir).out);
  std::vector<std::string> maps;
  collect_maps(config, "", maps);
  int checked = 0;
  for (const std::string& m : maps) {
    // Skipped: a map inside a section passed on to the runs.
    const std::string pattern = std::regex_replace(m, std::regex("\\[[0-9]+\\]"), "[]");
    bool passed_on = false;
    for (std::size_t dot = 0; dot != std::string::npos && !pattern.empty(); dot = pattern.find('.', dot + 1)) {
      std::string prefix = pattern.substr(0, pattern.find('.', dot + 1));
      if (prefix.size() > 2 && prefix.compare(prefix.size() - 2, 2, "[]") == 0) prefix.resize(prefix.size() - 2);
      const auto it = ref.find({"study", prefix});
      passed_on = passed_on || (it != ref.end() && it->second == "YAML, passed on");
    }
    if (passed_on) continue;
    const std::string key = (m.empty() ? "" : m + ".") + "plaf_unknown_key";
    INFO("added " << key);
    const fs::path bad = write_text(dir / "study.yaml", with_key(read_text(study), m, "plaf_unknown_key"));
    const PlafOutput s = run_plaf_output("compare-attenuation " + bad.string() + " --out " + (dir / "study_out").string(), dir);
    CHECK(s.code == plaf::exit_code::bad_input);
    CHECK(s.err.find("unknown key '" + key + "'") != std::string::npos);
    CHECK(std::count(s.err.begin(), s.err.end(), '\n') == 1);
    CHECK_FALSE(fs::exists(dir / "study_out"));
    ++checked;
  }
  CHECK(checked >= 2);
}

namespace {

// The reference's range column by run configuration key, read from its Markdown.
std::map<std::string, std::string> reference_ranges(const std::string& markdown, std::map<std::string, std::string>* read_by) {
  std::map<std::string, std::string> out;
  std::istringstream in(markdown);
  bool study = false;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("## ", 0) == 0) study = line == "## Study files";
    if (study || line.rfind("| `", 0) != 0) continue;
    std::vector<std::string> cells;
    for (std::size_t from = 2;;) {
      const std::size_t bar = line.find(" | ", from);
      if (bar == std::string::npos) break;
      cells.push_back(line.substr(from, bar - from));
      from = bar + 3;
    }
    if (cells.size() < 5) continue;
    const std::string key = cells[0].substr(1, cells[0].size() - 2);
    out[key] = cells[3];
    if (read_by) (*read_by)[key] = cells[4];
  }
  return out;
}

// text with the key at path ("a.b[].c": in the first item of list b) set to value.
std::string set_key(const std::string& text, const std::string& path, const YAML::Node& value) {
  YAML::Node document = YAML::Load(text);
  YAML::Node cur = document;
  std::vector<std::string> names;
  std::stringstream parts(path);
  for (std::string part; std::getline(parts, part, '.');) names.push_back(part);
  for (std::size_t i = 0; i < names.size(); ++i) {
    const bool item = names[i].size() > 2 && names[i].compare(names[i].size() - 2, 2, "[]") == 0;
    const std::string name = item ? names[i].substr(0, names[i].size() - 2) : names[i];
    if (i + 1 == names.size()) {
      cur[name] = value;
      break;
    }
    if (!cur[name].IsDefined() || cur[name].IsNull()) cur[name] = YAML::Node(YAML::NodeType::Map);
    YAML::Node next = cur[name];
    if (item) {  // the first item holding the next key, or the first
      std::size_t k = 0;
      const std::string inner = names[i + 1].substr(0, names[i + 1].find('['));
      while (k + 1 < next.size() && !next[k][inner]) ++k;
      next.reset(next[k]);
    }
    cur.reset(next);
  }
  YAML::Emitter e;
  e << document;
  return std::string(e.c_str()) + "\n";
}

std::string number_text(double x) {
  std::ostringstream s;
  s.precision(17);
  s << x;
  return s.str();
}

// "" when the configuration parses, else the error (a ConfigError's message, or "other: ...").
std::string parse_error(const std::string& text) {
  try {
    plaf::parse_run_config(text, "probe.yaml");
    return "";
  } catch (const plaf::ConfigError& e) {
    return e.what();
  } catch (const std::exception& e) {
    return std::string("other: ") + e.what();
  }
}

}  // namespace

TEST_CASE("keys: the reference is true: each range and choice it prints is what the parse accepts and refuses") {
  TempDir dir("keys_true");
  const PlafOutput probes = run_plaf_output("keys --probes", dir);
  REQUIRE(probes.code == 0);
  const PlafOutput doc = run_plaf_output("keys --markdown", dir);
  REQUIRE(doc.code == 0);
  std::map<std::string, std::string> read_by;
  const auto ranges = reference_ranges(doc.out, &read_by);
  const std::map<std::string, std::string> types = [&] {
    std::map<std::string, std::string> out;
    for (const auto& [key, type] : reference_keys(doc.out))
      if (key.first == "run") out[key.second] = type;
    return out;
  }();
  const YAML::Node list = YAML::Load(probes.out);
  REQUIRE(list.IsSequence());
  int numeric = 0, words = 0;
  for (const YAML::Node& probe : list) {
    const std::string key = probe["key"].as<std::string>(), range = probe["range"].as<std::string>();
    INFO("key " << key << ", range " << range);
    REQUIRE(ranges.count(key) == 1);
    std::vector<std::string> configs;
    for (const YAML::Node& c : probe["configs"]) configs.push_back(c.as<std::string>());
    REQUIRE(!configs.empty());
    const std::string named = key + ": ";  // in the message with its items' indices as []
    const bool list_value = types.at(key).find("list of numbers") != std::string::npos;
    auto node = [&](const std::string& v) { return list_value ? YAML::Load("[" + v + ", " + v + ", " + v + "]") : YAML::Node(v); };
    // The first configuration that accepts one of `inside` (tried in order: another key may bound
    // it, r_outer above r_inner): the one the bounds are tried on.
    auto accepting = [&](const std::vector<std::string>& inside) -> std::optional<std::string> {
      std::string errors;
      for (const std::string& v : inside)
        for (const std::string& c : configs) {
          const std::string e = parse_error(set_key(c, key, node(v)));
          if (e.empty()) return c;
          errors += "\n  " + v + ": " + e;
        }
      FAIL_CHECK("no configuration accepts the values inside:" << errors);
      return std::nullopt;
    };
    auto refused = [&](const std::string& config, const std::string& outside) {
      const std::string e = parse_error(set_key(config, key, node(outside)));
      INFO("outside value " << outside << ": " << (e.empty() ? "accepted" : e));
      CHECK(std::regex_replace(e, std::regex("\\[[0-9]+\\]"), "[]").find(named) != std::string::npos);
      CHECK(e.rfind("other: ", 0) != 0);
    };
    if (range.rfind("words: ", 0) == 0) {
      // The reference lists these words, each is accepted, another word is refused naming the key.
      std::stringstream in(range.substr(7));
      std::optional<std::string> config;
      for (std::string w; std::getline(in, w, ',');) {
        w.erase(0, w.find_first_not_of(' '));
        CHECK(ranges.at(key).find(w) != std::string::npos);
        config = accepting({w});
      }
      if (config) refused(*config, "plaf_no_such_word");
      ++words;
      continue;
    }
    // The reference prints the range the getters check (in its cell, among other types' ranges).
    CHECK(ranges.at(key).find(range) != std::string::npos);
    std::string r = range;
    const bool zero_too = r.rfind("0 or ", 0) == 0;
    if (zero_too) r = r.substr(5);
    const bool integer = r.find("..") != std::string::npos && r[0] != '[' && r[0] != '(';
    double lo = 0, hi = 0;
    bool open_lo = false, open_hi = false, has_hi = true;
    if (integer) {
      lo = std::stod(r.substr(0, r.find(".."))), hi = std::stod(r.substr(r.find("..") + 2));
    } else if (r[0] == '>') {
      open_lo = r[1] != '=';
      lo = std::stod(r.substr(open_lo ? 2 : 3));
      has_hi = false;
    } else {
      REQUIRE((r[0] == '[' || r[0] == '('));
      open_lo = r[0] == '(', open_hi = r.back() == ')';
      lo = std::stod(r.substr(1, r.find(',') - 1)), hi = std::stod(r.substr(r.find(',') + 2));
    }
    std::vector<std::string> inside;
    if (has_hi)
      inside.push_back(number_text(integer ? std::floor((lo + hi) / 2) : (lo + hi) / 2));
    else
      for (double above : {1.0, 100.0}) inside.push_back(number_text(lo + std::max(std::abs(lo), 1.0) * above));
    const std::optional<std::string> config = accepting(inside);
    if (!config) continue;
    if (zero_too) CHECK(parse_error(set_key(*config, key, node("0"))) == "");
    // A closed end is in (metric.growth's 1 was refused after a reference saying [1, 10]).
    if (!open_lo) accepting({number_text(lo)});
    if (has_hi && !open_hi) accepting({number_text(hi)});
    // Just outside each end: the open end itself, or a step beyond the closed one.
    const double below = open_lo ? lo : lo - (integer ? 1 : (lo == 0 ? 1e-3 : std::abs(lo) * 1e-3));
    if (!(zero_too && below == 0)) refused(*config, number_text(below));
    if (has_hi) refused(*config, number_text(open_hi ? hi : hi + (integer ? 1 : std::max(std::abs(hi), 1.0) * 1e-3)));
    ++numeric;
  }
  CHECK(numeric > 50);
  CHECK(words > 15);
  // A key the reference gives to 2D only is refused in a 3D configuration.
  for (const char* key : {"curvature_factor", "h_corner"}) {
    INFO(key);
    CHECK(read_by.at(std::string("metric.") + key) == "wall_power_law (2D)");
    CHECK(parse_error("geometry: {type: airfoils, bodies: [{file: a.dat}]}\nmetric: {type: wall_power_law, " +
                      std::string(key) + ": 0.3}\n") == "");
    const std::string e = parse_error("geometry: {type: sphere}\nmetric: {type: wall_power_law, " + std::string(key) + ": 0.3}\n");
    CHECK(e.find("metric." + std::string(key) + ": not a 3D wall_power_law key") != std::string::npos);
  }
}
