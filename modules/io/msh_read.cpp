// SPDX-License-Identifier: MIT
// Implements read_msh41 (msh_io.h): the Gmsh MSH 4.1 and 2.2 reader, ASCII and binary (Gmsh reference manual, "MSH
// file format"); what it accepts and how it maps groups to tags is documented in msh_io.h.
#include "modules/io/msh_io.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <map>
#include <string>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <unordered_map>
#include <utility>
#include <vector>

#include "modules/base/coordinates.h"
#include "modules/base/format.h"
#include "modules/io/gmsh_types.h"
#include "modules/io/text_cursor.h"

namespace plaf {
inline namespace io {
namespace {

// Maps possibly sparse node tags to contiguous indices in file order.
class NodeTagMap {
 public:
  // Dense storage when the tag range is at most a few times the node count.
  void init(std::int64_t num_nodes, std::int64_t min_tag, std::int64_t max_tag) {
    // Called with num_nodes == 0 or 1 <= min_tag <= max_tag (checked by the caller).
    constexpr std::int64_t dense_factor = 4, dense_slack = 1024;
    if (num_nodes == 0) return;
    min_tag_ = min_tag;
    max_tag_ = max_tag;
    dense_ = max_tag - min_tag < dense_factor * num_nodes + dense_slack;
    if (dense_) index_.assign(static_cast<std::size_t>(max_tag - min_tag + 1), -1);
  }
  // False if the tag was seen before.
  bool insert(std::int64_t tag, NodeId id) {
    if (dense_) {
      NodeId& slot = index_[static_cast<std::size_t>(tag - min_tag_)];
      if (slot >= 0) return false;
      slot = id;
      return true;
    }
    return sparse_.emplace(tag, id).second;
  }
  NodeId find(std::int64_t tag) const {
    if (tag < min_tag_ || tag > max_tag_) return -1;
    if (dense_) return index_[static_cast<std::size_t>(tag - min_tag_)];
    auto it = sparse_.find(tag);
    return it == sparse_.end() ? -1 : it->second;
  }
  std::int64_t min_tag() const { return min_tag_; }
  std::int64_t max_tag() const { return max_tag_; }

 private:
  bool dense_ = true;
  std::int64_t min_tag_ = 1, max_tag_ = 0;
  std::vector<NodeId> index_;
  std::unordered_map<std::int64_t, NodeId> sparse_;
};

struct RawBlock {
  int line = 0;  // of the block header
  int entity_dim = 0;
  std::int64_t entity_tag = 0;
  const GmshType* type = nullptr;
  std::vector<NodeId> nodes;  // contiguous node indices, type->nodes per element
};


// A section's fields as MSH 4.1 stores them: text tokens (ASCII), or Gmsh's binary layout (the
// reference manual's "MSH file format": ints of 4 bytes, size_t counts and tags of 8, doubles,
// in the writer's byte order, checked by the header). One reader per section serves both.
struct TextFields {
  TextCursor& in;
  void begin() {}
  std::int64_t int32(const char* what) { return in.integer(what); }
  std::int64_t int32(const char* what, std::int64_t lo, std::int64_t hi) { return in.integer(what, lo, hi); }
  std::int64_t size(const char* what) { return in.integer(what); }
  // A count of items of at least text_bytes characters each (binary_bytes in a binary file).
  std::int64_t count(const char* what, std::size_t text_bytes, std::size_t) { return in.count(what, text_bytes); }
  double real(const char* what) { return in.real(what); }
  double coordinate(const char* what) { return in.coordinate(what); }
};

struct BinaryFields {
  TextCursor& in;
  // The data starts on the line after the section's name.
  void begin() { in.start_binary(); }
  template <class T>
  T get(const char* what) {
    T v;
    std::memcpy(&v, in.raw(sizeof(T), what).data(), sizeof(T));
    return v;
  }
  std::int64_t int32(const char* what) { return get<std::int32_t>(what); }
  std::int64_t int32(const char* what, std::int64_t lo, std::int64_t hi) {
    const std::int64_t v = int32(what);
    if (v < lo || v > hi)
      in.fail(std::string(what) + " " + std::to_string(v) + " is outside " + std::to_string(lo) + ".." + std::to_string(hi));
    return v;
  }
  std::int64_t size(const char* what) {
    const auto v = get<std::uint64_t>(what);
    if (v > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()))
      in.fail(std::string("bad ") + what + " " + std::to_string(v));
    return static_cast<std::int64_t>(v);
  }
  std::int64_t count(const char* what, std::size_t, std::size_t binary_bytes) {
    const std::int64_t v = size(what);
    if (static_cast<std::uint64_t>(v) > in.remaining() / binary_bytes + 1)
      in.fail(std::string(what) + " " + std::to_string(v) + " exceeds what the rest of the file can hold (truncated file?)");
    return v;
  }
  double real(const char* what) {
    const double v = get<double>(what);
    if (!std::isfinite(v)) in.fail(std::string("bad ") + what + " " + std::to_string(v));
    return v;
  }
  double coordinate(const char* what) {
    const double v = real(what);
    if (std::abs(v) > kMaxCoordinate) in.fail(std::string(what) + " " + num(v) + " is beyond +-" + num(kMaxCoordinate));
    return v;
  }
};

class MshReader {
 public:
  MshReader(const std::filesystem::path& path, const std::string& text) : path_(path), in_(path, text) {}

  MshMesh read() {
    read_header();
    while (!in_.at_end()) {
      const int line = in_.line();
      const std::string_view t = in_.token("a section");
      if (t.size() < 2 || t[0] != '$') in_.fail("expected a section such as $Nodes, found " + TextCursor::quote(t));
      const std::string name(t.substr(1));
      if (!seen_.insert({name, line}).second) in_.fail("duplicate section $" + name);
      // One reader per known section; a $NodeData reader would be added here, next to $Nodes.
      if (name == "PhysicalNames")
        read_physical_names();  // text in binary files too
      else if (name == "Entities" && !v2_)
        binary_ ? read_entities(BinaryFields{in_}) : read_entities(TextFields{in_});
      else if (name == "Nodes" && v2_)
        binary_ ? read_nodes22(BinaryFields{in_}) : read_nodes22(TextFields{in_});
      else if (name == "Elements" && v2_)
        binary_ ? read_elements22(BinaryFields{in_}) : read_elements22(TextFields{in_});
      else if (name == "Nodes")
        binary_ ? read_nodes(BinaryFields{in_}) : read_nodes(TextFields{in_});
      else if (name == "Elements")
        binary_ ? read_elements(BinaryFields{in_}) : read_elements(TextFields{in_});
      else
        in_.skip_to_line("$End" + name, line, name);
    }
    if (!seen_.count("Nodes")) in_.fail("missing $Nodes section");
    if (!seen_.count("Elements")) in_.fail("missing $Elements section");
    return assemble();
  }

 private:
  void read_header() {
    in_.expect("$MeshFormat");
    const std::string_view version = in_.token("the MSH version");
    if (version != "4.1" && version != "2.2")
      in_.fail("MSH version " + TextCursor::quote(version) + " is not supported (plaf reads MSH 4.1 and 2.2)");
    v2_ = version == "2.2";
    const std::int64_t file_type = in_.integer("file type");
    if (file_type != 0 && file_type != 1) in_.fail("bad file type " + std::to_string(file_type) + " (0 is ASCII, 1 binary)");
    const std::int64_t data_size = in_.integer("data size");
    binary_ = file_type == 1;
    if (binary_) {
      // Gmsh's binary MSH 4.1: size_t of 8 bytes, then the integer 1 in the writer's byte order.
      if (data_size != 8) in_.fail("binary MSH with a data size of " + std::to_string(data_size) + " (plaf reads 8)");
      in_.start_binary();
      const auto one = BinaryFields{in_}.get<std::int32_t>("the binary one");
      if (one != 1)
        in_.fail("binary MSH: the integer 1 after the header reads as " + std::to_string(one) +
                 " (a file in the other byte order, big-endian, or not binary data)");
    }
    in_.expect("$EndMeshFormat");
  }

  void read_physical_names() {
    const std::int64_t n = in_.count("number of physical names", 6);
    for (std::int64_t i = 0; i < n; ++i) {
      const int dim = static_cast<int>(in_.integer("physical dimension", 0, 3));
      const std::int64_t tag = in_.integer("physical tag");
      const int line = in_.line();
      std::string name = in_.quoted_on_line("physical name");
      declares_volume_ = declares_volume_ || dim == 3;
      if (!physical_names_.emplace(std::make_pair(dim, tag), std::move(name)).second)
        in_.fail_at(line, "physical group (dimension " + std::to_string(dim) + ", tag " + std::to_string(tag) +
                              ") is named twice");
    }
    in_.expect("$EndPhysicalNames");
  }

  template <class Fields>
  void read_entities(Fields f) {
    f.begin();
    std::int64_t counts[4];
    static const char* const what[4] = {"number of points", "number of curves", "number of surfaces",
                                        "number of volumes"};
    for (int d = 0; d < 4; ++d) counts[d] = f.count(what[d], 8, 4 + 24 + 8);
    for (int d = 0; d < 4; ++d) {
      for (std::int64_t i = 0; i < counts[d]; ++i) {
        const std::int64_t tag = f.int32("entity tag");
        for (int k = 0; k < (d == 0 ? 3 : 6); ++k) f.real(d == 0 ? "point coordinate" : "bounding box coordinate");
        const std::int64_t num_physicals = f.count("number of physical tags", 2, 4);
        std::int64_t first = 0;
        for (std::int64_t k = 0; k < num_physicals; ++k) {
          const std::int64_t p = f.int32("physical tag");
          if (k == 0) first = p;
        }
        if (d > 0) {
          const std::int64_t num_bounding = f.count("number of bounding entities", 2, 4);
          for (std::int64_t k = 0; k < num_bounding; ++k) f.int32("bounding entity tag");
        }
        entity_physical_[{d, tag}] = first;
      }
    }
    declares_volume_ = declares_volume_ || counts[3] > 0;
    in_.expect("$EndEntities");
  }

  template <class Fields>
  void read_nodes(Fields f) {
    if (seen_.count("Elements")) in_.fail("$Nodes must come before $Elements");
    f.begin();
    const std::int64_t num_blocks = f.count("number of node blocks", 8, 20);
    const std::int64_t num_nodes = f.count("number of nodes", 8, 32);
    if (num_nodes > std::numeric_limits<NodeId>::max()) in_.fail("too many nodes: " + std::to_string(num_nodes));
    const std::int64_t min_tag = f.size("minimum node tag");
    const std::int64_t max_tag = f.size("maximum node tag");
    if (num_nodes > 0 && (min_tag < 1 || max_tag < min_tag || max_tag - min_tag + 1 < num_nodes))
      in_.fail("bad node tag range " + std::to_string(min_tag) + ".." + std::to_string(max_tag) + " for " +
               std::to_string(num_nodes) + " nodes");
    tags_.init(num_nodes, min_tag, max_tag);
    coords_.reserve(static_cast<std::size_t>(num_nodes));
    for (std::int64_t b = 0; b < num_blocks; ++b) {
      const int entity_dim = static_cast<int>(f.int32("entity dimension", 0, 3));
      f.int32("entity tag");
      const bool parametric = f.int32("parametric flag", 0, 1) == 1;
      const std::int64_t n = f.count("number of nodes in block", 4, 32);
      if (static_cast<std::int64_t>(coords_.size()) + n > num_nodes)
        in_.fail("node blocks hold more nodes than the " + std::to_string(num_nodes) + " announced");
      const NodeId base = static_cast<NodeId>(coords_.size());
      for (std::int64_t i = 0; i < n; ++i) {
        const std::int64_t tag = f.size("node tag");
        if (tag < tags_.min_tag() || tag > tags_.max_tag())
          in_.fail("node tag " + std::to_string(tag) + " is outside the range " + std::to_string(tags_.min_tag()) +
                   ".." + std::to_string(tags_.max_tag()) + " of the $Nodes header");
        if (!tags_.insert(tag, base + static_cast<NodeId>(i))) in_.fail("duplicate node tag " + std::to_string(tag));
      }
      const int num_params = parametric ? entity_dim : 0;
      for (std::int64_t i = 0; i < n; ++i) {
        std::array<double, 3> x;
        for (double& c : x) c = f.coordinate("node coordinate");
        for (int k = 0; k < num_params; ++k) f.real("parametric coordinate");
        if (std::abs(x[2]) > max_abs_z_) {
          max_abs_z_ = std::abs(x[2]);
          max_abs_z_line_ = in_.line();
        }
        coords_.push_back(x);
      }
    }
    if (static_cast<std::int64_t>(coords_.size()) != num_nodes)
      in_.fail("node blocks hold " + std::to_string(coords_.size()) + " nodes, the $Nodes header announced " +
               std::to_string(num_nodes));
    in_.expect("$EndNodes");
  }

  template <class Fields>
  void read_elements(Fields f) {
    if (!seen_.count("Nodes")) in_.fail("$Elements must come after $Nodes");
    elements_line_ = in_.line();
    f.begin();
    const std::int64_t num_blocks = f.count("number of element blocks", 8, 20);
    const std::int64_t num_elements = f.count("number of elements", 4, 16);
    f.size("minimum element tag");
    f.size("maximum element tag");
    std::int64_t total = 0;
    for (std::int64_t b = 0; b < num_blocks; ++b) {
      RawBlock block;
      block.entity_dim = static_cast<int>(f.int32("entity dimension", 0, 3));
      block.line = in_.line();
      block.entity_tag = f.int32("entity tag");
      const std::int64_t code = f.int32("element type");
      block.type = find_gmsh_type(code);
      if (!block.type) in_.fail("unsupported Gmsh element type " + std::to_string(code));
      if (block.type->dim != block.entity_dim)
        in_.fail("element type " + std::to_string(code) + " has dimension " + std::to_string(block.type->dim) +
                 " but its entity has dimension " + std::to_string(block.entity_dim));
      const int per = block.type->nodes;
      const std::int64_t n = f.count("number of elements in block", 2 * static_cast<std::size_t>(per) + 2,
                                     8 * (static_cast<std::size_t>(per) + 1));
      total += n;
      if (total > num_elements)
        in_.fail("element blocks hold more elements than the " + std::to_string(num_elements) + " announced");
      block.nodes.reserve(static_cast<std::size_t>(n * per));
      for (std::int64_t e = 0; e < n; ++e) {
        f.size("element tag");
        for (int k = 0; k < per; ++k) {
          const std::int64_t tag = f.size("node tag");
          const NodeId id = tags_.find(tag);
          if (id < 0) in_.fail("element refers to unknown node tag " + std::to_string(tag));
          block.nodes.push_back(id);
        }
      }
      blocks_.push_back(std::move(block));
    }
    if (total != num_elements)
      in_.fail("element blocks hold " + std::to_string(total) + " elements, the $Elements header announced " +
               std::to_string(num_elements));
    in_.expect("$EndElements");
  }

  // MSH 2.2: nodes as "id x y z" (binary: an int and three doubles), their count on a text line.
  template <class Fields>
  void read_nodes22(Fields f) {
    if (seen_.count("Elements")) in_.fail("$Nodes must come before $Elements");
    const std::int64_t num_nodes = in_.count("number of nodes", 8);
    if (num_nodes > std::numeric_limits<NodeId>::max()) in_.fail("too many nodes: " + std::to_string(num_nodes));
    f.begin();
    std::vector<std::int64_t> ids(static_cast<std::size_t>(num_nodes));
    coords_.resize(static_cast<std::size_t>(num_nodes));
    for (std::int64_t i = 0; i < num_nodes; ++i) {
      const std::int64_t id = f.int32("node tag", 1, std::numeric_limits<std::int32_t>::max());
      ids[static_cast<std::size_t>(i)] = id;
      std::array<double, 3>& x = coords_[static_cast<std::size_t>(i)];
      for (double& c : x) c = f.coordinate("node coordinate");
      if (std::abs(x[2]) > max_abs_z_) {
        max_abs_z_ = std::abs(x[2]);
        max_abs_z_line_ = in_.line();
      }
    }
    const auto [lo, hi] = std::minmax_element(ids.begin(), ids.end());
    if (num_nodes > 0) tags_.init(num_nodes, *lo, *hi);
    for (std::size_t i = 0; i < ids.size(); ++i)
      if (!tags_.insert(ids[i], static_cast<NodeId>(i))) in_.fail("duplicate node tag " + std::to_string(ids[i]));
    in_.expect("$EndNodes");
  }

  // MSH 2.2: elements as "id type num_tags tags... nodes..." (binary: blocks of one type, each
  // with the header type, count, num_tags, then per element id, tags, nodes, all 4-byte ints).
  // The first tag is the physical group, the second the elementary entity; consecutive elements
  // of one type and group make a block, on an entity keyed by the group (entity_physical_).
  template <class Fields>
  void read_elements22(Fields f) {
    if (!seen_.count("Nodes")) in_.fail("$Elements must come after $Nodes");
    elements_line_ = in_.line();
    const std::int64_t num_elements = in_.count("number of elements", 8);
    f.begin();
    constexpr bool binary = std::is_same_v<Fields, BinaryFields>;
    auto element = [&](std::int64_t code, std::int64_t num_tags) {
      const GmshType* type = find_gmsh_type(code);
      if (!type) in_.fail("unsupported Gmsh element type " + std::to_string(code));
      std::int64_t physical = 0, elementary = 0;
      for (std::int64_t k = 0; k < num_tags; ++k) {
        const std::int64_t t = f.int32("element tag");
        if (k == 0) physical = t;
        if (k == 1) elementary = t;
      }
      // An entity per physical group; elements without one on an entity of their own, named by
      // their elementary tag (entity_<tag>), below every group's key.
      const std::int64_t entity = physical > 0 ? physical : -1 - std::max<std::int64_t>(elementary, 0);
      if (blocks_.empty() || blocks_.back().type != type || blocks_.back().entity_tag != entity) {
        RawBlock b;
        b.line = in_.line();
        b.entity_dim = type->dim;
        b.entity_tag = entity;
        b.type = type;
        blocks_.push_back(std::move(b));
        entity_physical_.emplace(std::make_pair(type->dim, entity), std::max<std::int64_t>(physical, 0));
      }
      RawBlock& b = blocks_.back();
      for (int k = 0; k < type->nodes; ++k) {
        const std::int64_t tag = f.int32("node tag");
        const NodeId id = tags_.find(tag);
        if (id < 0) in_.fail("element refers to unknown node tag " + std::to_string(tag));
        b.nodes.push_back(id);
      }
    };
    std::int64_t done = 0;
    while (done < num_elements) {
      if constexpr (binary) {
        const std::int64_t code = f.int32("element type");
        const std::int64_t n = f.int32("number of elements in block", 1, num_elements - done);
        const std::int64_t num_tags = f.int32("number of tags", 0, 64);
        for (std::int64_t e = 0; e < n; ++e) {
          f.int32("element id");
          element(code, num_tags);
        }
        done += n;
      } else {
        f.int32("element id");
        const std::int64_t code = f.int32("element type");
        element(code, f.int32("number of tags", 0, 64));
        ++done;
      }
    }
    in_.expect("$EndElements");
  }

  // The first physical group of a block's entity (0: none, or no $Entities section).
  std::int64_t entity_physical(const RawBlock& b) {
    if (!v2_ && !seen_.count("Entities")) return 0;
    auto it = entity_physical_.find({b.entity_dim, b.entity_tag});
    if (it == entity_physical_.end())
      in_.fail_at(b.line, "element block refers to entity (dimension " + std::to_string(b.entity_dim) + ", tag " +
                              std::to_string(b.entity_tag) + ") missing from $Entities");
    return it->second;
  }

  // The boundary tag of a facet (or curve) block: from its entity's first physical group.
  template <int Dim>
  int facet_tag(HybridMesh<Dim>& mesh, const RawBlock& b) {
    const std::int64_t physical = entity_physical(b);
    std::string name;
    if (physical == 0) {
      // (MSH 2.2 keys an element without a group by -1 - its elementary tag: read_elements22.)
      name = "entity_" + std::to_string(b.entity_tag >= 0 || !v2_ ? b.entity_tag : -1 - b.entity_tag);
    } else {
      auto it = physical_names_.find({b.entity_dim, physical});
      name = it != physical_names_.end() ? it->second : "physical_" + std::to_string(physical);
    }
    return mesh.add_tag(name, boundary_kind_from_name(name));
  }

  template <int Dim>
  void fill(HybridMesh<Dim>& mesh) {
    mesh.nodes.resize(coords_.size());
    for (std::size_t i = 0; i < coords_.size(); ++i)
      for (int d = 0; d < Dim; ++d) mesh.nodes[i][d] = coords_[i][d];
    // Named physical groups of the facet dimension (and of curves in 3D) first, in physical tag
    // order, so that tags written by write_msh41 come back with the same indices (write_msh41
    // writes no tag without elements, so an empty tag of a mesh does not come back).
    std::vector<std::tuple<std::int64_t, int, const std::string*>> named;
    for (const auto& [key, name] : physical_names_)
      if (key.first == Dim - 1 || (Dim == 3 && key.first == 1)) named.emplace_back(key.second, key.first, &name);
    std::sort(named.begin(), named.end());
    for (const auto& [tag, dim, name] : named) mesh.add_tag(*name, boundary_kind_from_name(*name));
    for (const RawBlock& b : blocks_) {
      if (Dim == 3 && b.type->dim == 1) {
        if (b.type->supported && entity_physical(b) != 0) {
          CellBlock& out = mesh.curve_block(b.type->order, facet_tag(mesh, b));
          out.connectivity.insert(out.connectivity.end(), b.nodes.begin(), b.nodes.end());
        }
        continue;
      }
      if (b.type->dim < Dim - 1) continue;
      if (!b.type->supported)
        in_.fail_at(b.line, "unsupported Gmsh element type " + std::to_string(b.type->code) + " in a " +
                                std::to_string(Dim) +
                                "D mesh (plaf reads Lagrange lines, triangles, "
                                "quadrilaterals, tetrahedra and prisms of order 1..4)");
      CellBlock& out = b.type->dim == Dim ? mesh.block(b.type->type, b.type->order)
                                          : mesh.boundary_block(b.type->type, b.type->order, facet_tag(mesh, b));
      out.connectivity.insert(out.connectivity.end(), b.nodes.begin(), b.nodes.end());
    }
  }

  MshMesh assemble() {
    MshMesh result;
    for (const RawBlock& b : blocks_) result.dim = std::max(result.dim, b.type->dim);
    // Lines alone are a 2D surface mesh (boundary loops without cells).
    if (result.dim == 1) result.dim = 2;
    if (result.dim < 2) in_.fail_at(elements_line_, "no line, 2D or 3D elements in $Elements");
    // Surface elements alone in a file that declares a volume (entity or physical group) are a 3D
    // surface mesh, as write_msh41 writes one (its "domain" volume).
    if (result.dim == 2 && declares_volume_) result.dim = 3;
    if (result.dim == 2) {
      // The mesh must lie in the plane z = 0, up to round-off relative to its extent.
      constexpr double planar_z_tol_rel = 1e-10;
      double extent = 0;
      for (const auto& x : coords_) extent = std::max({extent, std::abs(x[0]), std::abs(x[1])});
      if (max_abs_z_ > planar_z_tol_rel * extent)
        in_.fail_at(max_abs_z_line_, "2D mesh has a node off the plane z = 0 (z = " + std::to_string(max_abs_z_) +
                                         "; a 3D surface mesh must declare a volume entity or physical group)");
      fill(result.mesh2);
    } else {
      fill(result.mesh3);
    }
    return result;
  }

  const std::filesystem::path& path_;
  TextCursor in_;
  std::map<std::string, int> seen_;  // section name -> line
  std::map<std::pair<int, std::int64_t>, std::string> physical_names_;
  std::map<std::pair<int, std::int64_t>, std::int64_t> entity_physical_;  // 0: none
  NodeTagMap tags_;
  std::vector<std::array<double, 3>> coords_;
  std::vector<RawBlock> blocks_;
  int elements_line_ = 0;
  double max_abs_z_ = 0;
  int max_abs_z_line_ = 0;
  bool declares_volume_ = false;  // a volume entity or a physical group of dimension 3
  bool binary_ = false;           // $MeshFormat's file type 1
  bool v2_ = false;               // MSH 2.2 (nodes and elements without entities)
};

}  // namespace

MshMesh read_msh41(const std::filesystem::path& path) {
  const std::string text = read_whole_file(path);
  return MshReader(path, text).read();
}

}  // namespace io
}  // namespace plaf
