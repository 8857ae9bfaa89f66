// SPDX-License-Identifier: MIT
// Implements read_cgns (cgns_io.h): the CGNS reader through libcgns's mid-level library (cg_open,
// cg_base_read, cg_zone_read, cg_coord_read, cg_section_read, cg_elements_read, cg_boco_info,
// cg_boco_read, cg_famname_read); what it takes and how facets get their tags is documented in
// cgns_io.h.
#include <cgnslib.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "modules/base/coordinates.h"
#include "modules/base/error.h"
#include "modules/io/cgns_io.h"
#include "modules/elements/lagrange.h"
#include "modules/io/cgns_types.h"

namespace plaf {
inline namespace io {
namespace {

class CgnsInput {
 public:
  explicit CgnsInput(const std::filesystem::path& path) : path_(path) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) fail("cannot open the file (it does not exist or is not a file)");
    int valid = 0;
    if (cg_is_cgns(path.c_str(), &valid) != CG_OK) fail("not a CGNS file");
    if (cg_open(path.c_str(), CG_MODE_READ, &fn_) != CG_OK) {
      // libcgns may count the file as open before it fails a check: release its slot.
      const std::string why = cg_get_error();
      if (fn_ > 0) cg_close(fn_);
      fn_ = -1;
      fail("cannot open (libcgns: " + why + ")");
    }
  }
  ~CgnsInput() {
    if (fn_ > 0) cg_close(fn_);
  }
  CgnsInput(const CgnsInput&) = delete;
  CgnsInput& operator=(const CgnsInput&) = delete;
  int fn() const { return fn_; }
  void check(int rc, const std::string& what) const {
    if (rc != CG_OK) fail(what + " (libcgns: " + cg_get_error() + ")");
  }
  [[noreturn]] void fail(const std::string& why) const { throw InputError(path_.string() + ": " + why); }

 private:
  std::filesystem::path path_;
  int fn_ = -1;
};

BoundaryKind kind_of(CGNS_ENUMT(BCType_t) type, const std::string& name) {
  switch (type) {
    case CGNS_ENUMV(BCWall):
    case CGNS_ENUMV(BCWallInviscid):
    case CGNS_ENUMV(BCWallViscous):
    case CGNS_ENUMV(BCWallViscousHeatFlux):
    case CGNS_ENUMV(BCWallViscousIsothermal):
      return BoundaryKind::Wall;
    case CGNS_ENUMV(BCFarfield):
      return BoundaryKind::Farfield;
    case CGNS_ENUMV(BCSymmetryPlane):
      return BoundaryKind::Symmetry;
    default:
      break;
  }
  return boundary_kind_from_name(name);
}

// The BC type of a family of the base (its FamilyBC_t), or BCTypeNull.
CGNS_ENUMT(BCType_t) family_bc_type(CgnsInput& in, int base, const std::string& family) {
  int n = 0;
  if (cg_nfamilies(in.fn(), base, &n) != CG_OK) return CGNS_ENUMV(BCTypeNull);
  for (int f = 1; f <= n; ++f) {
    char name[64] = {};
    int nbc = 0, ngeo = 0;
    if (cg_family_read(in.fn(), base, f, name, &nbc, &ngeo) != CG_OK || family != name || nbc < 1) continue;
    char bc_name[64] = {};
    CGNS_ENUMT(BCType_t) type = CGNS_ENUMV(BCTypeNull);
    if (cg_fambc_read(in.fn(), base, f, 1, bc_name, &type) == CG_OK) return type;
  }
  return CGNS_ENUMV(BCTypeNull);
}

struct Section {
  std::string name;
  CellType type;
  int order;
  cgsize_t start, end;
  std::vector<NodeId> nodes;  // Gmsh order, 0-based
};

template <int Dim>
void fill(CgnsInput& in, int base, int zone, cgsize_t node_count, bool surface, HybridMesh<Dim>& mesh) {
  const int fn = in.fn();
  // Coordinates.
  mesh.nodes.resize(static_cast<std::size_t>(node_count));
  static const char* const names[3] = {"CoordinateX", "CoordinateY", "CoordinateZ"};
  std::vector<double> x(static_cast<std::size_t>(node_count));
  for (int d = 0; d < Dim; ++d) {
    cgsize_t lo = 1, hi = node_count;
    in.check(cg_coord_read(fn, base, zone, names[d], CGNS_ENUMV(RealDouble), &lo, &hi, x.data()),
             std::string("cannot read ") + names[d]);
    for (std::size_t i = 0; i < x.size(); ++i) {
      if (!std::isfinite(x[i]) || std::abs(x[i]) > kMaxCoordinate)
        in.fail(std::string(names[d]) + " of node " + std::to_string(i + 1) + " is " + std::to_string(x[i]));
      mesh.nodes[i][d] = x[i];
    }
  }
  // Sections of the cells' and the facets' dimension.
  int num_sections = 0;
  in.check(cg_nsections(fn, base, zone, &num_sections), "cannot count the element sections");
  std::vector<Section> sections;
  for (int s = 1; s <= num_sections; ++s) {
    char name[64] = {};
    CGNS_ENUMT(ElementType_t) code;
    cgsize_t start = 0, end = 0;
    int nbndry = 0, parent = 0;
    in.check(cg_section_read(fn, base, zone, s, name, &code, &start, &end, &nbndry, &parent),
             "cannot read element section " + std::to_string(s));
    const auto cell = cell_of_cgns_type(static_cast<int>(code));
    if (!cell) {
      int npe = 0;
      if (cg_npe(code, &npe) == CG_OK && npe > 0 && npe <= 2) continue;  // points: ignored
      in.fail(std::string("section '") + name + "' has element type " + ElementTypeName[code] +
              ", which plaf does not represent (Lagrange BAR, TRI, QUAD, TETRA and PENTA of order 1..4)");
    }
    // Cells and facets; a surface's facets and (3D) curves; anything else is ignored.
    const int dim = ref_dim(cell->first);
    if (surface ? dim != Dim - 1 && !(Dim == 3 && dim == 1) : dim != Dim && dim != Dim - 1) continue;
    if (end < start) in.fail(std::string("section '") + name + "' has the element range " + std::to_string(start) + ".." + std::to_string(end));
    Section sec{name, cell->first, cell->second, start, end, {}};
    const std::vector<int> perm = cgns_node_permutation(sec.type, sec.order);
    const auto n = static_cast<std::size_t>(static_cast<std::int64_t>(end) - static_cast<std::int64_t>(start) + 1);
    const std::size_t per = perm.size();
    cgsize_t data_size = 0;
    in.check(cg_ElementDataSize(fn, base, zone, s, &data_size), std::string("cannot size section '") + name + "'");
    if (static_cast<std::size_t>(data_size) != n * per)
      in.fail(std::string("section '") + name + "' holds " + std::to_string(data_size) + " node numbers for " +
              std::to_string(n) + " elements of " + std::to_string(per) + " nodes");
    std::vector<cgsize_t> conn(n * per);
    in.check(cg_elements_read(fn, base, zone, s, conn.data(), nullptr), std::string("cannot read section '") + name + "'");
    sec.nodes.resize(conn.size());
    for (std::size_t e = 0; e < n; ++e)
      for (std::size_t k = 0; k < per; ++k) {
        const cgsize_t v = conn[e * per + k];
        if (v < 1 || v > node_count)
          in.fail(std::string("section '") + name + "' element " + std::to_string(start + static_cast<cgsize_t>(e)) +
                  " refers to node " + std::to_string(v) + " of " + std::to_string(node_count));
        sec.nodes[e * per + static_cast<std::size_t>(perm[k])] = static_cast<NodeId>(v - 1);
      }
    sections.push_back(std::move(sec));
  }
  if (sections.empty())
    in.fail("zone 1 has no element section plaf reads (Lagrange TRI, QUAD, TETRA, PENTA, BAR of order 1..4 of the "
            "zone's dimensions)");
  // Boundary conditions: which element numbers each names.
  int num_bcs = 0;
  in.check(cg_nbocos(fn, base, zone, &num_bcs), "cannot count the boundary conditions");
  struct Bc {
    std::string name;
    BoundaryKind kind;
    std::vector<cgsize_t> list;  // sorted element numbers
    bool range = false;          // list = {first, last}
  };
  std::vector<Bc> bcs;
  for (int b = 1; b <= num_bcs; ++b) {
    char name[64] = {};
    CGNS_ENUMT(BCType_t) type;
    CGNS_ENUMT(PointSetType_t) set;
    cgsize_t npnts = 0, normal_size = 0;
    int normal_index[3] = {0, 0, 0}, datasets = 0;
    CGNS_ENUMT(DataType_t) normal_type;
    in.check(cg_boco_info(fn, base, zone, b, name, &type, &set, &npnts, normal_index, &normal_size, &normal_type, &datasets),
             "cannot read boundary condition " + std::to_string(b));
    const bool range = set == CGNS_ENUMV(PointRange) || set == CGNS_ENUMV(ElementRange);
    if (!range && set != CGNS_ENUMV(PointList) && set != CGNS_ENUMV(ElementList)) continue;
    if (range && npnts != 2) in.fail(std::string("boundary condition '") + name + "' has a range of " + std::to_string(npnts) + " values");
    CGNS_ENUMT(GridLocation_t) location = CGNS_ENUMV(Vertex);
    in.check(cg_boco_gridlocation_read(fn, base, zone, b, &location), std::string("cannot read the location of '") + name + "'");
    // Element-based BCs only (a list of vertices does not say which facets).
    if (location == CGNS_ENUMV(Vertex) && set != CGNS_ENUMV(ElementRange) && set != CGNS_ENUMV(ElementList)) continue;
    Bc bc{name, kind_of(type, name), std::vector<cgsize_t>(static_cast<std::size_t>(npnts)), range};
    in.check(cg_boco_read(fn, base, zone, b, bc.list.data(), nullptr), std::string("cannot read the elements of '") + name + "'");
    if (cg_goto(fn, base, "Zone_t", zone, "ZoneBC_t", 1, "BC_t", b, "end") == CG_OK) {
      char family[4096] = {};  // a family path may be longer than a name in libcgns 4
      if (cg_famname_read(family) == CG_OK && family[0] != '\0') {
        bc.name = family;
        // FamilySpecified: the type is the family's FamilyBC.
        if (type == CGNS_ENUMV(FamilySpecified)) bc.kind = kind_of(family_bc_type(in, base, family), bc.name);
      }
    }
    if (!range) std::sort(bc.list.begin(), bc.list.end());
    bcs.push_back(std::move(bc));
  }
  auto bc_of = [&](cgsize_t element) -> const Bc* {
    for (const Bc& bc : bcs)
      if (bc.range ? element >= bc.list[0] && element <= bc.list[1]
                   : std::binary_search(bc.list.begin(), bc.list.end(), element))
        return &bc;
    return nullptr;
  };
  std::map<std::string, int> tag_of;
  auto tag = [&](const std::string& name, BoundaryKind kind) {
    auto it = tag_of.find(name);
    if (it != tag_of.end()) return it->second;
    return tag_of[name] = mesh.add_tag(name, kind);
  };
  for (const Section& sec : sections) {
    const int per = num_nodes(sec.type, sec.order);
    if (ref_dim(sec.type) == Dim && !surface) {
      CellBlock& out = mesh.block(sec.type, sec.order);
      out.connectivity.insert(out.connectivity.end(), sec.nodes.begin(), sec.nodes.end());
      continue;
    }
    // Facets no BC names: tagged by their section's name, less a "_<CGNS type>" suffix that plaf's
    // writer adds to a tag's second section ("wall", "wall_QUAD_9").
    std::string section_tag = sec.name;
    for (CellType t : {CellType::Line, CellType::Triangle, CellType::Quadrilateral})
      for (int q = 1; q <= max_order; ++q) {
        std::string suffix(1, '_');
        suffix += cgns_element_name(t, q);
        if (section_tag.size() > suffix.size() && section_tag.ends_with(suffix) &&
            tag_of.count(section_tag.substr(0, section_tag.size() - suffix.size())))
          section_tag.resize(section_tag.size() - suffix.size());
      }
    for (cgsize_t e = sec.start; e <= sec.end; ++e) {
      const Bc* bc = bc_of(e);
      const int t = bc ? tag(bc->name, bc->kind) : tag(section_tag, boundary_kind_from_name(section_tag));
      CellBlock& out = Dim == 3 && surface && ref_dim(sec.type) == 1 ? mesh.curve_block(sec.order, t)
                                                                     : mesh.boundary_block(sec.type, sec.order, t);
      const auto first = sec.nodes.begin() + static_cast<std::ptrdiff_t>((e - sec.start) * per);
      out.connectivity.insert(out.connectivity.end(), first, first + per);
    }
  }
}

}  // namespace

