// SPDX-License-Identifier: MIT
// _plaf: the compiled half of the Python module (python/plaf/__init__.py is the other): runs a
// configuration (YAML text or a file) through the driver (apps/run.h) and hands back the mesh in
// memory (nodes and cells as numpy arrays, Gmsh node order), its tags and the JSON report; writes
// the mesh in plaf's formats; certifies a mesh file as `plaf check` does. plaf's errors become
// Python exceptions carrying the CLI's one-line message: plaf.Error (a RuntimeError) and its
// subclasses InputError (ConfigError is one) and MesherError.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>

#include "apps/run.h"
#include "modules/base/error.h"
#include "modules/elements/lagrange.h"
#include "modules/io/cgns_io.h"
#include "modules/io/msh_io.h"
#include "modules/io/output_set.h"
#include "modules/io/text_cursor.h"
#include "modules/io/vtu_writer.h"
#include "modules/pipeline/run_config.h"

namespace py = pybind11;
namespace fs = std::filesystem;

namespace {

// A scratch folder removed with its contents when the run ends.
class ScratchDir {
 public:
  ScratchDir() {
    std::string pattern = (fs::temp_directory_path() / "plaf_python_XXXXXX").string();
    if (!::mkdtemp(pattern.data())) throw plaf::Error("cannot create a scratch folder in " + fs::temp_directory_path().string());
    path_ = pattern;
  }
  ~ScratchDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};


// One run's result: the mesh (2D or 3D), its exit code and report.
struct Result {
  int dim = 0;
  int exit_code = 0;
  std::string report_json;
  std::string name;
  std::shared_ptr<const plaf::HybridMesh<2>> mesh2;
  std::shared_ptr<const plaf::HybridMesh<3>> mesh3;
};

template <int Dim>
py::array_t<double> points_of(const plaf::HybridMesh<Dim>& m) {
  py::array_t<double> a({static_cast<py::ssize_t>(m.nodes.size()), py::ssize_t{3}});
  auto r = a.mutable_unchecked<2>();
  for (std::size_t i = 0; i < m.nodes.size(); ++i)
    for (int d = 0; d < 3; ++d) r(static_cast<py::ssize_t>(i), d) = d < Dim ? m.nodes[i][d] : 0.0;
  return a;
}

// Blocks as {"prism_Q2": array (cells x nodes, 0-based node numbers, Gmsh's node order)}; blocks
// of one type and order are joined. With a tag filter: only the blocks of that tag.
py::dict blocks_of(const std::vector<plaf::CellBlock>& blocks, int tag = -1) {
  std::map<std::string, std::vector<const plaf::CellBlock*>> by_key;
  for (const plaf::CellBlock& b : blocks)
    if (tag < 0 || b.tag == tag)
      by_key[std::string(plaf::cell_name(b.type)) + "_Q" + std::to_string(b.order)].push_back(&b);
  py::dict out;
  for (const auto& [key, list] : by_key) {
    const py::ssize_t per = list.front()->nodes_per_cell();
    py::ssize_t n = 0;
    for (const plaf::CellBlock* b : list) n += static_cast<py::ssize_t>(b->size());
    py::array_t<std::int64_t> a({n, per});
    std::int64_t* p = a.mutable_data();
    for (const plaf::CellBlock* b : list)
      for (plaf::NodeId v : b->connectivity) *p++ = v;
    out[py::str(key)] = a;
  }
  return out;
}

template <int Dim>
py::dict boundary_of(const plaf::HybridMesh<Dim>& m) {
  py::dict out;
  for (int t = 0; t < static_cast<int>(m.tags.size()); ++t)
    out[py::str(m.tags[static_cast<std::size_t>(t)].name)] = blocks_of(m.boundary, t);
  return out;
}

template <int Dim>
py::list tags_of(const plaf::HybridMesh<Dim>& m) {
  py::list out;
  for (const plaf::BoundaryTag& t : m.tags) out.append(py::make_tuple(t.name, plaf::boundary_kind_name(t.kind)));
  return out;
}

// Writes by the path's suffix: .cgns, .vtu, .msh (MSH 4.1, or 2.2 with format "msh22").
template <int Dim>
void write_mesh(const plaf::HybridMesh<Dim>& m, const fs::path& path, const std::string& format, bool binary) {
  std::string ext = path.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const std::string f = format.empty() ? (ext == ".cgns" ? "cgns" : ext == ".vtu" ? "vtu" : ext == ".msh" ? "msh" : "")
                                       : format;
  if (f == "msh")
    plaf::write_msh41(m, path, binary ? plaf::MshEncoding::binary : plaf::MshEncoding::ascii);
  else if (f == "msh22")
    plaf::write_msh22(m, path, binary ? plaf::MshEncoding::binary : plaf::MshEncoding::ascii);
  else if (f == "cgns")
    plaf::write_cgns(m, path);
  else if (f == "vtu")
    plaf::write_vtu(m, path, {}, binary ? plaf::VtuEncoding::binary : plaf::VtuEncoding::ascii);
  else
    throw plaf::InputError(path.string() + ": unknown format '" + f +
                           "' (give a path ending in .msh, .cgns or .vtu, or format msh, msh22, cgns or vtu)");
}

// Runs a parsed configuration. out: the folder for the configured outputs; none: the run writes
// only its report, into a scratch folder, and the mesh stays in memory.
Result run(plaf::RunConfig c, const std::optional<fs::path>& out, bool quiet, bool keep_invalid) {
  std::optional<ScratchDir> scratch;
  if (out) {
    c.output.dir = *out;
  } else {
    scratch.emplace();
    c.output.dir = scratch->path();
    c.output.formats = {"report"};
    c.output.cuts.clear();
  }
  // A failed run's mesh is handed back in memory either way (exit_code 2); written only when asked.
  c.output.keep_invalid = keep_invalid;
  plaf::prepare_output_dir(c.output.dir, c.name);
  plaf::RunOutcome o;
  {
    py::gil_scoped_release release;
    o = plaf::run_config(c, quiet);  // quiet: no stage lines, no progress; failures still on stderr
  }
  Result r;
  r.dim = c.dim;
  r.exit_code = o.code;
  r.name = c.name;
  r.report_json = plaf::report_json(o.report);
  r.mesh2 = o.mesh2;
  r.mesh3 = o.mesh3;
  return r;
}

}  // namespace

