// SPDX-License-Identifier: MIT
// The key reference (apps/keys.h): docs/config.md is exactly what `plaf keys --markdown` prints
// now and the reference is complete (no warning); every key a shipped configuration uses is in
// it; a key outside it is refused with one line naming it.
#include <doctest/doctest.h>
#include <sys/wait.h>
#include <yaml-cpp/yaml.h>

#include <cstdlib>
#include <filesystem>
#include <map>
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
using plaf::test::read_text;
using plaf::test::TempDir;
using plaf::test::write_text;

namespace {

const fs::path root = fs::path(PLAF_CONFIGS).parent_path();

struct Output {
  int code = -1;
  std::string out, err;
};

// `plaf args` with its stdout and stderr.
Output plaf_output(const std::string& args, const TempDir& dir) {
  const std::string cmd = std::string(PLAF_EXE) + " " + args + " > " + (dir / "out.txt").string() + " 2> " +
                          (dir / "err.txt").string();
  const int status = std::system(cmd.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, read_text(dir / "out.txt"), read_text(dir / "err.txt")};
}

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
  const Output o = plaf_output("keys --markdown", dir);
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
  const Output layers = plaf_output("keys layers", dir);
  REQUIRE(layers.code == 0);
  CHECK(layers.out.rfind("layers: ", 0) == 0);
  CHECK(layers.out.find("  layers.f_atten  (number in [0, 1]; default 0.2; read by extrude)") != std::string::npos);
  CHECK(layers.out.find("geometry.") == std::string::npos);
  const Output bad = plaf_output("keys nosuch", dir);
  CHECK(bad.code == plaf::exit_code::bad_input);
  CHECK(bad.out.empty());
  CHECK(bad.err.find("unknown section 'nosuch' (known: top, geometry, metric,") != std::string::npos);
  CHECK(bad.err.find("study)") != std::string::npos);
  CHECK(std::count(bad.err.begin(), bad.err.end(), '\n') == 1);
  CHECK(plaf_output("--help", dir).out.find("plaf keys [SECTION]") != std::string::npos);
}

TEST_CASE("keys: every key a shipped config uses is in the reference, and a key outside it is refused naming it") {
  TempDir dir("keys_configs");
  const Output o = plaf_output("keys --markdown", dir);
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
  const Output r = plaf_output("run " + run.string() + " --out " + (dir / "out").string(), dir);
  CHECK(r.code == plaf::exit_code::bad_input);
  CHECK(r.err.find("unknown key 'layers.f_aten' (known here: ") != std::string::npos);
  CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  CHECK_FALSE(fs::exists(dir / "out"));
  // The shipped study, with a key added to each map its own parser reads (its cases' run sections
  // are checked by the runs' parse, above).
  const fs::path study = fs::path(PLAF_CONFIGS) / "attenuation_study.yaml";
  const YAML::Node config = YAML::LoadFile(study.string());
  const auto ref = reference_keys(plaf_output("keys --markdown", dir).out);
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
    const Output s = plaf_output("compare-attenuation " + bad.string() + " --out " + (dir / "study_out").string(), dir);
    CHECK(s.code == plaf::exit_code::bad_input);
    CHECK(s.err.find("unknown key '" + key + "'") != std::string::npos);
    CHECK(std::count(s.err.begin(), s.err.end(), '\n') == 1);
    CHECK_FALSE(fs::exists(dir / "study_out"));
    ++checked;
  }
  CHECK(checked >= 2);
}
