// SPDX-License-Identifier: MIT
// End-to-end tests of the plaf CLI: runs the built binary on configs, good and bad.
#include <doctest/doctest.h>
#include <sys/wait.h>

#include <csignal>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <sstream>
#include <vector>

#include "apps/exit_codes.h"
#include "modules/io/msh_io.h"
#include "tests/test_support.h"
#include "tests/published_data.h"

namespace fs = std::filesystem;
using plaf::test::count_files;
using plaf::test::PlafResult;
using plaf::test::read_text;
using plaf::test::run_plaf;
using plaf::test::TempDir;
using plaf::test::write_text;

namespace {

std::string replace_all(std::string s, const std::string& from, const std::string& to) {
  for (std::size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size())) s.replace(at, from.size(), to);
  return s;
}

const std::string good = "order: 2\ngeometry: {type: annulus, angle_deg: 90}\nmetric: {type: uniform, h: 0.4}\n";

}  // namespace

TEST_CASE("cli: run writes msh, vtu, report and png, check re-reads the msh and certifies it") {
  const TempDir d("cli_run");
  const fs::path cfg = write_text(d / "case.yaml", good);
  const PlafResult r = run_plaf("run " + cfg.string() + " --out " + (d / "out").string(), d);
  CHECK(r.code == 0);
  for (const char* ext : {".msh", ".vtu", "_boundary.vtu", ".report.json", ".png"})
    CHECK(fs::file_size(d / "out" / (std::string("case") + ext)) > 0);
  CHECK(count_files(d / "out") == 5);  // no temporaries left behind
  CHECK(read_text(d / "out" / "case.report.json").find("\"invalid\": 0") != std::string::npos);
  CHECK(run_plaf("check " + (d / "out" / "case.msh").string(), d).code == 0);
}

TEST_CASE("cli: check measures another mesh in a config's metric and writes its report") {
  const TempDir d("cli_check_metric");
  const fs::path cfg = write_text(d / "case.yaml", good);
  REQUIRE(run_plaf("run " + cfg.string() + " --out " + (d / "out").string(), d).code == 0);
  // The same metric gives the same unit fraction as the run's own report; a 4x larger size in
  // the metric makes every edge about 1/4 unit long, so none is in [1/sqrt 2, sqrt 2].
  const fs::path coarse = write_text(d / "coarse.yaml", "metric: {type: uniform, h: 1.6}\n");
  CHECK(run_plaf("check " + (d / "out" / "case.msh").string() + " --metric " + cfg.string() + " --report " +
                     (d / "same.json").string(),
                 d)
            .code == 0);
  CHECK(run_plaf("check " + (d / "out" / "case.msh").string() + " --report " + (d / "coarse.json").string() +
                     " --metric " + coarse.string(),
                 d)
            .code == 0);
  const std::string run_report = read_text(d / "out" / "case.report.json");
  const std::string same = read_text(d / "same.json");
  const auto unit_fraction = [](const std::string& json) {
    const std::size_t k = json.find("\"unit_fraction\": ");
    REQUIRE(k != std::string::npos);
    return std::stod(json.substr(k + 17));
  };
  CHECK(unit_fraction(same) == doctest::Approx(unit_fraction(run_report)));
  CHECK(unit_fraction(same) > 0.5);
  CHECK(unit_fraction(read_text(d / "coarse.json")) == 0.0);
  const PlafResult bad = run_plaf("check " + (d / "out" / "case.msh").string() + " --metric " + (d / "no.yaml").string(), d);
  CHECK(bad.code == 1);
  CHECK(bad.err.find("no.yaml") != std::string::npos);
  CHECK(run_plaf("check " + (d / "out" / "case.msh").string() + " --metric", d).code == 1);
}

