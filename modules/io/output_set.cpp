// SPDX-License-Identifier: MIT
#include "modules/io/output_set.h"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "modules/base/error.h"
#include "modules/io/atomic_file.h"

namespace plaf {
inline namespace io {

namespace {

// The staging folders (DIR/.plaf-stage-PID) in `dir` whose process is gone, removed.
void remove_stale_stages(const std::filesystem::path& dir) {
  std::error_code ec;
  const std::string marker = kStagingMarker;
  std::vector<std::filesystem::path> stale;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
    const std::string f = e.path().filename().string();
    if (f.rfind(marker, 0) != 0 || !e.is_directory(ec)) continue;
    const std::string digits = f.substr(marker.size());
    if (digits.empty() || digits.size() > 9 || !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }))
      continue;
    const auto pid = static_cast<pid_t>(std::stol(digits));
    // Alive (or not ours to signal) unless the system says there is no such process.
    if (pid != ::getpid() && ::kill(pid, 0) != 0 && errno == ESRCH) stale.push_back(e.path());
  }
  for (const std::filesystem::path& p : stale) std::filesystem::remove_all(p, ec);
}

}  // namespace

void prepare_output_dir(const std::filesystem::path& dir, const std::string& name) {
  std::error_code ec;
  if (dir.empty()) throw InputError("output.dir '': cannot create the folder (an empty path)");
  std::filesystem::create_directories(dir, ec);
  if (ec) throw InputError("output.dir '" + dir.string() + "': cannot create the folder (" + ec.message() + ")");
  remove_stale_stages(dir);
  if (std::filesystem::is_directory(dir / (name + ".failed"), ec)) remove_stale_stages(dir / (name + ".failed"));
  const std::filesystem::path probe = dir / (kStagingMarker + std::to_string(static_cast<long long>(::getpid())));
  std::filesystem::create_directory(probe, ec);
  if (ec) throw InputError("output.dir '" + dir.string() + "': cannot write in it (" + ec.message() + ")");
  std::filesystem::remove(probe, ec);
}

OutputSet::OutputSet(std::filesystem::path dir, std::string name) : dir_(std::move(dir)), name_(std::move(name)) {
  stage_ = dir_ / (kStagingMarker + std::to_string(static_cast<long long>(::getpid())));
  std::error_code ec;
  if (dir_.empty()) throw InputError("output.dir '': cannot create the folder (an empty path)");
  std::filesystem::create_directories(dir_, ec);
  if (ec) throw InputError("output.dir '" + dir_.string() + "': cannot create the folder (" + ec.message() + ")");
  std::filesystem::remove_all(stage_, ec);  // a leftover of an earlier process of the same id
  std::filesystem::create_directory(stage_, ec);
  if (ec) throw InputError("output.dir '" + dir_.string() + "': cannot create a folder in it (" + ec.message() + ")");
  slot_ = cleanup::add(stage_, true);
}

OutputSet::~OutputSet() {
  if (!committed_) remove_stage();
}

void OutputSet::remove_stage() noexcept {
  std::error_code ignored;
  std::filesystem::remove_all(stage_, ignored);
  cleanup::release_under(stage_);
  cleanup::release(slot_);
}

void OutputSet::commit() {
  std::vector<std::filesystem::path> staged;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(stage_, ec))
    if (e.is_regular_file()) staged.push_back(e.path());
  if (ec) throw InputError(stage_.string() + ": cannot list the staged outputs (" + ec.message() + ")");
  for (const std::filesystem::path& p : staged) {
    std::filesystem::rename(p, dir_ / p.filename(), ec);
    if (ec)
      throw InputError("cannot move " + p.filename().string() + " into output.dir '" + dir_.string() + "' (" +
                       ec.message() + ")");
  }
  // An owned file this run did not write is an earlier run's: it does not belong to the set.
  for (const std::string& suffix : owned_) {
    const std::filesystem::path old = dir_ / (name_ + suffix);
    const bool written = std::any_of(staged.begin(), staged.end(),
                                     [&](const std::filesystem::path& p) { return p.filename() == old.filename(); });
    if (!written) std::filesystem::remove(old, ec);
  }
  // The numbered ones (NAME.cut<k>.png): every k this run did not write.
  for (const auto& [prefix, suffix] : owned_numbered_) {
    const std::string head = name_ + prefix;
    std::vector<std::filesystem::path> present;  // listed first: removing while iterating is unspecified
    for (const std::filesystem::directory_entry& e : std::filesystem::directory_iterator(dir_, ec)) present.push_back(e.path());
    for (const std::filesystem::path& path : present) {
      const std::string f = path.filename().string();
      if (f.size() <= head.size() + suffix.size() || f.compare(0, head.size(), head) != 0 ||
          f.compare(f.size() - suffix.size(), suffix.size(), suffix) != 0)
        continue;
      const std::string k = f.substr(head.size(), f.size() - head.size() - suffix.size());
      if (!std::all_of(k.begin(), k.end(), [](char c) { return c >= '0' && c <= '9'; })) continue;
      const bool written = std::any_of(staged.begin(), staged.end(), [&](const std::filesystem::path& p) { return p.filename() == f; });
      if (!written) std::filesystem::remove(path, ec);
    }
  }
  committed_ = true;
  remove_stage();
}

}  // namespace io
}  // namespace plaf
