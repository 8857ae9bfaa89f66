// SPDX-License-Identifier: MIT
// Implements write_cgns (cgns_io.h): the CGNS writer through libcgns's mid-level library (CGNS
// Mid-Level Library manual: cg_open, cg_base_write, cg_zone_write, cg_coord_write,
// cg_section_write, cg_family_write, cg_fambc_write, cg_boco_write, cg_famname_write); the layout
// of sections, families and BCs is documented in cgns_io.h.
#include "modules/io/cgns_io.h"

#include <cgnslib.h>
#include <unistd.h>

#include <array>
#include <limits>
#include <algorithm>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <system_error>
#include <vector>

#include "modules/base/error.h"
#include "modules/io/atomic_file.h"
#include "modules/io/cgns_types.h"

namespace plaf {
inline namespace io {
namespace {

// An open CGNS file, closed on every path (an error thrown mid-way included).
class CgnsFile {
 public:
  CgnsFile(const std::filesystem::path& path, const std::filesystem::path& target) : target_(target) {
    if (cg_open(path.c_str(), CG_MODE_WRITE, &fn_) != CG_OK) {
      const std::string why = cg_get_error();
      if (fn_ > 0) cg_close(fn_);  // libcgns may count the file as open before it fails
      fn_ = -1;
      throw Error("cannot write " + target_.string() + ": cannot open for writing (libcgns: " + why + ")");
    }
  }
  ~CgnsFile() {
    if (fn_ > 0) cg_close(fn_);
  }
  CgnsFile(const CgnsFile&) = delete;
  CgnsFile& operator=(const CgnsFile&) = delete;
  int fn() const { return fn_; }
  // Checks a libcgns return code; the library's message names what failed.
  void check(int rc, const char* what) const {
    if (rc != CG_OK) fail(what);
  }
  void close() {
    const int fn = fn_;
    fn_ = -1;
    if (cg_close(fn) != CG_OK) fail("cannot close");
  }
  [[noreturn]] void fail(const std::string& what) const {
    throw Error("cannot write " + target_.string() + ": " + what + " (libcgns: " + cg_get_error() + ")");
  }

 private:
  std::filesystem::path target_;
  int fn_ = -1;
};

CGNS_ENUMT(BCType_t) bc_type(BoundaryKind kind) {
  switch (kind) {
    case BoundaryKind::Wall:
      return CGNS_ENUMV(BCWall);
    case BoundaryKind::Farfield:
      return CGNS_ENUMV(BCFarfield);
    case BoundaryKind::Symmetry:
      return CGNS_ENUMV(BCSymmetryPlane);
    case BoundaryKind::Named:
      break;
  }
  return CGNS_ENUMV(BCTypeUserDefined);
}

// One block's connectivity in CGNS order, 1-based.
std::vector<cgsize_t> cgns_connectivity(const CellBlock& b) {
  const std::vector<int> perm = cgns_node_permutation(b.type, b.order);
  std::vector<cgsize_t> out;
  out.reserve(b.connectivity.size());
  for (std::size_t i = 0; i < b.size(); ++i) {
    const NodeId* c = b.cell(i);
    for (int p : perm) out.push_back(static_cast<cgsize_t>(c[p]) + 1);
  }
  return out;
}

// Node names of the file: at most 32 characters, no '/', not blank, unique among the base's and
// the zone's children (one set for all: families, the zone, sections, BCs). A clash or a cut name
// gets "_2", "_3", ... within the 32 characters.
class CgnsNames {
 public:
  CgnsNames() : used_{"plaf", "domain", "GridCoordinates", "ZoneBC", "ZoneType", "FamBC", "DataClass"} {}
  std::string make(const std::string& wanted) {
    std::string base = wanted;
    std::replace(base.begin(), base.end(), '/', '_');
    if (base.find_first_not_of(' ') == std::string::npos) base = "unnamed";
    base = base.substr(0, 32);
    std::string name = base;
    for (int k = 2; !used_.insert(name).second; ++k) {
      const std::string number = std::to_string(k);
      name = base.substr(0, 31 - number.size());
      name.push_back('_');
      name.append(number);
    }
    return name;
  }

 private:
  std::set<std::string> used_;
};

template <int Dim>
void write_file(const HybridMesh<Dim>& mesh, CgnsFile& f) {
  const int fn = f.fn();
  int base = 0, zone = 0;
  // A mesh without cells (a surface run) is a zone of cell dimension Dim - 1: its facets are its
  // cells, tagged by their sections' names (no BCs: they would bound nothing); in 3D its curves
  // are its boundary, with BCs at EdgeCenter.
  std::size_t num_cells = 0;
  for (const CellBlock& b : mesh.cells) num_cells += b.size();
  const bool surface = num_cells == 0;
  if (surface)
    for (const CellBlock& b : mesh.boundary) num_cells += b.size();
  f.check(cg_base_write(fn, "plaf", surface ? Dim - 1 : Dim, Dim, &base), "cg_base_write");
  // The coordinates' units are the geometry's, which plaf does not know.
  f.check(cg_goto(fn, base, "end"), "cg_goto");
  f.check(cg_dataclass_write(CGNS_ENUMV(NormalizedByUnknownDimensional)), "cg_dataclass_write");
  cgsize_t size[3] = {static_cast<cgsize_t>(mesh.nodes.size()), static_cast<cgsize_t>(num_cells), 0};
  f.check(cg_zone_write(fn, base, "domain", size, CGNS_ENUMV(Unstructured), &zone), "cg_zone_write");
  static const char* const coordinates[3] = {"CoordinateX", "CoordinateY", "CoordinateZ"};
  std::vector<double> x(mesh.nodes.size());
  for (int d = 0; d < Dim; ++d) {
    for (std::size_t i = 0; i < mesh.nodes.size(); ++i) x[i] = mesh.nodes[i][d];
    int c = 0;
    f.check(cg_coord_write(fn, base, zone, CGNS_ENUMV(RealDouble), coordinates[d], x.data(), &c), "cg_coord_write");
    // A length: exponents of mass, length, time, temperature, angle.
    const double length[5] = {0, 1, 0, 0, 0};
    f.check(cg_goto(fn, base, "Zone_t", zone, "GridCoordinates_t", 1, "DataArray_t", c, "end"), "cg_goto");
    f.check(cg_exponents_write(CGNS_ENUMV(RealDouble), length), "cg_exponents_write");
  }
  cgsize_t next = 1;  // the next element number
  CgnsNames names;
  // Each tag's name in the file, chosen once (its family, BC and first section).
  std::vector<std::string> tag_name;
  for (const BoundaryTag& t : mesh.tags) tag_name.push_back(names.make(t.name));
  auto section = [&](const CellBlock& b, const std::string& unique) {
    if (b.size() == 0) return;
    const std::vector<cgsize_t> conn = cgns_connectivity(b);
    const cgsize_t start = next, end = next + static_cast<cgsize_t>(b.size()) - 1;
    int s = 0;
    f.check(cg_section_write(fn, base, zone, unique.c_str(),
                             static_cast<CGNS_ENUMT(ElementType_t)>(cgns_element_type(b.type, b.order)), start, end, 0,
                             conn.data(), &s),
            "cg_section_write");
    next = end + 1;
  };
  for (const CellBlock& b : mesh.cells) section(b, names.make(cgns_element_name(b.type, b.order)));
  // Blocks by tag, each tag's blocks in a row (one element range per tag), with a family and a BC
  // on that range at `location` when `bcs`.
  std::set<std::string> families;
  auto by_tag = [&](const std::vector<CellBlock>& blocks, bool bcs, CGNS_ENUMT(GridLocation_t) location) {
    for (int t = 0; t < static_cast<int>(mesh.tags.size()); ++t) {
      const BoundaryTag& tag = mesh.tags[static_cast<std::size_t>(t)];
      const std::string& name = tag_name[static_cast<std::size_t>(t)];
      const cgsize_t first = next;
      bool any = false;
      for (const CellBlock& b : blocks)
        if (b.tag == t && b.size() > 0) {
          section(b, any ? names.make(tag_name[static_cast<std::size_t>(t)] + "_" + cgns_element_name(b.type, b.order))
                         : tag_name[static_cast<std::size_t>(t)]);
          any = true;
        }
      if (!any || !bcs) continue;
      if (families.insert(name).second) {
        int family = 0, family_bc = 0;
        f.check(cg_family_write(fn, base, name.c_str(), &family), "cg_family_write");
        f.check(cg_fambc_write(fn, base, family, "FamBC", bc_type(tag.kind), &family_bc), "cg_fambc_write");
      }
      int bc = 0;
      const cgsize_t range[2] = {first, next - 1};
      f.check(cg_boco_write(fn, base, zone, name.c_str(), bc_type(tag.kind), CGNS_ENUMV(PointRange), 2, range, &bc),
              "cg_boco_write");
      f.check(cg_boco_gridlocation_write(fn, base, zone, bc, location), "cg_boco_gridlocation_write");
      f.check(cg_goto(fn, base, "Zone_t", zone, "ZoneBC_t", 1, "BC_t", bc, "end"), "cg_goto");
      f.check(cg_famname_write(name.c_str()), "cg_famname_write");
    }
  };
  by_tag(mesh.boundary, !surface, Dim == 3 ? CGNS_ENUMV(FaceCenter) : CGNS_ENUMV(EdgeCenter));
  if (Dim == 3 && surface) by_tag(mesh.curves, true, CGNS_ENUMV(EdgeCenter));
}

}  // namespace

template <int Dim>
void write_cgns(const HybridMesh<Dim>& mesh, const std::filesystem::path& path) {
  // 1. Validate before touching the file system: the blocks, the tags, libcgns's 32-bit sizes.
  auto fail = [&](const std::string& why) { throw Error("cannot write " + path.string() + ": " + why); };
  std::size_t elements = 0;
  for (const auto* blocks : {&mesh.cells, &mesh.boundary})
    for (const CellBlock& b : *blocks) {
      if (b.order < 1 || b.order > max_order) fail(std::string(cell_name(b.type)) + " block of order " + std::to_string(b.order));
      if (b.connectivity.size() % static_cast<std::size_t>(b.nodes_per_cell()) != 0)
        fail(std::string(cell_name(b.type)) + " block with a partial cell");
      for (NodeId v : b.connectivity)
        if (v < 0 || static_cast<std::size_t>(v) >= mesh.nodes.size())
          fail(std::string(cell_name(b.type)) + " block refers to node " + std::to_string(v) + " of " +
               std::to_string(mesh.nodes.size()));
      elements += b.size();
      if (b.connectivity.size() > static_cast<std::size_t>(std::numeric_limits<cgsize_t>::max()))
        fail(std::string(cell_name(b.type)) + " block of " + std::to_string(b.size()) + " cells holds more node numbers than libcgns's " +
             std::to_string(8 * sizeof(cgsize_t)) + "-bit sizes count");
    }
  for (const CellBlock& b : mesh.boundary)
    if (b.tag < 0 || b.tag >= static_cast<int>(mesh.tags.size()))
      fail("boundary block has tag index " + std::to_string(b.tag) + " but the mesh has " +
           std::to_string(mesh.tags.size()) + " tags");
  if (mesh.nodes.size() > static_cast<std::size_t>(std::numeric_limits<cgsize_t>::max()) ||
      elements > static_cast<std::size_t>(std::numeric_limits<cgsize_t>::max()))
    fail("libcgns counts with " + std::to_string(8 * sizeof(cgsize_t)) + "-bit integers; this mesh has " +
         std::to_string(mesh.nodes.size()) + " nodes and " + std::to_string(elements) + " elements");
  // 2. The file, under a temporary name beside the target (removed on failure or a signal);
  //    libcgns is used by one thread at a time.
  const std::lock_guard<std::mutex> lock(cgns_mutex());
  const std::filesystem::path temp = path.string() + ".tmp." + std::to_string(::getpid());
  const int slot = cleanup::add(temp);
  try {
    CgnsFile f(temp, path);
    write_file(mesh, f);
    f.close();
    std::error_code ec;
    std::filesystem::rename(temp, path, ec);
    if (ec) fail("cannot rename " + temp.string() + " onto it: " + ec.message());
  } catch (...) {
    std::error_code ec;
    std::filesystem::remove(temp, ec);
    cleanup::release(slot);
    throw;
  }
  cleanup::release(slot);
}

template void write_cgns(const HybridMesh<2>&, const std::filesystem::path&);
template void write_cgns(const HybridMesh<3>&, const std::filesystem::path&);

}  // namespace io
}  // namespace plaf