MshMesh read_cgns(const std::filesystem::path& path) {
  const std::lock_guard<std::mutex> lock(cgns_mutex());
  CgnsInput in(path);
  const int fn = in.fn();
  int num_bases = 0;
  in.check(cg_nbases(fn, &num_bases), "cannot count the bases");
  if (num_bases < 1) in.fail("no base (CGNSBase_t)");
  char name[64] = {};
  int cell_dim = 0, phys_dim = 0;
  in.check(cg_base_read(fn, 1, name, &cell_dim, &phys_dim), "cannot read base 1");
  if ((phys_dim != 2 && phys_dim != 3) || (cell_dim != phys_dim && cell_dim != phys_dim - 1))
    in.fail("base '" + std::string(name) + "' has cell dimension " + std::to_string(cell_dim) + " and physical dimension " +
            std::to_string(phys_dim) + " (plaf reads planar 2D meshes, 3D volume meshes and 3D surface meshes)");
  int num_zones = 0;
  in.check(cg_nzones(fn, 1, &num_zones), "cannot count the zones");
  if (num_zones < 1) in.fail("base '" + std::string(name) + "' has no zone");
  if (num_zones > 1 || num_bases > 1)
    in.fail(std::to_string(num_bases) + " bases and " + std::to_string(num_zones) +
            " zones in the first: plaf reads a mesh of one zone (merge the zones, e.g. with cgnsupdate tools)");
  CGNS_ENUMT(ZoneType_t) type;
  in.check(cg_zone_type(fn, 1, 1, &type), "cannot read zone 1's type");
  if (type != CGNS_ENUMV(Unstructured)) in.fail("zone 1 is not unstructured");
  cgsize_t size[3] = {0, 0, 0};
  in.check(cg_zone_read(fn, 1, 1, name, size), "cannot read zone 1");
  // A cell dimension one below the physical one: a surface mesh (lines in 2D, triangles and
  // quadrilaterals with their curves in 3D).
  MshMesh result;
  result.dim = phys_dim;
  if (phys_dim == 2)
    fill(in, 1, 1, size[0], cell_dim == 1, result.mesh2);
  else
    fill(in, 1, 1, size[0], cell_dim == 2, result.mesh3);
  return result;
}

MshMesh read_mesh_file(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  for (char& ch : extension) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return extension == ".cgns" ? read_cgns(path) : read_msh41(path);
}

}  // namespace io
}  // namespace plaf
