// SPDX-License-Identifier: MIT
// plaf — curved high-order hybrid meshes by prismatic layers and advancing fronts.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <exception>
#include <new>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "apps/exit_codes.h"
#include "apps/keys.h"
#include "apps/picture.h"
#include "apps/run.h"
#include "apps/study.h"
#include "modules/base/error.h"
#include "modules/io/atomic_file.h"
#include "modules/pipeline/data_root.h"
#include "modules/pipeline/progress.h"

namespace {

constexpr const char* usage =
    "usage: plaf run CONFIG.yaml [--out DIR] [--data DIR] [--keep-invalid] [--quiet | --progress=json]\n"
    "                                          mesh a configured case into DIR (default: output.dir); a\n"
    "                                          failed run writes its report and picture to DIR/NAME.failed/\n"
    "                                          (its mesh too with --keep-invalid)\n"
    "       plaf check MESH.msh|MESH.cgns [--metric CONFIG.yaml] [--report FILE.json] [--data DIR]\n"
    "                                          re-read a Gmsh MSH 4.1 or 2.2 mesh (ASCII or binary) or a\n"
    "                                          CGNS file and certify its cells; measure\n"
    "                                          its edges in CONFIG's metric; write the JSON report\n"
    "       plaf picture MESH.msh|MESH.cgns [--out FILE.png] [--cut X,Y,Z,NX,NY,NZ] [--at X,Y[,Z],R]...\n"
    "                    [--view X,Y,Z] [--size W,H]\n"
    "                                          draw any mesh as a run draws its own (3D: a cut, its zooms\n"
    "                                          and a shaded view), its cells certified first (invalid red);\n"
    "                                          the first zoom is the worst cell, each --at adds one; default\n"
    "                                          FILE: MESH_STEM.picture.png beside the mesh; exit 2 if invalid\n"
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
    "Progress of run, on stderr: a line as each stage ends, and while a long one runs at most one a second\n"
    "(remesh round k of n, each layer with its row of the layer table, quality's and the fill's share\n"
    "done). --quiet: only errors, and the verdict on stdout; --progress=json: one JSON object per line\n"
    "(docs/outputs.md), --progress=text the default.\n"
    "--data DIR: the data root, where a config's data:REL paths (published geometry) are found; then\n"
    "the environment's PLAF_DATA, then ../shared/data beside the source tree (docs/data.md).\n"
    "Outputs of run: <name>.msh (Gmsh 4.1; binary above 1e5 nodes: output.msh), <name>.vtu (VTK Lagrange\n"
    "cells; output.vtu), <name>.report.json, <name>.png; with msh22 or cgns in output.formats also\n"
    "<name>_msh22.msh (Gmsh 2.2) or <name>.cgns.\n"
    "Exit codes: 0 success, 1 bad input or usage (nothing written), 2 the run failed: invalid or not\n"
    "conforming cells, the boundary layer asked for is not there (layers.min_coverage), or a stage\n"
    "could not finish; its report (and picture, given a mesh) are in DIR/NAME.failed/; 3 a bug in\n"
    "plaf (nothing written; please report it).\n";

// An unexpected exception (exit_code::report_bug): its lines on stderr, or with JSON progress
// one error object holding them.
int bug(const std::string& what, std::optional<plaf::Progress>& progress) {
  if (!progress || progress->mode() != plaf::ProgressMode::Json) return plaf::exit_code::report_bug(std::cerr, what);
  std::ostringstream lines;
  const int code = plaf::exit_code::report_bug(lines, what);
  std::string text = lines.str();
  while (!text.empty() && text.back() == '\n') text.pop_back();
  progress->error(text);
  progress->verdict(false, code, "internal error: " + what);
  return code;
}

int fail_usage(const std::string& why) {
  std::cerr << "plaf: error: " << why << "\n" << usage;
  return plaf::exit_code::bad_input;
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  plaf::install_signal_cleanup();  // SIGINT/SIGTERM remove the temporaries and an incomplete output set
  // A run's progress (--quiet, --progress=json): its errors go there too, so that with JSON every
  // line on stderr is JSON; every other command's are text.
  std::optional<plaf::Progress> progress;
  const auto error = [&](const std::string& what, int code) {
    if (!progress) {
      std::cerr << "plaf: error: " << what << '\n';
      return code;
    }
    progress->error(what);
    progress->verdict(false, code, what);
    return code;
  };
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
      std::optional<plaf::ProgressMode> mode;
      const auto set_mode = [&](plaf::ProgressMode m) {  // false: another one was given
        if (mode && *mode != m) return false;
        mode = m;
        return true;
      };
      for (std::size_t i = 1; i < args.size(); ++i) {
        if (args[i] == "--keep-invalid" && run) {
          keep_invalid = true;
        } else if (run && (args[i] == "--quiet" || args[i] == "-q")) {
          if (!set_mode(plaf::ProgressMode::Quiet)) return fail_usage("--quiet and --progress=json: choose one");
        } else if (run && args[i].rfind("--progress", 0) == 0) {
          const std::string v = args[i] == "--progress" && i + 1 < args.size() ? args[++i]
                                : args[i].rfind("--progress=", 0) == 0 ? args[i].substr(11)
                                                                        : "";
          if (v != "json" && v != "text") return fail_usage("--progress takes json or text, got '" + v + "'");
          if (!set_mode(v == "json" ? plaf::ProgressMode::Json : plaf::ProgressMode::Text))
            return fail_usage("--quiet and --progress=json: choose one");
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
      if (!run) return plaf::compare_attenuation_command(*file, out_dir);
      double interval_s = plaf::Progress::kMinInterval_s;  // (tests: every step, PLAF_PROGRESS_INTERVAL_S=0)
      if (const char* env = std::getenv("PLAF_PROGRESS_INTERVAL_S")) interval_s = std::max(0.0, std::atof(env));
      progress.emplace(mode.value_or(plaf::ProgressMode::Text), std::cerr, plaf::Progress::Clock{}, interval_s);
      return plaf::run_command(*file, out_dir, keep_invalid, &*progress);
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
    if (args[0] == "picture") {
      plaf::PictureRequest pr;
      bool have_mesh = false;
      for (std::size_t i = 1; i < args.size(); ++i) {
        const std::string& a = args[i];
        if (a == "--out" || a == "--cut" || a == "--at" || a == "--view" || a == "--size") {
          if (i + 1 >= args.size()) return fail_usage(a + " needs a value");
          const std::string& v = args[++i];
          if (a == "--out") {
            pr.out = v;
          } else if (a == "--cut") {
            const std::vector<double> x = plaf::parse_numbers(a, v, 6, 6);
            pr.cut = std::array<double, 6>{x[0], x[1], x[2], x[3], x[4], x[5]};
          } else if (a == "--at") {
            pr.zooms.push_back(plaf::parse_numbers(a, v, 3, 4));
          } else if (a == "--view") {
            const std::vector<double> x = plaf::parse_numbers(a, v, 3, 3);
            pr.view = std::array<double, 3>{x[0], x[1], x[2]};
          } else {
            const std::vector<double> x = plaf::parse_numbers(a, v, 2, 2);
            if (!(x[0] >= 64 && x[0] <= 16384 && x[1] >= 64 && x[1] <= 16384) || x[0] != std::floor(x[0]) ||
                x[1] != std::floor(x[1]))
              return fail_usage("--size: '" + v + "': width and height are whole numbers of pixels in 64..16384");
            pr.width = static_cast<int>(x[0]);
            pr.height = static_cast<int>(x[1]);
          }
        } else if (!a.empty() && a[0] == '-') {
          return fail_usage("unknown option '" + a + "'");
        } else if (have_mesh) {
          return fail_usage("picture takes one mesh file, got '" + pr.mesh.string() + "' and '" + a + "'");
        } else {
          pr.mesh = a;
          have_mesh = true;
        }
      }
      if (!have_mesh) return fail_usage("picture needs a mesh file");
      return plaf::picture_command(pr);
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
    return error(e.what(), plaf::exit_code::bad_input);
  } catch (const std::bad_alloc&) {
    // Not a bug: an input or a run larger than this machine's memory (a run's limits: raised too
    // far, a huge mesh to check).
    return error("out of memory (std::bad_alloc): the input or the run is too large for this machine; coarsen the "
                 "metric or lower the limits: section",
                 plaf::exit_code::bad_input);
  } catch (const std::exception& e) {
    return bug(e.what(), progress);
  } catch (...) {
    return bug("an exception of unknown type", progress);
  }
}
