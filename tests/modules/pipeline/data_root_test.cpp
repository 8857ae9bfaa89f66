// SPDX-License-Identifier: MIT
// The data root (modules/pipeline/data_root.h): `data:REL` paths found in --data, then PLAF_DATA,
// then ../shared/data beside the source tree; a missing file is one line naming the key, the file,
// the roots tried and where the file comes from; the provenance catalogue matches docs/data.md.
#include "modules/pipeline/data_root.h"

#include <doctest/doctest.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <regex>
#include <set>
#include <string>

#include "modules/pipeline/config.h"
#include "tests/published_data.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using plaf::test::read_text;
using plaf::test::TempDir;
using plaf::test::write_text;

namespace {

const fs::path repo = fs::path(PLAF_CONFIGS).parent_path();

// PLAF_DATA set (or unset) for the life of the object, restored after.
class ScopedEnv {
 public:
  explicit ScopedEnv(const std::optional<std::string>& value) {
    if (const char* old = std::getenv("PLAF_DATA")) old_ = old;
    if (value)
      ::setenv("PLAF_DATA", value->c_str(), 1);
    else
      ::unsetenv("PLAF_DATA");
  }
  ~ScopedEnv() {
    if (old_)
      ::setenv("PLAF_DATA", old_->c_str(), 1);
    else
      ::unsetenv("PLAF_DATA");
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  std::optional<std::string> old_;
};

// --data for the life of the object.
struct ScopedOption {
  explicit ScopedOption(const fs::path& dir) { plaf::set_data_root_option(dir); }
  ~ScopedOption() { plaf::set_data_root_option(""); }
  ScopedOption(const ScopedOption&) = delete;
  ScopedOption& operator=(const ScopedOption&) = delete;
};

}  // namespace

TEST_CASE("data root: --data before PLAF_DATA before the shelf beside the source tree, one rule for every path key") {
  const TempDir a("data_root_a"), b("data_root_b");
  fs::create_directories(a.path / "airfoils");
  fs::create_directories(b.path / "airfoils");
  write_text(a.path / "airfoils" / "only_a.dat", "a");
  write_text(a.path / "airfoils" / "both.dat", "a");
  write_text(b.path / "airfoils" / "both.dat", "b");
  const ScopedEnv env(b.path.string());
  CHECK(plaf::find_data_file("airfoils/both.dat") == (b.path / "airfoils" / "both.dat").string());
  CHECK_FALSE(plaf::find_data_file("airfoils/only_a.dat").has_value());
  {
    const ScopedOption option(a.path);
    CHECK(plaf::find_data_file("airfoils/both.dat") == (a.path / "airfoils" / "both.dat").string());
    CHECK(plaf::find_data_file("airfoils/only_a.dat") == (a.path / "airfoils" / "only_a.dat").string());
    // Through a config's path key, in any section (ConfigNode::get_path).
    const plaf::ConfigNode n = plaf::ConfigNode::load_string("file: data:airfoils/only_a.dat\nsol: plain.sol\n",
                                                             (a.path / "case.yaml").string());
    CHECK(n.get_path("file", "") == (a.path / "airfoils" / "only_a.dat").string());
    CHECK(n.get_path("sol", "") == (a.path / "plain.sol").string());  // plain paths: beside the config
  }
  // The roots, in order, with where each came from.
  const std::vector<plaf::DataRoot> roots = plaf::data_roots();
  REQUIRE(roots.size() == 3);
  CHECK(roots[0].origin == "--data");
  CHECK_FALSE(roots[0].dir.has_value());
  CHECK(roots[1].origin == "PLAF_DATA");
  CHECK(roots[1].dir == b.path.string());
  REQUIRE(roots[2].dir.has_value());
  CHECK(fs::path(*roots[2].dir) == repo.parent_path() / "shared" / "data");
  // --data must name a folder.
  CHECK_THROWS_WITH_AS(plaf::set_data_root_option(a.path / "airfoils" / "both.dat"), doctest::Contains("not a directory"),
                       plaf::InputError);
}

TEST_CASE("data root: a data path stays inside the root") {
  for (const char* bad : {"data:", "data:/etc/passwd", "data:../configs/annulus.yaml", "data:airfoils/../../x.dat"}) {
    INFO(bad);
    const plaf::ConfigNode n = plaf::ConfigNode::load_string(std::string("file: \"") + bad + "\"\n", "case.yaml");
    CHECK_THROWS_WITH_AS(n.get_path("file", ""), doctest::Contains("case.yaml:1:7: file: '"), plaf::ConfigError);
  }
}

TEST_CASE("data root: a missing published file is one line naming the key, the file, the roots tried and its source") {
  const std::vector<plaf::DataRoot> roots = {
      {"--data", std::nullopt}, {"PLAF_DATA", "/nowhere/data"}, {"beside the source tree", "/src/../shared/data"}};
  const std::string m = plaf::missing_data_message("data:airfoils/e387.dat", "c.yaml:8:13: geometry.bodies[0].file", roots);
  CHECK(m.find('\n') == std::string::npos);
  CHECK(m.rfind("c.yaml:8:13: geometry.bodies[0].file: published file 'data:airfoils/e387.dat' not found", 0) == 0);
  CHECK(m.find("roots tried: --data (not given), /nowhere/data (PLAF_DATA), /src/../shared/data (beside the source tree)") !=
        std::string::npos);
  CHECK(m.find("it comes from peterdsharpe/AeroSandbox aerosandbox/geometry/airfoil/airfoil_database/e387.dat (MIT)") !=
        std::string::npos);
  CHECK(m.find("--data DIR or PLAF_DATA") != std::string::npos);
  const std::string unknown = plaf::missing_data_message("data:surfaces/mine.stl", "k", roots);
  CHECK(unknown.find("not in plaf's provenance notes") != std::string::npos);
}

TEST_CASE("data root: plaf run with a missing published file exits 1 within a second, one line, nothing written") {
  const TempDir d("data_root_cli");
  const fs::path cfg = write_text(d / "missing.yaml",
                                  "name: missing\ngeometry:\n  type: surface_file\n  file: data:surfaces/no_such_body.stl\n"
                                  "metric: {type: uniform, h: 0.2}\n");
  fs::create_directories(d.path / "empty_root");
  const auto t0 = std::chrono::steady_clock::now();
  const plaf::test::PlafResult r =
      plaf::test::run_plaf("run " + cfg.string() + " --data " + (d.path / "empty_root").string() + " --out " +
                               (d.path / "out").string(),
                           d);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  INFO(r.err);
  CHECK(r.code == 1);
  CHECK(seconds < 1.0);
  CHECK(r.err == "plaf: error: " + cfg.string() +
                     ":4:9: geometry.file: published file 'data:surfaces/no_such_body.stl' not found; roots tried: " +
                     (d.path / "empty_root").string() + " (--data), " +
                     (std::getenv("PLAF_DATA") ? std::string(std::getenv("PLAF_DATA")) + " (PLAF_DATA)"
                                               : std::string("PLAF_DATA (not set)")) +
                     ", " + plaf::data_roots()[2].dir.value_or("") +
                     " (beside the source tree); it is not in plaf's provenance notes (docs/data.md); point plaf at a "
                     "folder holding surfaces/no_such_body.stl with --data DIR or PLAF_DATA\n");
  CHECK(plaf::test::count_files(d.path / "out") == 0);
  // --data naming no folder is a usage error.
  const plaf::test::PlafResult bad = plaf::test::run_plaf("run " + cfg.string() + " --data " + (d.path / "nope").string(), d);
  CHECK(bad.code == 1);
  CHECK(bad.err.find("--data " + (d.path / "nope").string() + ": not a directory") != std::string::npos);
}

TEST_CASE("data root: the provenance catalogue lists the files of docs/data.md, and every file of the shelf") {
  // docs/data.md's table rows: | `airfoils/e387.dat` | ... |
  const std::string doc = read_text(repo / "docs" / "data.md");
  std::set<std::string> documented;
  const std::regex row(R"(\n\| `((?:airfoils|surfaces)/[A-Za-z0-9_.]+)` \|)");
  for (std::sregex_iterator m(doc.begin(), doc.end(), row), end; m != end; ++m) documented.insert((*m)[1].str());
  std::set<std::string> catalogued;
  for (const plaf::DataCatalogueRow& r : plaf::data_catalogue()) catalogued.insert(r.path);
  CHECK(documented.size() >= 20);
  CHECK(documented == catalogued);
  // The shelf, where it is beside the repository: nothing on it that plaf cannot say the source of.
  const fs::path shelf = repo.parent_path() / "shared" / "data";
  if (!fs::is_directory(shelf)) {
    plaf::test::request_skip("no shelf beside the repository (" + shelf.string() + ")");
    return;
  }
  for (const char* folder : {"airfoils", "surfaces"})
    for (const auto& e : fs::directory_iterator(shelf / folder)) {
      const std::string rel = std::string(folder) + "/" + e.path().filename().string();
      INFO(rel);
      CHECK(plaf::data_provenance(rel).has_value());
    }
}
