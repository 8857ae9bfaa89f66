// SPDX-License-Identifier: MIT
// The repository stands alone: every path a shipped configuration names resolves to a file inside
// the repository, the tests' data folders are inside it, and no shipped source, script, config or
// document points beside it (the data once lived in a folder next to the repository, which a
// clone does not have).
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

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
        const fs::path value = (*m)[2].str();
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
  for (const char* dir : {PLAF_DATA, PLAF_TEST_DATA, PLAF_CONFIGS}) {
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
  int scanned = 0;
  for (const fs::path& f : shipped_text_files()) {
    ++scanned;
    const std::string text = read_all(f);
    for (const std::string& s : outside) {
      INFO(f.lexically_relative(root).string() << " contains " << s);
      CHECK(text.find(s) == std::string::npos);
    }
  }
  CHECK(scanned > 100);
}
