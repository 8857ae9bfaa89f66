// SPDX-License-Identifier: MIT
// The repository stands alone: every path a shipped configuration names is a file inside the
// repository or a published file named through the data root (`data:REL`, listed in the provenance
// catalogue of modules/pipeline/data_root.h); the tests' data folders are inside it; data/ holds
// only generated files and their generators; and no shipped source, script, config or document
// points beside it except the data root's own rule (its code and its documentation).
#include <doctest/doctest.h>

#include <unistd.h>

#include <cstdlib>

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "modules/pipeline/data_root.h"
#include "tests/published_data.h"

namespace fs = std::filesystem;

namespace {

const fs::path root = fs::weakly_canonical(fs::path(PLAF_CONFIGS).parent_path());

// Whether p, made absolute and normalised (symbolic links followed where they exist), lies in the
// repository.
bool inside_root(const fs::path& p) {
  const fs::path rel = fs::weakly_canonical(p).lexically_relative(root);
  return !rel.empty() && *rel.begin() != "..";
}

std::string read_all(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The shipped text files: sources, CMake, scripts, configs and documents, in the folders that
// hold them (a build folder inside the repository is not scanned).
std::vector<fs::path> shipped_text_files() {
  const std::set<std::string> folders = {"apps",    "bench",   "configs",   "data",  "docs",   "layers",
                                         "modules", "scripts", "surface3d", "tests", "volume", ".ci"};
  const std::set<std::string> exts = {".cpp", ".h", ".txt", ".cmake", ".py", ".sh", ".md", ".yaml", ""};
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(root)) {
    const std::string name = e.path().filename().string();
    if (e.is_regular_file() && exts.count(e.path().extension().string())) out.push_back(e.path());
    if (!e.is_directory() || !folders.count(name)) continue;
    for (const auto& f : fs::recursive_directory_iterator(e.path()))
      if (f.is_regular_file() && exts.count(f.path().extension().string())) out.push_back(f.path());
  }
  return out;
}

}  // namespace