TEST_CASE("cli: bad inputs give one clear error line, exit code 1 and no output files") {
  struct Case {
    const char* name;
    std::string config;  // empty: the config file does not exist
    const char* message;
  };
  const Case cases[] = {
      {"missing file", "", "cannot open the config file"},
      {"unknown key", good + "colour: red\n", "unknown key 'colour'"},
      {"unknown nested key", "order: 2\nmetric: {type: uniform, hh: 0.4}\n", "unknown key 'metric.hh'"},
      {"negative order", "order: -2\n", "order: -2 is outside 1..4"},
      {"order 7", "order: 7\n", "order: 7 is outside 1..4"},
      {"negative size", "metric: {type: uniform, h: -0.1}\n", "metric.h: must be positive, got -0.1"},
      {"unknown metric", "metric: {type: magic}\n",
       "unknown 2D metric type 'magic' (known: background, uniform, wall_power_law)"},
      {"wrong type", "order: three\n", "order: expected an integer, got 'three'"},
      {"yaml syntax", "order: [3\n", "YAML syntax error"},
      {"radii", "geometry: {type: annulus, r_inner: 2, r_outer: 1}\n", "geometry.r_outer: must be larger than r_inner"},
      {"fill of an annulus", good + "fill: {}\n", "the fill needs a spline geometry"},
      {"unknown fill key", good + "fill: {speed: 3}\n", "unknown key 'fill.speed'"},
      {"fill max_triangles", good + "fill: {max_triangles: 0}\n", "fill.max_triangles: 0 is outside"},
  };
  for (const Case& c : cases) {
    INFO(std::string(c.name));
    const TempDir d("cli_bad");
    const fs::path cfg = c.config.empty() ? d / "nope.yaml" : write_text(d / "case.yaml", c.config);
    const PlafResult r = run_plaf("run " + cfg.string() + " --out " + (d / "out").string(), d);
    CHECK(r.code == 1);
    CHECK(r.err.find(c.message) != std::string::npos);
    CHECK(r.err.find(cfg.string()) != std::string::npos);      // names the file
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);  // one line
    CHECK(count_files(d / "out") == 0);
  }
}

TEST_CASE("cli: usage errors, --help and --version") {
  const TempDir d("cli_usage");
  CHECK(run_plaf("--help", d).code == 0);
  CHECK(run_plaf("--version", d).code == 0);
  CHECK(run_plaf("", d).code == 1);
  CHECK(run_plaf("frobnicate", d).code == 1);
  CHECK(run_plaf("run", d).code == 1);
  const PlafResult bad_mesh =
      run_plaf("check " + write_text(d / "bad.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n").string(), d);
  CHECK(bad_mesh.code == 1);
  CHECK(bad_mesh.err.find("bad.msh") != std::string::npos);
}

TEST_CASE("cli: exit codes are the documented four, and a bug (code 3) asks for a report") {
  std::ostringstream err;
  CHECK(plaf::exit_code::report_bug(err, "vector::_M_range_check") == 3);
  const std::string text = err.str();
  CHECK(text.rfind("plaf: internal error: vector::_M_range_check\n", 0) == 0);
  CHECK(text.find("please report it") != std::string::npos);
  CHECK(std::count(text.begin(), text.end(), '\n') == 2);
  // --help states all four.
  const TempDir d("cli_exit_codes");
  REQUIRE(std::system((std::string(PLAF_EXE) + " --help > " + (d / "help.txt").string()).c_str()) == 0);
  const std::string usage = read_text(d / "help.txt");
  for (const char* code : {"0 success", "1 bad input", "2 the run failed", "3 a bug"})
    CHECK_MESSAGE(usage.find(code) != std::string::npos, code);
}

