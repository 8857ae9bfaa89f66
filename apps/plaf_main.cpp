// SPDX-License-Identifier: MIT
// plaf — curved high-order hybrid meshes by prismatic layers and advancing fronts.
#include <exception>
#include <new>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "apps/exit_codes.h"
#include "apps/keys.h"
#include "apps/run.h"
#include "apps/study.h"
#include "modules/base/error.h"
#include "modules/io/atomic_file.h"
#include "modules/pipeline/data_root.h"

namespace {

constexpr const char* usage =
    "usage: plaf run CONFIG.yaml [--out DIR] [--data DIR] [--keep-invalid]\n"
    "                                          mesh a configured case into DIR (default: output.dir); a\n"
    "                                          failed run writes its report and picture to DIR/NAME.failed/\n"
    "                                          (its mesh too with --keep-invalid)\n"
    "       plaf check MESH.msh [--metric CONFIG.yaml] [--report FILE.json] [--data DIR]\n"
    "                                          re-read a Gmsh MSH 4.1 mesh and certify its cells; measure\n"
    "                                          its edges in CONFIG's metric; write the JSON report\n"
    "       plaf compare-attenuation STUDY.yaml [--out DIR] [--data DIR]\n"
    "                                          run paired 2D and 3D layer cases (a section and its extrusion,\n"
    "                                          a circle and a sphere) over f_atten and h0; write the tables,\n"
    "                                          JSON and charts into DIR (default out/<study name>)\n"
    "       plaf data [REL...] [--data DIR]    where published files are found: the data roots in order,\n"
    "                                          or the path of each data:REL file (exit 1 naming a missing one)\n"
    "       plaf plugins                        list the registered type of every stage (geometry, metric,\n"
    "                                          surface, layers, fill) and the output formats\n"
    "       plaf keys [SECTION] [--markdown]   every configuration key: type, default, range or choices,\n"
    "                                          the types that read it, what it does (docs/config.md)\n"
    "       plaf --help | --version\n"
    "--data DIR: the data root, where a config's data:REL paths (published geometry) are found; then\n"
    "the environment's PLAF_DATA, then ../shared/data beside the source tree (docs/data.md).\n"
    "Outputs of run: <name>.msh (Gmsh 4.1), <name>.vtu (VTK Lagrange cells), <name>.report.json, <name>.png.\n"
    "Exit codes: 0 success, 1 bad input or usage (nothing written), 2 the run failed: invalid or not\n"
    "conforming cells, the boundary layer asked for is not there (layers.min_coverage), or a stage\n"
    "could not finish; its report (and picture, given a mesh) are in DIR/NAME.failed/; 3 a bug in\n"
    "plaf (nothing written; please report it).\n";

int fail_usage(const std::string& why) {
  std::cerr << "plaf: error: " << why << "\n" << usage;
  return plaf::exit_code::bad_input;
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  plaf::install_signal_cleanup();  // SIGINT/SIGTERM remove the temporaries and an incomplete output set
  try {
    if (args.empty()) return fail_usage("no command given");
    if (args[0] == "--help" || args[0] == "-h") {
      std::cout << usage;
      return 0;
    }
    if (args[0] == "--version") {
      std::cout << "plaf " << PLAF_VERSION << '\n';
      return 0;
    }
    if (args[0] == "run" || args[0] == "compare-attenuation") {
      // One file (a run config or a study) and an optional --out folder.
      const bool run = args[0] == "run";
      const std::string what = run ? "config file" : "study file";
      std::optional<std::string> file, out;
      bool keep_invalid = false;
      for (std::size_t i = 1; i < args.size(); ++i) {
        if (args[i] == "--keep-invalid" && run) {
          keep_invalid = true;
        } else if (args[i] == "--out") {
          if (i + 1 >= args.size()) return fail_usage("--out needs a directory");
          out = args[++i];
        } else if (args[i] == "--data") {
          if (i + 1 >= args.size()) return fail_usage("--data needs a directory");
          plaf::set_data_root_option(args[++i]);
        } else if (!args[i].empty() && args[i][0] == '-') {
          return fail_usage("unknown option '" + args[i] + "'");
        } else if (file) {
          return fail_usage(args[0] + " takes one " + what + ", got '" + *file + "' and '" + args[i] + "'");
        } else {
          file = args[i];
        }
      }
      if (!file) return fail_usage(args[0] + " needs a " + what);
      std::optional<std::filesystem::path> out_dir;
      if (out) out_dir = *out;
      return run ? plaf::run_command(*file, out_dir, keep_invalid) : plaf::compare_attenuation_command(*file, out_dir);
    }
    if (args[0] == "data") {
      std::vector<std::string> files;
      for (std::size_t i = 1; i < args.size(); ++i) {
        if (args[i] == "--data") {
          if (i + 1 >= args.size()) return fail_usage("--data needs a directory");
          plaf::set_data_root_option(args[++i]);
        } else if (!args[i].empty() && args[i][0] == '-') {
          return fail_usage("unknown option '" + args[i] + "'");
        } else {
          files.push_back(args[i]);
        }
      }
      return plaf::data_command(files);
    }
    if (args[0] == "plugins") {
      if (args.size() > 1) return fail_usage("plugins takes no argument");
      return plaf::plugins_command();
    }
    if (args[0] == "keys") {
      std::optional<std::string> section;
      bool markdown = false, probes = false;
      for (std::size_t i = 1; i < args.size(); ++i) {
        if (args[i] == "--markdown") {
          markdown = true;
        } else if (args[i] == "--probes") {  // for tests/apps/keys_test.cpp (keys.h)
          probes = true;
        } else if (!args[i].empty() && args[i][0] == '-') {
          return fail_usage("unknown option '" + args[i] + "'");
        } else if (section) {
          return fail_usage("keys takes one section, got '" + *section + "' and '" + args[i] + "'");
        } else {
          section = args[i];
        }
      }
      if (markdown && section)
        return fail_usage("keys --markdown prints the whole reference (docs/config.md), not one section");
      if (probes) {
        if (markdown || section) return fail_usage("keys --probes takes no other argument");
        plaf::register_all_plugins();
        std::cout << plaf::key_probes_yaml();
        return 0;
      }
      return plaf::keys_command(section, markdown);
    }
    if (args[0] == "check") {
      std::optional<std::string> mesh, metric, report;
      for (std::size_t i = 1; i < args.size(); ++i) {
        if (args[i] == "--metric" || args[i] == "--report") {
          if (i + 1 >= args.size()) return fail_usage(args[i] + " needs a file");
          (args[i] == "--metric" ? metric : report) = args[i + 1];
          ++i;
        } else if (args[i] == "--data") {
          if (i + 1 >= args.size()) return fail_usage("--data needs a directory");
          plaf::set_data_root_option(args[++i]);
        } else if (!args[i].empty() && args[i][0] == '-') {
          return fail_usage("unknown option '" + args[i] + "'");
        } else if (mesh) {
          return fail_usage("check takes one mesh file, got '" + *mesh + "' and '" + args[i] + "'");
        } else {
          mesh = args[i];
        }
      }
      if (!mesh) return fail_usage("check needs a mesh file");
      std::optional<std::filesystem::path> metric_path, report_path;
      if (metric) metric_path = *metric;
      if (report) report_path = *report;
      return plaf::check_command(*mesh, metric_path, report_path);
    }
    return fail_usage("unknown command '" + args[0] + "'");
  } catch (const plaf::Error& e) {
    std::cerr << "plaf: error: " << e.what() << '\n';
    return plaf::exit_code::bad_input;
  } catch (const std::bad_alloc&) {
    // Not a bug: an input or a run larger than this machine's memory (a run's limits: raised too
    // far, a huge mesh to check).
    std::cerr << "plaf: error: out of memory (std::bad_alloc): the input or the run is too large for this "
                 "machine; coarsen the metric or lower the limits: section\n";
    return plaf::exit_code::bad_input;
  } catch (const std::exception& e) {
    return plaf::exit_code::report_bug(std::cerr, e.what());
  } catch (...) {
    return plaf::exit_code::report_bug(std::cerr, "an exception of unknown type");
  }
}
