// SPDX-License-Identifier: MIT
// Published geometry (airfoil contours and surfaces from other projects) is not part of plaf's
// repository: a configuration names such a file relative to a *data root*, as `data:REL`
// (e.g. `file: data:airfoils/e387.dat`). Every path key of every section takes this form
// (ConfigNode::get_path), and the same rule finds the file everywhere:
//
//   1. the folder given by `--data DIR` on the command line (set_data_root_option),
//   2. the folder in the environment variable PLAF_DATA,
//   3. `../shared/data` beside the source tree plaf was built from (the reference shelf).
//
// The first root holding the file wins. A file found in none of them is an InputError of one line
// naming the key, the file, every root tried and where the file comes from (its row of the
// provenance catalogue below, which mirrors docs/data.md). Plain relative paths stay relative to
// the config file, as before.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "modules/base/error.h"

namespace plaf {
inline namespace pipeline {

// The prefix that marks a path relative to the data root.
inline constexpr const char* kDataPrefix = "data:";

// A published file was not found in any data root (an InputError: exit code 1). Tests and the
// shipped-config runners tell it from other input errors to report a run as skipped.
class MissingDataError : public InputError {
 public:
  using InputError::InputError;
};

// One place a data root may come from, in the order tried.
struct DataRoot {
  std::string origin;              // "--data", "PLAF_DATA" or "beside the source tree"
  std::optional<std::string> dir;  // nothing when not given / not set
};

// `--data DIR` (an empty path clears it). Throws InputError when DIR is not a directory.
void set_data_root_option(const std::filesystem::path& dir);

// The three roots in the order they are tried.
std::vector<DataRoot> data_roots();

// The file `rel` (e.g. "airfoils/e387.dat") in the first root holding it, or nothing.
std::optional<std::string> find_data_file(const std::string& rel);

// Where a published file comes from: "SOURCE, LICENCE" from the catalogue, or nothing for a file
// the catalogue does not list.
std::optional<std::string> data_provenance(const std::string& rel);

// The rows of the catalogue: (relative path, "owner/repo path, licence").
struct DataCatalogueRow {
  const char* path;
  const char* source;
};
const std::vector<DataCatalogueRow>& data_catalogue();

// `value` as written in a config ("data:REL"): REL checked (relative, no "..") and found, else
// MissingDataError "WHERE: published file 'data:REL' not found; tried ...; it comes from ...".
// `where` is the key's "file:line:col: key" prefix.
std::string resolve_data_path(const std::string& value, const std::string& where);

// The one line of a MissingDataError for `value` ("data:REL") and the roots that were tried.
std::string missing_data_message(const std::string& value, const std::string& where,
                                 const std::vector<DataRoot>& roots);

}  // namespace pipeline
}  // namespace plaf