TEST_CASE("cli: a fill without layers meshes from the surface front, and layers and fill of type none are accepted") {
  const TempDir d("cli_fill_only");
  const std::string airfoil = std::string("order: 1\ngeometry:\n  type: airfoils\n  bodies: [{naca: {digits: \"0012\", trailing_edge: blunt}}]\n") +
                              "  farfield: {radius: 3}\nmetric: {type: uniform, h: 0.3}\n";
  for (const std::string& extra : {std::string("fill: {}\n"), std::string("layers: {type: none}\nfill: {}\n")}) {
    INFO(extra);
    const fs::path cfg = write_text(d / "fill.yaml", airfoil + extra);
    const PlafResult r = run_plaf("run " + cfg.string() + " --out " + (d / "out").string(), d);
    CHECK(r.code == 0);
    const std::string report = read_text(d / "out" / "fill.report.json");
    CHECK(report.find("\"triangle_Q1\"") != std::string::npos);
    CHECK(report.find("\"steps\"") != std::string::npos);  // the fill's section
  }
  const fs::path none = write_text(d / "none.yaml", good + "layers: {type: none}\nfill: {type: none}\n");
  CHECK(run_plaf("run " + none.string() + " --out " + (d / "out2").string(), d).code == 0);
  const fs::path sphere = write_text(d / "sphere.yaml", "geometry: {type: sphere}\nmetric: {type: uniform, h: 0.5}\n"
                                                        "layers: {type: none}\nfill: {type: none}\n");
  CHECK(run_plaf("run " + sphere.string() + " --out " + (d / "out3").string(), d).code == 0);
}

TEST_CASE("cli: an output folder that cannot be made is exit code 1 with one line naming it") {
  const TempDir d("cli_out_dir");
  const fs::path cfg = write_text(d / "case.yaml", good);
  write_text(d / "afile", "x");
  const PlafResult r = run_plaf("run " + cfg.string() + " --out " + (d / "afile" / "sub").string(), d);
  CHECK(r.code == 1);
  CHECK(r.err.find("output.dir '" + (d / "afile" / "sub").string() + "': cannot create the folder") !=
        std::string::npos);
}

TEST_CASE("cli: check --metric refuses a configuration of the other dimension, and --out '' is an output.dir error") {
  const TempDir d("cli_check_3d");
  const fs::path cfg = write_text(d / "case.yaml", good);
  REQUIRE(run_plaf("run " + cfg.string() + " --out " + (d / "out").string(), d).code == 0);
  const fs::path sphere = write_text(d / "sphere.yaml", "geometry: {type: sphere}\nmetric: {type: uniform, h: 0.5}\n");
  const PlafResult r = run_plaf("check " + (d / "out" / "case.msh").string() + " --metric " + sphere.string(), d);
  CHECK(r.code == 1);
  CHECK(r.err.find((d / "out" / "case.msh").string() + ": a 2D mesh measured in the metric of a 3D configuration (" +
                   sphere.string() + ")") != std::string::npos);
  const PlafResult empty = run_plaf("run " + cfg.string() + " --out ''", d);
  CHECK(empty.code == 1);
  CHECK(empty.err.find("output.dir '': cannot create the folder") != std::string::npos);
}

TEST_CASE("cli: a mesher failure on valid keys fails the run (exit 2), naming the config and the keys most likely to help, with its report") {
  PLAF_NEEDS_PUBLISHED("airfoils/e387.dat");
  // The E387's sharp trailing edge without a fan (corner angle 179) and a first layer of 5e-7 c:
  // no first layer can be grown there.
  const TempDir d("cli_mesher_hint");
  const fs::path cfg = write_text(d / "nofan.yaml",
                                  "order: 3\n"
                                  "geometry: {type: airfoils, bodies: [{file: data:airfoils/e387.dat}], corner_angle_deg: 179}\n"
                                  "metric: {type: wall_power_law, h0: 5.0e-7, growth: 1.2, h_max: 10, h_wall_max: 0.05, "
                                  "curvature_factor: 0.04, h_corner: 0.01}\n"
                                  "layers: {max: 1, corner_angle_deg: 179}\n");
  const PlafResult r = run_plaf("run " + cfg.string() + " --out " + (d / "out").string(), d);
  INFO(r.err);
  // The run failed (exit 2), as for an invalid mesh: the error with its hint, then where its
  // report is; no mesh, and nothing beside a valid run's outputs.
  CHECK(r.code == 2);
  CHECK(r.err.find("plaf: error: " + cfg.string() + ": layers: not even the first layer could be grown") != std::string::npos);
  CHECK(r.err.find("metric.h0") != std::string::npos);
  CHECK(r.err.find("layers.corner_angle_deg") != std::string::npos);
  CHECK(r.err.find("the run FAILED before it had a mesh; its report is in " + (d / "out" / "nofan.failed").string()) !=
        std::string::npos);
  std::size_t errors = 0;  // two error lines (the progress lines are "[plaf] ...")
  for (std::size_t at = r.err.find("plaf: error"); at != std::string::npos; at = r.err.find("plaf: error", at + 1)) ++errors;
  CHECK(errors == 2);
  CHECK(count_files(d / "out") == 1);
  const std::string report = read_text(d / "out" / "nofan.failed" / "nofan.report.json");
  CHECK(report.find("\"ok\": false") != std::string::npos);
  CHECK(report.find("\"exit_code\": 2,\n  \"failures\": [\"layers: not even the first layer could be grown") != std::string::npos);
  CHECK(report.find("\"error\": \"layers: not even the first layer could be grown") != std::string::npos);
  CHECK(report.find("\"hint\": \"try a thinner first layer") != std::string::npos);
  // The stages that ran are in it (issue 37, item 7: messages pointing to the report's sections
  // pointed to a report that held only the error): the surface's curve elements here.
  CHECK(report.find("\"surface\": {") != std::string::npos);
  CHECK(report.find("\"cells\": {\n    \"total\": 0,") != std::string::npos);
}

