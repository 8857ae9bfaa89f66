// SPDX-License-Identifier: MIT
// The data root (data_root.h): where published geometry is found, and where it comes from.
#include "modules/pipeline/data_root.h"

#include <cstdlib>
#include <system_error>

namespace plaf {
inline namespace pipeline {

namespace {

// `--data DIR`, set once by the CLI before any config is read.
std::optional<std::string>& option_root() {
  static std::optional<std::string> root;
  return root;
}

bool regular_file(const std::filesystem::path& p) {
  std::error_code ec;
  return std::filesystem::is_regular_file(p, ec);
}

}  // namespace

void set_data_root_option(const std::filesystem::path& dir) {
  if (dir.empty()) {
    option_root().reset();
    return;
  }
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec))
    throw InputError("--data " + dir.string() + ": not a directory (the data root holds airfoils/ and surfaces/)");
  option_root() = dir.string();
}

std::vector<DataRoot> data_roots() {
  std::vector<DataRoot> roots;
  roots.push_back({"--data", option_root()});
  const char* env = std::getenv("PLAF_DATA");
  roots.push_back({"PLAF_DATA", env && *env ? std::optional<std::string>(env) : std::nullopt});
#ifdef PLAF_SOURCE_DIR
  roots.push_back({"beside the source tree",
                   (std::filesystem::path(PLAF_SOURCE_DIR).parent_path() / "shared" / "data").string()});
#else
  roots.push_back({"beside the source tree", std::nullopt});
#endif
  return roots;
}

std::optional<std::string> find_data_file(const std::string& rel) {
  for (const DataRoot& r : data_roots()) {
    if (!r.dir) continue;
    const std::filesystem::path p = std::filesystem::path(*r.dir) / rel;
    if (regular_file(p)) return p.lexically_normal().string();
  }
  return std::nullopt;
}

// The provenance catalogue: every file of the reference shelf a config, test or benchmark may
// name, with its source. docs/data.md holds the full notes (commits, blobs, measurements);
// tests/modules/pipeline/data_root_test.cpp checks that the two list the same files.
const std::vector<DataCatalogueRow>& data_catalogue() {
  static const std::vector<DataCatalogueRow> rows = {
      {"airfoils/e387.dat", "peterdsharpe/AeroSandbox aerosandbox/geometry/airfoil/airfoil_database/e387.dat (MIT)"},
      {"airfoils/rae2822.dat",
       "peterdsharpe/AeroSandbox aerosandbox/geometry/airfoil/airfoil_database/rae2822.dat (MIT)"},
      {"airfoils/naca0012.dat",
       "peterdsharpe/AeroSandbox aerosandbox/geometry/airfoil/airfoil_database/naca0012.dat (MIT)"},
      {"airfoils/n0012.dat", "peterdsharpe/AeroSandbox aerosandbox/geometry/airfoil/airfoil_database/n0012.dat (MIT)"},
      {"airfoils/naca0012_sharp.dat",
       "smatkovi/pasl naca0012_sharp.dat (no licence stated; data/make_naca0012_sharp.py writes the same file)"},
      {"airfoils/nlr7301.dat",
       "peterdsharpe/AeroSandbox aerosandbox/geometry/airfoil/airfoil_database/nlr7301.dat (MIT)"},
      {"airfoils/30p30n_slat.dat", "linuxguy123/30P-30N-Validation-Case 30P-30N-Slat-raw.dat (GPL-3.0)"},
      {"airfoils/30p30n_main.dat", "linuxguy123/30P-30N-Validation-Case 30P-30N-Main-raw.dat (GPL-3.0)"},
      {"airfoils/30p30n_flap.dat", "linuxguy123/30P-30N-Validation-Case 30P-30N-Flap-raw.dat (GPL-3.0)"},
      {"surfaces/onera_m6_small.fmt", "mdolab/pyhyp examples/m6/m6_small.fmt (Apache-2.0)"},
      {"surfaces/bwb_half.fmt", "mdolab/pyhyp examples/BWB/bwb.fmt (Apache-2.0)"},
      {"surfaces/wing_717_small.fmt", "mdolab/pyhyp examples/wing_717/717_small.fmt (Apache-2.0)"},
      {"surfaces/sphere_cube6_even.fmt", "mdolab/pyhyp examples/sphere/even_sphere.fmt (Apache-2.0)"},
      {"surfaces/sphere_cube6_uneven.fmt", "mdolab/pyhyp examples/sphere/uneven_sphere.fmt (Apache-2.0)"},
      {"surfaces/bullet_projectile_binary.stl", "LontaniN/bulletStability bullet.stl (no licence stated)"},
      {"surfaces/ellipsoid_binary.stl", "Kaweees/fTetWild ellipsoid.stl (MPL-2.0)"},
      {"surfaces/orion_capsule_binary.stl", "rmrsk/EBGeometry Examples/Resources/orion_binary.stl (GPL-3.0-or-later)"},
      {"surfaces/sphere_burkardt_ascii.stl",
       "rmrsk/EBGeometry Examples/Resources/sphere_ascii.stl (GPL-3.0-or-later)"},
      {"surfaces/airfoil_extruded_amrex_ascii.stl",
       "rmrsk/EBGeometry Examples/Resources/airfoil_ascii.stl (GPL-3.0-or-later)"},
      {"surfaces/spot.obj", "alecjacobson/common-3d-test-models data/spot.obj (no licence stated)"},
      {"surfaces/stanford_bunny.obj", "alecjacobson/common-3d-test-models data/stanford-bunny.obj (no licence stated)"},
  };
  return rows;
}

std::optional<std::string> data_provenance(const std::string& rel) {
  const std::string clean = std::filesystem::path(rel).lexically_normal().generic_string();
  for (const DataCatalogueRow& r : data_catalogue())
    if (clean == r.path) return std::string(r.source);
  return std::nullopt;
}

std::string resolve_data_path(const std::string& value, const std::string& where) {
  const std::string rel = value.substr(std::string(kDataPrefix).size());
  const std::filesystem::path p(rel);
  bool escapes = rel.empty() || p.is_absolute();
  for (const auto& part : p.lexically_normal())
    if (part == "..") escapes = true;
  if (escapes)
    throw ConfigError(where + ": '" + value + "': a data path is relative to the data root and stays inside it " +
                      "(e.g. data:airfoils/e387.dat)");
  if (std::optional<std::string> found = find_data_file(rel)) return *found;
  throw MissingDataError(missing_data_message(value, where, data_roots()));
}

std::string missing_data_message(const std::string& value, const std::string& where,
                                 const std::vector<DataRoot>& roots) {
  const std::string rel = value.substr(std::string(kDataPrefix).size());
  std::string tried;
  for (const DataRoot& r : roots) {
    if (!tried.empty()) tried += ", ";
    if (r.dir)
      tried += *r.dir + " (" + r.origin + ")";
    else
      tried += r.origin + " (" + (r.origin == "--data" ? "not given" : "not set") + ")";
  }
  const std::optional<std::string> source = data_provenance(rel);
  return where + ": published file '" + value + "' not found; roots tried: " + tried + "; " +
         (source ? "it comes from " + *source + " (docs/data.md)"
                 : std::string("it is not in plaf's provenance notes (docs/data.md)")) +
         "; point plaf at a folder holding " + rel + " with --data DIR or PLAF_DATA";
}

}  // namespace pipeline
}  // namespace plaf