TEST_CASE("repository: every path a shipped config names is a file inside the repository") {
  // Path keys (ConfigNode::get_path): `file` (contours, wing sections, surfaces, background
  // meshes) and `sol`, in block (`file: x`) or flow (`{file: x, name: y}`) style.
  const std::regex path_key(R"((?:^|[\s{,])(file|sol)\s*:\s*["']?([^\s,}"'#]+))");
  int configs = 0, paths = 0;
  for (const auto& e : fs::directory_iterator(root / "configs")) {
    if (e.path().extension() != ".yaml") continue;
    ++configs;
    std::ifstream in(e.path());
    std::string line;
    for (int n = 1; std::getline(in, line); ++n) {
      const std::string code = line.substr(0, line.find('#'));
      for (std::sregex_iterator m(code.begin(), code.end(), path_key), end; m != end; ++m) {
        ++paths;
        const std::string raw = (*m)[2].str();
        INFO(e.path().filename().string() << ":" << n << ": " << (*m)[1].str() << ": " << raw);
        if (raw.rfind(plaf::kDataPrefix, 0) == 0) {  // published: in the catalogue
          CHECK(plaf::data_provenance(raw.substr(std::string(plaf::kDataPrefix).size())).has_value());
          continue;
        }
        const fs::path value = raw;
        const fs::path resolved = value.is_absolute() ? value : e.path().parent_path() / value;
        INFO(e.path().filename().string() << ":" << n << ": " << (*m)[1].str() << ": " << value.string());
        CHECK(value.is_relative());
        CHECK(inside_root(resolved));
        CHECK(fs::is_regular_file(resolved));
      }
    }
  }
  CHECK(configs > 0);
  CHECK(paths > 0);  // the scan sees the paths at all
}

TEST_CASE("repository: the tests' data folders are inside the repository") {
  for (const char* dir : {PLAF_REPO_DATA, PLAF_TEST_DATA, PLAF_CONFIGS}) {
    INFO(dir);
    CHECK(inside_root(dir));
    CHECK(fs::is_directory(dir));
  }
}

TEST_CASE("repository: no shipped file refers to a folder beside the repository") {
  // What the sources used before data/ was in the repository, and CMake paths that climb out of
  // it; each spelled in two parts so that this file does not match its own scan.
  const std::string up = "/..";
  const std::vector<std::string> outside = {".." + std::string("/shared"), "shared" + std::string("/data"),
                                            "PROJECT_SOURCE_DIR}" + up, "CMAKE_SOURCE_DIR}" + up};
  // The data root's rule names the shelf beside the repository: its code, the CLI's usage, the
  // test helper that follows it, and the documents that explain it.
  const std::set<std::string> rule = {"modules/pipeline/data_root.cpp", "modules/pipeline/data_root.h",
                                      "apps/plaf_main.cpp", "tests/published_data.h",
                                      "tests/modules/pipeline/data_root_test.cpp",
                                      "docs/data.md",
                                      "README.md", "docs/architecture.md"};
  int scanned = 0;
  for (const fs::path& f : shipped_text_files()) {
    if (rule.count(f.lexically_relative(root).generic_string())) continue;
    ++scanned;
    const std::string text = read_all(f);
    for (const std::string& s : outside) {
      INFO(f.lexically_relative(root).string() << " contains " << s);
      CHECK(text.find(s) == std::string::npos);
    }
  }
  CHECK(scanned > 100);
}

TEST_CASE("repository: data/ holds only generators and the files they write, none a copy of the shelf") {
  // Every file under data/ is a generator (make_*.py) or the output of one, and the generator run
  // into a scratch file writes the same bytes as that output -- or, where the output is not
  // committed because the reference shelf holds it (airfoils/naca0012_sharp.dat), as the shelf's
  // file in the data root. No committed file is a copy of a file of the shelf.
  const fs::path data = root / "data";
  std::set<std::string> outputs;
  int generators = 0;
  for (const auto& e : fs::directory_iterator(data)) {
    const std::string name = e.path().filename().string();
    if (!e.is_regular_file() || name.rfind("make_", 0) != 0 || e.path().extension() != ".py") continue;
    ++generators;
    // The output a generator writes by default is named in its docstring: "Writes DIR/FILE.EXT",
    // or "Writes DIR/FILE.EXT and .EXT2" for a pair (given one path, it writes the pair beside it).
    const std::string text = read_all(e.path());
    std::smatch m;
    REQUIRE_MESSAGE(std::regex_search(text, m, std::regex(R"(Writes ([A-Za-z0-9_/]+)(\.[a-z]+)(?: and (\.[a-z]+))?)")), name);
    std::vector<std::string> extensions = {m[2].str()};
    if (m[3].matched) extensions.push_back(m[3].str());
    const fs::path scratch = fs::temp_directory_path() / ("plaf_generated_" + std::to_string(::getpid()));
    const std::string cmd = "python3 " + e.path().string() + " " + scratch.string() + extensions.front() + " > /dev/null";
    INFO(cmd);
    REQUIRE(std::system(cmd.c_str()) == 0);
    for (const std::string& ext : extensions) {
      const std::string out = m[1].str() + ext;
      const fs::path written = scratch.string() + ext;
      outputs.insert(out);
      const std::string shelf = plaf::test::published(out);
      if (fs::exists(data / out))
        CHECK(read_all(written) == read_all(data / out));
      else if (!shelf.empty())
        CHECK(read_all(written) == read_all(shelf));
      else
        plaf::test::request_skip("no data root holds " + out + " to compare its generator's output with");
      fs::remove(written);
    }
  }
  CHECK(generators == 3);
  for (const auto& f : fs::recursive_directory_iterator(data)) {
    if (!f.is_regular_file()) continue;
    const std::string rel = f.path().lexically_relative(data).generic_string();
    INFO(rel);
    CHECK((outputs.count(rel) || (rel.rfind("make_", 0) == 0 && f.path().extension() == ".py")));
    const std::string shelf = plaf::test::published(rel);
    CHECK_MESSAGE((shelf.empty() || read_all(shelf) != read_all(f.path())), "a copy of the shelf's " << shelf);
  }
}