TEST_CASE("cli: a key found wrong once the mesh exists (a farfield inside the layers) names the config and the key") {
  const TempDir d("cli_farfield");
  const fs::path cfg = write_text(d / "tight.yaml",
                                  "order: 2\ngeometry: {type: sphere, center: [0, 0, 0], radius: 1}\n"
                                  "metric: {type: wall_power_law, h0: 0.01, growth: 1.3, h_max: 5.0, h_wall_max: 0.5}\n"
                                  "layers: {type: extrude, max: 3}\n"
                                  "fill: {type: tetgen, farfield: {shape: sphere, radius: 1.01}}\n");
  const PlafResult r = run_plaf("run " + cfg.string() + " --out " + (d / "out").string(), d);
  INFO(r.err);
  CHECK(r.code == 1);
  CHECK(r.err.find("plaf: error: " + cfg.string() + ": fill.farfield.radius: 1.01 does not enclose the bodies") !=
        std::string::npos);
  CHECK(count_files(d / "out") == 0);
}

TEST_CASE("cli: a run beyond its size budget stops before meshing, naming the estimate and the limits key to raise") {
  const TempDir d("cli_budget");
  struct Case {
    const char* name;
    std::string yaml;
    const char* message;
  };
  const std::string naca = "{naca: \"0012\"}";
  const std::vector<Case> cases = {
      // Issue 17's probe: each ran for minutes into gigabytes before.
      {"annulus_q4", "order: 4\ngeometry: {type: annulus, angle_deg: 360}\nmetric: {type: uniform, h: 9.0e-4}\n",
       "limits.nodes: the annulus' order-4 cells would make about 1.9e+08 (budget 6e+07); coarsen the metric or raise limits.nodes"},
      {"airfoil_fine", "geometry: {type: airfoils, bodies: [" + naca + "]}\nmetric: {type: uniform, h: 3.0e-6}\n",
       "limits.surface_elements: the curves of the bodies and the farfield would make about 4.3e+07"},
      {"fill_fine",
       "geometry: {type: airfoils, bodies: [" + naca + "]}\n"
       "metric: {type: wall_power_law, h0: 1.0e-4, growth: 1.2, h_max: 1.0e-3, h_wall_max: 1.0e-3}\n"
       "layers: {max: 20}\nfill: {type: advancing_front}\n",
       "limits.cells: the domain's cells would make about"},
      {"sphere_fine", "order: 2\ngeometry: {type: sphere, center: [0, 0, 0], radius: 0.5}\nmetric: {type: uniform, h: 2.0e-3}\n",
       "limits.surface_elements: the surface's triangles would make about 1.8e+06 (budget 500000)"},
      {"layers_high",
       "order: 2\ngeometry: {type: sphere, center: [0, 0, 0], radius: 1}\n"
       "metric: {type: wall_power_law, h0: 0.01, growth: 1.3, h_max: 5.0, h_wall_max: 0.5}\n"
       "layers: {type: extrude, max: 3}\nlimits: {cells: 100}\n",
       "limits.cells: up to 3 layers (layers.max) on"},
      {"tets_many",
       "order: 2\ngeometry: {type: sphere, center: [0, 0, 0], radius: 1}\n"
       "metric: {type: wall_power_law, h0: 0.01, growth: 1.3, h_max: 5.0, h_wall_max: 0.5}\n"
       "layers: {type: extrude, max: 3}\nfill: {type: tetgen, farfield: {shape: sphere, radius: 5}}\n"
       "limits: {cells: 2000}\n",
       "limits.cells: the layers' 320 cells and the fill's tetrahedra would make about"},
  };
  for (const Case& c : cases) {
    INFO(c.name);
    const fs::path cfg = write_text(d / (std::string(c.name) + ".yaml"), c.yaml);
    const fs::path out = d / (std::string("out_") + c.name);
    const PlafResult r = run_plaf("run " + cfg.string() + " --out " + out.string(), d);
    INFO(r.err);
    CHECK(r.code == 1);
    CHECK(r.err.find("plaf: error: " + cfg.string() + ": " + c.message) != std::string::npos);
    CHECK(count_files(out) == 0);
  }
  // The key raised, the layered sphere runs.
  const fs::path raised =
      write_text(d / "raised.yaml", replace_all(cases[4].yaml, "limits: {cells: 100}", "limits: {cells: 1.0e+4}"));
  CHECK(run_plaf("run " + raised.string() + " --out " + (d / "out_raised").string(), d).code == 0);
  // The keys themselves are checked like any other.
  for (const char* bad : {"limits: {cells: -1}\n", "limits: {memory_gb: 8}\n", "limits: {nodes: [1]}\n"}) {
    const fs::path cfg = write_text(d / "bad_limits.yaml", good + bad);
    const PlafResult r = run_plaf("run " + cfg.string() + " --out " + (d / "out_bad").string(), d);
    INFO(bad, r.err);
    CHECK(r.code == 1);
    CHECK(r.err.find("limits") != std::string::npos);
    CHECK(count_files(d / "out_bad") == 0);
  }
}

