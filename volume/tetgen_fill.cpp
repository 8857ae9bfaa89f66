// SPDX-License-Identifier: MIT
#include "volume/tetgen_fill.h"

#include <tetgen.h>

#include <Eigen/Geometry>
#include <sstream>

#include "modules/base/error.h"

namespace plaf::volume {

HybridMesh<3> tetgen_fill(const HybridMesh<3>& boundary, const TetFillParams& params) {
  std::size_t n_tri = 0;
  for (const CellBlock& b : boundary.boundary) {
    if (b.type != CellType::Triangle || b.order != 1)
      throw InputError("tetgen fill: the boundary must be linear triangles, got " + std::string(cell_name(b.type)) +
                       " of order " + std::to_string(b.order));
    for (NodeId v : b.connectivity)
      if (v < 0 || static_cast<std::size_t>(v) >= boundary.nodes.size())
        throw InputError("tetgen fill: a boundary triangle refers to node " + std::to_string(v) + " of " +
                         std::to_string(boundary.nodes.size()));
    n_tri += b.size();
  }
  if (n_tri < 4 || boundary.nodes.size() < 4) throw InputError("tetgen fill: the boundary has fewer than 4 triangles");

  // 1. The piecewise linear complex: one facet per triangle, the tag as facet marker.
  tetgenio in, out;
  in.firstnumber = 0;
  in.numberofpoints = static_cast<int>(boundary.nodes.size());
  in.pointlist = new REAL[3 * boundary.nodes.size()];  // owned and freed by tetgenio
  for (std::size_t i = 0; i < boundary.nodes.size(); ++i)
    for (int d = 0; d < 3; ++d) in.pointlist[3 * i + d] = boundary.nodes[i][d];
  in.numberoffacets = static_cast<int>(n_tri);
  in.facetlist = new tetgenio::facet[n_tri];
  in.facetmarkerlist = new int[n_tri];
  std::size_t f = 0;
  for (const CellBlock& b : boundary.boundary)
    for (std::size_t i = 0; i < b.size(); ++i, ++f) {
      tetgenio::facet& facet = in.facetlist[f];
      tetgenio::init(&facet);
      facet.numberofpolygons = 1;
      facet.polygonlist = new tetgenio::polygon[1];
      tetgenio::init(&facet.polygonlist[0]);
      facet.polygonlist[0].numberofvertices = 3;
      facet.polygonlist[0].vertexlist = new int[3];
      for (int k = 0; k < 3; ++k) facet.polygonlist[0].vertexlist[k] = b.cell(i)[k];
      in.facetmarkerlist[f] = b.tag + 1;
    }

  // 2. Tetrahedralize: p (PLC), Y (no Steiner points on the boundary), Q (quiet), q/a bounds.
  std::ostringstream sw;
  sw << "pYQz";
  if (params.max_radius_edge > 0) sw << 'q' << params.max_radius_edge;
  if (params.max_volume > 0) sw << 'a' << params.max_volume;
  std::string switches = sw.str();
  try {
    tetrahedralize(switches.data(), &in, &out);
  } catch (int code) {
    throw MesherError("tetgen fill: TetGen failed with code " + std::to_string(code) + " (switches -" + switches +
                      "; 2: out of memory, 3: internal error, 4: a very small input feature, 5: two facets " +
                      "very close, 10: an input error such as self-intersecting facets)");
  }

  // 3. Back to core types: TetGen keeps the input points first (switch Y, z numbering).
  HybridMesh<3> mesh;
  mesh.tags = boundary.tags;
  mesh.boundary = boundary.boundary;
  mesh.nodes.resize(static_cast<std::size_t>(out.numberofpoints));
  for (int i = 0; i < out.numberofpoints; ++i)
    mesh.nodes[i] = Eigen::Vector3d(out.pointlist[3 * i], out.pointlist[3 * i + 1], out.pointlist[3 * i + 2]);
  for (std::size_t i = 0; i < boundary.nodes.size(); ++i)
    if ((mesh.nodes[i] - boundary.nodes[i]).norm() != 0)
      throw MesherError("tetgen fill: TetGen renumbered the boundary nodes");
  CellBlock& tets = mesh.block(CellType::Tetrahedron, 1);
  tets.connectivity.reserve(static_cast<std::size_t>(out.numberoftetrahedra) * 4);
  for (int t = 0; t < out.numberoftetrahedra; ++t) {
    const int* c = out.tetrahedronlist + 4 * t;
    // TetGen 1.5's tetrahedra already have positive volume in plaf's convention (vertex 3 on the
    // side of face 0-1-2's right-hand normal); the tests check every volume.
    tets.connectivity.insert(tets.connectivity.end(), {c[0], c[1], c[2], c[3]});
  }
  return mesh;
}

}  // namespace plaf::volume
