// SPDX-License-Identifier: MIT
// The architecture as tests (docs/architecture.md): the link rule read from the sources' includes,
// and every stage kind's plugins registered and listed by `plaf plugins`.
#include <doctest/doctest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "modules/pipeline/stages.h"

namespace fs = std::filesystem;

namespace {

const fs::path root = fs::path(PLAF_CONFIGS).parent_path();

// The repository folders (modules, surface3d, layers, volume, apps) a folder's sources include.
std::map<std::string, std::set<std::string>> includes_of(const std::string& folder) {
  std::map<std::string, std::set<std::string>> out;  // included folder -> including files
  const std::regex inc("^#include \"([a-z0-9_]+)/");
  for (const auto& e : fs::recursive_directory_iterator(root / folder)) {
    const std::string ext = e.path().extension().string();
    if (!e.is_regular_file() || (ext != ".h" && ext != ".cpp")) continue;
    std::ifstream in(e.path());
    std::string line;
    std::smatch m;
    while (std::getline(in, line))
      if (std::regex_search(line, m, inc)) out[m[1]].insert(e.path().lexically_relative(root).string());
  }
  return out;
}

std::string run_plaf_plugins() {
  std::string out;
  std::unique_ptr<FILE, int (*)(FILE*)> p(popen((std::string(PLAF_EXE) + " plugins").c_str(), "r"), pclose);
  REQUIRE(p);
  char buf[512];
  while (fgets(buf, sizeof buf, p.get())) out += buf;
  return out;
}

}  // namespace

TEST_CASE("architecture: stages include only core, core includes no stage") {
  const std::map<std::string, std::set<std::string>> allowed = {
      {"modules", {"modules"}},
      {"surface3d", {"modules", "surface3d"}},
      {"layers", {"modules", "layers"}},
      {"volume", {"modules", "volume"}},
  };
  for (const auto& [folder, ok] : allowed) {
    INFO(folder);
    const auto inc = includes_of(folder);
    CHECK(inc.count("modules") == 1);  // the scan sees the includes at all
    for (const auto& [target, files] : inc) {
      INFO(target << " included by " << *files.begin());
      CHECK(ok.count(target) == 1);
    }
  }
}

TEST_CASE("architecture: every stage kind has registered plugins, all listed by plaf plugins") {
  const std::string listing = run_plaf_plugins();
  REQUIRE(listing == plaf::plugin_listing());  // the test runner registers what the driver does
  for (plaf::StageKind k : plaf::all_stage_kinds) {
    INFO(plaf::stage_kind_name(k));
    CHECK(listing.find(std::string(plaf::stage_kind_name(k)) + ":\n") != std::string::npos);
    CHECK_FALSE(plaf::stage_registry<2>(k).names().empty());
    CHECK_FALSE(plaf::stage_registry<3>(k).names().empty());
    for (const std::string& name : plaf::stage_registry<2>(k).names()) CHECK(listing.find(name) != std::string::npos);
  }
  // The shipped configurations' types are all registered (their runs are in configs_test).
  for (const char* type : {"annulus", "airfoils", "sphere", "box", "wing", "surface_file"})
    CHECK(listing.find(type) != std::string::npos);
  for (const char* type : {"wall_power_law", "background", "curves", "remesh", "extrude", "advancing_front"})
    CHECK(listing.find(type) != std::string::npos);
}