TEST_CASE("cli: output.cuts writes a picture per plane, and a rerun with fewer leaves none of the earlier run's") {
  const TempDir d("cli_cuts");
  const std::string sphere = "name: s\norder: 2\ngeometry: {type: sphere}\nmetric: {type: uniform, h: 0.5}\n";
  const std::string two = "output: {formats: [report, png], cuts: [{point: [0, 0, 0], normal: [1, 0, 0], radius: 0.3, "
                          "label: x = 0}, {point: [0, 0, 0.5], normal: [0, 0, 1]}]}\n";
  const fs::path a = write_text(d / "a.yaml", sphere + two);
  REQUIRE(run_plaf("run " + a.string() + " --out " + (d / "out").string(), d).code == 0);
  CHECK(fs::is_regular_file(d / "out" / "s.png"));
  CHECK(fs::is_regular_file(d / "out" / "s.cut1.png"));
  CHECK(fs::is_regular_file(d / "out" / "s.cut2.png"));
  const fs::path b = write_text(d / "b.yaml", sphere + "output: {formats: [report, png], cuts: [{point: [0, 0, 0], normal: [0, 1, 0]}]}\n");
  REQUIRE(run_plaf("run " + b.string() + " --out " + (d / "out").string(), d).code == 0);
  CHECK(fs::is_regular_file(d / "out" / "s.cut1.png"));
  CHECK_FALSE(fs::exists(d / "out" / "s.cut2.png"));
  CHECK(count_files(d / "out") == 3);  // s.report.json, s.png, s.cut1.png
  // Cuts without png among the formats: refused, naming the key.
  const fs::path c = write_text(d / "c.yaml", sphere + "output: {formats: [report], cuts: [{point: [0, 0, 0], normal: [0, 1, 0]}]}\n");
  const PlafResult r = run_plaf("run " + c.string() + " --out " + (d / "out2").string(), d);
  CHECK(r.code == 1);
  CHECK(r.err.find("output.cuts: the cut pictures are PNG files: add png to output.formats") != std::string::npos);
}