PYBIND11_MODULE(_plaf, m) {
  m.doc() = "plaf: curved high-order hybrid meshes (prismatic layers and advancing fronts); see plaf/__init__.py";
  plaf::register_all_plugins();
  static py::exception<plaf::Error> error(m, "Error", PyExc_RuntimeError);
  static py::exception<plaf::InputError> input_error(m, "InputError", error.ptr());
  static py::exception<plaf::ConfigError> config_error(m, "ConfigError", input_error.ptr());
  static py::exception<plaf::MesherError> mesher_error(m, "MesherError", error.ptr());
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const plaf::ConfigError& e) {
      config_error(e.what());
    } catch (const plaf::InputError& e) {
      input_error(e.what());
    } catch (const plaf::MesherError& e) {
      mesher_error(e.what());
    } catch (const plaf::Error& e) {
      error(e.what());
    }
  });

  py::class_<Result>(m, "Mesh", "A run's mesh: points, cells by type, boundary facets by tag, and its report")
      .def_readonly("dim", &Result::dim)
      .def_readonly("exit_code", &Result::exit_code, "0: valid; 2: the run failed (see report)")
      .def_readonly("name", &Result::name)
      .def_readonly("report_json", &Result::report_json)
      .def_property_readonly("points", [](const Result& r) { return r.dim == 2 ? points_of(*r.mesh2) : points_of(*r.mesh3); },
                             "nodes x 3 (z = 0 in 2D), float64")
      .def_property_readonly("cells",
                             [](const Result& r) { return blocks_of(r.dim == 2 ? r.mesh2->cells : r.mesh3->cells); },
                             "{'prism_Q2': cells x nodes int64 (0-based, Gmsh's node order), ...}")
      .def_property_readonly("boundary",
                             [](const Result& r) { return r.dim == 2 ? boundary_of(*r.mesh2) : boundary_of(*r.mesh3); },
                             "{tag name: {'triangle_Q2': facets x nodes, ...}}")
      .def_property_readonly("tags", [](const Result& r) { return r.dim == 2 ? tags_of(*r.mesh2) : tags_of(*r.mesh3); },
                             "[(name, kind)] with kind wall, farfield, symmetry or named")
      .def(
          "write",
          [](const Result& r, const fs::path& path, const std::string& format, bool binary) {
            if (r.dim == 2)
              write_mesh(*r.mesh2, path, format, binary);
            else
              write_mesh(*r.mesh3, path, format, binary);
          },
          py::arg("path"), py::arg("format") = "", py::arg("binary") = false,
          "write the mesh: format from the suffix (.msh: MSH 4.1, .cgns, .vtu) or msh, msh22, cgns, vtu");

  m.def(
      "_run_yaml",
      [](const std::string& text, const std::string& name, const std::optional<fs::path>& out, bool quiet,
         bool keep_invalid) { return run(plaf::parse_run_config(text, name), out, quiet, keep_invalid); },
      py::arg("text"), py::arg("name"), py::arg("out") = py::none(), py::arg("quiet") = true,
      py::arg("keep_invalid") = false);
  m.def(
      "_run_file",
      [](const fs::path& path, const std::optional<fs::path>& out, bool quiet, bool keep_invalid) {
        return run(plaf::load_run_config(path), out, quiet, keep_invalid);
      },
      py::arg("path"), py::arg("out") = py::none(), py::arg("quiet") = true, py::arg("keep_invalid") = false);
  m.def(
      "_check",
      [](const fs::path& path) {
        ScratchDir scratch;
        const fs::path report = scratch.path() / "check.report.json";
        int code = 0;
        {
          py::gil_scoped_release release;
          code = plaf::check_command(path, std::nullopt, report);
        }
        return py::make_tuple(code, plaf::read_whole_file(report));
      },
      py::arg("path"));
}
