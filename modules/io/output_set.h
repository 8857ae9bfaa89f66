// SPDX-License-Identifier: MIT
// OutputSet: the files of one run as one set. The writers write into a staging folder beside
// the outputs (DIR/.plaf-stage-PID, each file itself through AtomicFile); commit() moves
// them into DIR together. A run that fails before (a full disk, a name too long for the file
// system, any writer's error) leaves none of its files and replaces none of an earlier run's;
// stopped by SIGINT or SIGTERM (install_signal_cleanup, atomic_file.h), neither.
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace plaf {
inline namespace io {

// Before a run's work: creates DIR (if needed) and proves it writable by making and removing a
// staging folder of this process in it (InputError naming DIR when it cannot: an unwritable
// --out was found only after the meshing), and removes the staging folders that processes no
// longer alive left in DIR and in DIR/NAME.failed (a run killed by SIGKILL cannot remove its own).
void prepare_output_dir(const std::filesystem::path& dir, const std::string& name);

class OutputSet {
 public:
  // Creates DIR (if needed) and the staging folder; InputError naming DIR when it cannot.
  OutputSet(std::filesystem::path dir, std::string name);
  // Not committed: removes the staging folder and everything in it.
  ~OutputSet();
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;

  // The base path the writers append their extensions to (in the staging folder).
  std::filesystem::path staged_base() const { return stage_ / name_; }
  // Where the files are once committed: DIR/NAME.
  std::filesystem::path final_base() const { return dir_ / name_; }
  // Moves every staged file into DIR (replacing files of the same name) and removes the staging
  // folder. InputError naming the file when one cannot be moved (the rest stay staged, removed
  // with the folder).
  void commit();
  // NAME + suffix is a file of this set that a run may or may not write (NAME_boundary.vtu):
  // commit removes an earlier run's one that this run did not write.
  void own(const std::string& suffix) { owned_.push_back(suffix); }
  // The same for the files NAME + prefix + <digits> + suffix (NAME.cut1.png, NAME.cut2.png, ...).
  void own_numbered(const std::string& prefix, const std::string& suffix) { owned_numbered_.emplace_back(prefix, suffix); }

 private:
  void remove_stage() noexcept;

  std::filesystem::path dir_;
  std::string name_;
  std::filesystem::path stage_;
  int slot_ = -1;
  bool committed_ = false;
  std::vector<std::string> owned_;
  std::vector<std::pair<std::string, std::string>> owned_numbered_;
};

}  // namespace io
}  // namespace plaf