TEST_CASE("cli: the outputs are one set: a writer that fails half-way, or a stop signal, leaves none of them") {
  const TempDir d("cli_output_set");
  // A name the file system takes for the .msh and .vtu but not with the boundary file's longer
  // suffix: refused with the config, before any work (it once failed after two files were
  // written; a writer failing half-way is output_set_test's).
  const std::string name(243, 'n');
  const fs::path cfg = write_text(d / "long.yaml", "name: " + name + "\n" + good);
  const PlafResult r = run_plaf("run " + cfg.string() + " --out " + (d / "out").string(), d);
  INFO(r.err);
  CHECK(r.code == 1);
  CHECK(r.err.find("name: must be a plain file name") != std::string::npos);
  CHECK(count_files(d / "out") == 0);
  // An earlier run's files are replaced only by a complete set.
  const fs::path ok = write_text(d / "ok.yaml", "name: kept\n" + good);
  REQUIRE(run_plaf("run " + ok.string() + " --out " + (d / "out").string(), d).code == 0);
  CHECK(count_files(d / "out") == 5);
  // A run of the same name that writes no boundary file (a 2D surface: lines alone) does not
  // leave the earlier run's one beside its own files.
  const fs::path lines = write_text(d / "lines.yaml", "name: kept\norder: 2\ngeometry: {type: airfoils, bodies: [{naca: \"0012\"}]}\n"
                                                      "metric: {type: uniform, h: 0.2}\n");
  REQUIRE(run_plaf("run " + lines.string() + " --out " + (d / "out").string(), d).code == 0);
  CHECK_FALSE(fs::exists(d / "out" / "kept_boundary.vtu"));
  CHECK(count_files(d / "out") == 4);
  // SIGTERM while the outputs are written: the run (a 360-degree order-4 annulus, some 170 MB of
  // files) is stopped as soon as its progress says the quality stage is done, i.e. while the
  // writers run; the folder then holds nothing, never a temporary or the staging folder. Run
  // twice, and once more stopped later (after the first files are staged).
  const fs::path big = write_text(d / "big.yaml", "name: big\norder: 4\ngeometry: {type: annulus, angle_deg: 360}\n"
                                                  "metric: {type: uniform, h: 0.012}\n");
  int round = 0;
  for (const char* extra : {"0", "0", "0.3"}) {
    const fs::path out = d / ("killed_" + std::to_string(round));
    // A file of its own per round: with one shared file, a loaded machine let the loop below find
    // the previous round's "quality:" before the new run had truncated it, and the stop came
    // before the run had begun.
    const fs::path err = d / ("killed_" + std::to_string(round++) + ".err");
    const std::string cmd = "sh -c '" + std::string(PLAF_EXE) + " run " + big.string() + " --out " + out.string() +
                            " > /dev/null 2> " + err.string() + " & p=$!; i=0; while ! grep -q \"quality:\" " +
                            err.string() + " && [ $i -lt 20000 ]; do sleep 0.01; i=$((i+1)); done; sleep " + extra +
                            "; kill -TERM $p; wait $p; exit $?'";
    const int status = std::system(cmd.c_str());
    const std::string log = read_text(err);
    const std::string when = extra;  // INFO captures by reference: named, not a temporary
    INFO("stopped " << when << " s after the quality stage, exit status " << status << "\n" << log);
    REQUIRE(log.find("quality:") != std::string::npos);  // the stop came in the output phase
    CHECK(WIFEXITED(status));
    CHECK(WEXITSTATUS(status) == 128 + SIGTERM);  // stopped by the signal, not finished
    CHECK(log.find("[plaf] write:") == std::string::npos);
    // Stopped before the writers made the folder (a loaded machine), or after: nothing is left.
    CHECK((!fs::exists(out) || fs::is_empty(out)));
  }
}

TEST_CASE("cli: check --metric measures a 3D mesh's tetrahedra in a 3D configuration's metric, as the run did") {
  // Another tool's mesh (bench/bench_volume.py: Gmsh's) is measured so; here plaf's own, whose
  // run measured it too.
  const TempDir d("cli_check_metric_3d");
  const fs::path cfg = write_text(
      d / "case.yaml",
      "name: case\norder: 2\ngeometry: {type: sphere, center: [0, 0, 0], radius: 1}\n"
      "metric: {type: wall_power_law, h0: 0.001, growth: 1.3, h_max: 2.0, h_wall_max: 0.3}\n"
      "layers: {max: 6}\nfill: {type: tetgen, farfield: {shape: box, size: [8, 8, 8]}}\n");
  REQUIRE(run_plaf("run " + cfg.string() + " --out " + (d / "out").string(), d).code == 0);
  const PlafResult r = run_plaf("check " + (d / "out" / "case.msh").string() + " --metric " + cfg.string() + " --report " +
                                    (d / "check.json").string(),
                                d);
  INFO(r.err);
  REQUIRE(r.code == 0);
  const std::string ran = plaf::test::read_text(d / "out" / "case.report.json");
  const std::string checked = plaf::test::read_text(d / "check.json");
  const double run_unit = plaf::test::report_value(ran, {"metric", "tetrahedra", "unit_fraction"});
  const double check_unit = plaf::test::report_value(checked, {"metric", "tetrahedra", "unit_fraction"});
  MESSAGE("tetrahedra's unit edges: run " << run_unit << ", check " << check_unit);
  CHECK(run_unit > 0.5);
  CHECK(check_unit == doctest::Approx(run_unit).epsilon(1e-6));
}

TEST_CASE("cli: picture draws a run's mesh and another one, the worst cell first, and exit 2 on an invalid mesh") {
  const TempDir d("cli_picture");
  const fs::path cfg = write_text(d / "case.yaml", good);
  REQUIRE(run_plaf("run " + cfg.string() + " --out " + (d / "out").string(), d).code == 0);
  // 2D, default name beside the mesh; the summary and the worst cell on stdout.
  const plaf::test::PlafOutput r = plaf::test::run_plaf_output("picture " + (d / "out" / "case.msh").string() + " --at 0.5,0.5,0.1", d);
  CHECK(r.code == 0);
  CHECK(r.out.find("worst cell, scaled Jacobian") != std::string::npos);
  CHECK(r.out.find("invalid cells: 0") != std::string::npos);
  const std::string png = read_text(d / "out" / "case.picture.png");
  REQUIRE(png.size() > 8);
  CHECK(png.substr(1, 3) == "PNG");
  // 3D: one inverted linear tetrahedron (its fourth node below the first three's plane), written
  // by the MSH writer as another tool's file would be: drawn, and the verdict is exit 2.
  plaf::HybridMesh<3> m;
  m.nodes = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, -1}};
  m.cells.push_back({plaf::CellType::Tetrahedron, 1, -1, {0, 1, 2, 3}});
  plaf::write_msh41(m, d / "bad.msh");
  const PlafResult bad = run_plaf("picture " + (d / "bad.msh").string() + " --out " + (d / "bad.png").string() +
                                      " --cut 0,0,0,0,0,1 --view 1,1,1 --size 320,240 --at 0.2,0.2,0,0.5",
                                  d);
  CHECK(bad.code == 2);
  CHECK(bad.err.find("NOT valid: 1 invalid cells") != std::string::npos);
  CHECK(fs::file_size(d / "bad.png") > 0);
  // Usage errors: exit 1 and one line naming the option, nothing drawn.
  for (const std::string& args : {std::string(" --at 1,2"), std::string(" --cut 0,0,0"), std::string(" --size 10,10"),
                                  std::string(" --out x.jpg"), std::string(" --at 0,0,0,-1"), std::string(" --bogus")}) {
    const PlafResult u = run_plaf("picture " + (d / "bad.msh").string() + args, d);
    CHECK_MESSAGE(u.code == 1, args);
    CHECK_MESSAGE(u.err.rfind("plaf: error: ", 0) == 0, args);
  }
  CHECK(run_plaf("picture " + (d / "missing.msh").string(), d).code == 1);
}
