// SPDX-License-Identifier: MIT
#include "volume/tetgen_fill.h"

#include <tetgen.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <memory>
#include <sstream>
#include <unordered_map>

#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "modules/base/error.h"
#include "modules/base/format.h"
#include "modules/geometry/predicates.h"

namespace plaf::volume {

namespace {

using Face = std::array<NodeId, 3>;  // sorted node ids

Face sorted_face(NodeId a, NodeId b, NodeId c) {
  Face f{a, b, c};
  std::sort(f.begin(), f.end());
  return f;
}

struct FaceHash {
  std::size_t operator()(const Face& f) const {
    std::uint64_t h = 1469598103934665603ull;
    for (NodeId v : f) h = (h ^ static_cast<std::uint32_t>(v)) * 1099511628211ull;
    return static_cast<std::size_t>(h);
  }
};

using FaceIndex = std::unordered_map<Face, std::size_t, FaceHash>;  // front triangle per sorted face

std::string ids_text(const std::array<NodeId, 3>& t) {
  return "(" + std::to_string(t[0]) + ", " + std::to_string(t[1]) + ", " + std::to_string(t[2]) + ")";
}

// Entry checks of linear_front.h that need no meshing; returns the front's triangles by sorted face.
FaceIndex check_front(const LinearFront<3>& front) {
  const std::size_t n = front.nodes.size();
  if (front.triangles.size() < 4)
    throw InputError("tetgen fill: the front has " + std::to_string(front.triangles.size()) +
                     " triangles, a closed surface needs at least 4");
  if (front.triangle_tag.size() != front.triangles.size())
    throw InputError("tetgen fill: the front has " + std::to_string(front.triangles.size()) + " triangles but " +
                     std::to_string(front.triangle_tag.size()) + " triangle tags");
  FaceIndex faces;
  faces.reserve(front.triangles.size());
  for (std::size_t i = 0; i < front.triangles.size(); ++i) {
    const std::array<NodeId, 3>& t = front.triangles[i];
    for (NodeId v : t) {
      if (v < 0 || static_cast<std::size_t>(v) >= n)
        throw InputError("tetgen fill: front triangle " + std::to_string(i) + " " + ids_text(t) + " refers to node " +
                         std::to_string(v) + " of " + std::to_string(n));
      if (!front.nodes[v].allFinite())
        throw InputError("tetgen fill: node " + std::to_string(v) + " of front triangle " + std::to_string(i) +
                         " has a non-finite coordinate " + point_text(front.nodes[v]));
    }
    if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0])
      throw InputError("tetgen fill: front triangle " + std::to_string(i) + " " + ids_text(t) + " repeats a node");
    const int tag = front.triangle_tag[i];
    if (tag < 0 || static_cast<std::size_t>(tag) >= front.tags.size())
      throw InputError("tetgen fill: front triangle " + std::to_string(i) + " has tag " + std::to_string(tag) + " of " +
                       std::to_string(front.tags.size()));
    const auto [it, fresh] = faces.emplace(sorted_face(t[0], t[1], t[2]), i);
    if (!fresh)
      throw InputError("tetgen fill: front triangles " + std::to_string(it->second) + " and " + std::to_string(i) +
                       " have the same nodes " + ids_text(t));
  }
  for (std::size_t h = 0; h < front.holes.size(); ++h)
    if (!front.holes[h].allFinite())
      throw InputError("tetgen fill: hole point " + std::to_string(h) + " " + point_text(front.holes[h]) +
                       " is not finite");
  return faces;
}

// TetGen's output as it numbers it: 3 coordinates per point, 4 point ids per tet.
struct TetGenOutput {
  std::vector<double> points;
  std::vector<int> tets;
};

static_assert(sizeof(REAL) == sizeof(double));

// Exit statuses of the TetGen process besides TetGen's own codes (1..10, tetgen.h terminatetetgen).
constexpr int exit_write_failed = 120;
constexpr int exit_other_exception = 121;

bool write_all(int fd, const void* data, std::size_t bytes) {
  const char* p = static_cast<const char*>(data);
  while (bytes > 0) {
    const ssize_t n = ::write(fd, p, bytes);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    p += n;
    bytes -= static_cast<std::size_t>(n);
  }
  return true;
}

std::vector<char> read_all(int fd) {
  std::vector<char> bytes;
  std::array<char, 1 << 16> chunk;
  for (;;) {
    const ssize_t n = ::read(fd, chunk.data(), chunk.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    bytes.insert(bytes.end(), chunk.data(), chunk.data() + n);
  }
  return bytes;
}

// The last lines TetGen printed (its only account of why it stopped), on one line.
std::string log_tail(std::FILE* log) {
  if (log == nullptr) return {};
  std::fflush(log);
  std::string text;
  if (std::fseek(log, 0, SEEK_SET) == 0) {
    std::array<char, 4096> chunk;
    std::size_t n;
    while ((n = std::fread(chunk.data(), 1, chunk.size(), log)) > 0) text.append(chunk.data(), n);
  }
  std::string line, tail;
  std::istringstream lines(text);
  while (std::getline(lines, line)) {
    const std::size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos) continue;
    tail += (tail.empty() ? "" : " ") + line.substr(first);
  }
  constexpr std::size_t max_chars = 400;
  if (tail.size() > max_chars) tail = "..." + tail.substr(tail.size() - max_chars);
  return tail.empty() ? "" : "; TetGen said: " + tail;
}

std::string tetgen_failed(const std::string& switches) {
  return "tetgen fill: TetGen failed (switches -" + switches;
}

// The child's side of run_tetgen: TetGen's printing goes to `log`, the mesh to `fd`, and the
// outcome to the exit status (0, TetGen's code, or one of the exit_* above).
[[noreturn]] void tetgen_child(tetgenio& in, const std::string& switches, int fd, std::FILE* log) {
  if (log != nullptr) {
    ::dup2(::fileno(log), STDOUT_FILENO);
    ::dup2(::fileno(log), STDERR_FILENO);
  }
  std::setvbuf(stdout, nullptr, _IONBF, 0);  // what TetGen printed survives a crash
  for (int sig : {SIGSEGV, SIGABRT, SIGBUS, SIGFPE, SIGILL})
    std::signal(sig, SIG_DFL);  // a crash ends the child, not a handler of the parent (a test runner's)
  const rlimit no_core{0, 0};
  ::setrlimit(RLIMIT_CORE, &no_core);  // the crash run_tetgen explains is expected: no core file
  int status = 0;
  try {
    tetgenio out;
    std::string sw = switches;  // tetrahedralize takes a mutable char*
    tetrahedralize(sw.data(), &in, &out);
    const std::array<std::uint64_t, 2> sizes{static_cast<std::uint64_t>(out.numberofpoints),
                                             static_cast<std::uint64_t>(out.numberoftetrahedra)};
    const bool sent = write_all(fd, sizes.data(), sizeof(sizes)) &&
                      write_all(fd, out.pointlist, sizeof(REAL) * 3 * sizes[0]) &&
                      write_all(fd, out.tetrahedronlist, sizeof(int) * 4 * sizes[1]);
    status = sent ? 0 : exit_write_failed;
  } catch (int code) {
    status = code > 0 && code < exit_write_failed ? code : exit_other_exception;
  } catch (...) {
    status = exit_other_exception;
  }
  ::_exit(status);  // no atexit handlers or stdio flushes of the parent's state
}

// The child's end (waitpid's status) as a MesherError, unless it exited with 0.
void check_child_status(int wstatus, const std::string& switches, std::FILE* log) {
  const std::string failed = tetgen_failed(switches);
  if (WIFSIGNALED(wstatus))
    throw MesherError(failed + "; its process died of signal " + std::to_string(WTERMSIG(wstatus)) + ", " +
                      strsignal(WTERMSIG(wstatus)) + " (TetGen 1.5.0 crashes so on every error it detects, most " +
                      "often self-intersecting or touching facets)" + log_tail(log) + ")");
  const int code = WIFEXITED(wstatus) ? WEXITSTATUS(wstatus) : exit_other_exception;
  if (code == exit_write_failed)
    throw MesherError(failed + "; its process could not send the mesh back" + log_tail(log) + ")");
  if (code == exit_other_exception)
    throw MesherError(failed + "; it threw an exception other than its error code" + log_tail(log) + ")");
  if (code != 0)
    throw MesherError("tetgen fill: TetGen failed with code " + std::to_string(code) + " (switches -" + switches +
                      "; 1: out of memory, 2: internal error, 3: self-intersecting facets, 4: a very small input " +
                      "feature, 5: two facets very close, 10: an input error" + log_tail(log) + ")");
}

// The bytes tetgen_child sent: the two sizes, then the points and the tets.
TetGenOutput decode_mesh(const std::vector<char>& bytes, const std::string& switches) {
  std::array<std::uint64_t, 2> sizes{};
  TetGenOutput out;
  if (bytes.size() >= sizeof(sizes)) {
    std::memcpy(sizes.data(), bytes.data(), sizeof(sizes));
    const std::size_t point_bytes = sizeof(double) * 3 * sizes[0], tet_bytes = sizeof(int) * 4 * sizes[1];
    if (bytes.size() == sizeof(sizes) + point_bytes + tet_bytes) {
      out.points.resize(3 * sizes[0]);
      out.tets.resize(4 * sizes[1]);
      std::memcpy(out.points.data(), bytes.data() + sizeof(sizes), point_bytes);
      std::memcpy(out.tets.data(), bytes.data() + sizeof(sizes) + point_bytes, tet_bytes);
      return out;
    }
  }
  throw MesherError(tetgen_failed(switches) + "; its process sent " + std::to_string(bytes.size()) +
                    " bytes, not a mesh)");
}

// Runs TetGen in a child process, which sends the mesh back through a pipe. TetGen 1.5.0 (the
// Debian libtet1.5-dev) cannot fail inside our process: terminatetetgen() frees the mesh's memory
// pools and throws its code, then ~tetgenmesh() frees them again while the exception unwinds
// tetrahedralize() (freememory() leaves its pointers dangling, tetgen.h), and the double free
// kills the process before any catch (inducer/meshpy#21 shows the same backtrace). In the child
// that crash only ends the child: its exit code, or the signal that ended it, and the lines TetGen
// printed (captured from its stdout) become the MesherError.
TetGenOutput run_tetgen(tetgenio& in, const std::string& switches) {
  const std::string failed = tetgen_failed(switches);
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> log(std::tmpfile(), &std::fclose);
  int fds[2];
  if (::pipe(fds) != 0) throw MesherError(failed + "; no pipe to its process: " + std::strerror(errno) + ")");
  std::fflush(stdout);  // or the child would print our pending output a second time
  std::fflush(stderr);
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) {
    const int err = errno;
    ::close(fds[0]);
    ::close(fds[1]);
    throw MesherError(failed + "; could not start its process: " + std::strerror(err) + ")");
  }
  if (pid == 0) {
    // The child dies with the process that waits for it: a SIGTERM or SIGKILL of plaf left
    // TetGen running and allocating for seconds (issue 37, item 4). The parent may have died
    // before the request: then the child is already an orphan and ends now.
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(exit_other_exception);
    ::close(fds[0]);
    tetgen_child(in, switches, fds[1], log.get());
  }
  ::close(fds[1]);
  const std::vector<char> bytes = read_all(fds[0]);
  ::close(fds[0]);
  int wstatus = 0;
  while (::waitpid(pid, &wstatus, 0) < 0)
    if (errno != EINTR) throw MesherError(failed + "; lost its process: " + std::strerror(errno) + ")");
  check_child_status(wstatus, switches, log.get());
  return decode_mesh(bytes, switches);
}

// The front's nodes as TetGen numbers them: the nodes the triangles use, 0..n_used-1 in
// first-use order. Nodes no triangle uses stay out: inside the layers, TetGen would jettison or
// mesh them.
struct PlcNumbering {
  std::vector<int> tetgen_id;    // per front node; -1: no triangle uses it
  std::vector<NodeId> front_id;  // per TetGen input point
};

PlcNumbering number_used_nodes(const LinearFront<3>& front) {
  PlcNumbering ids;
  ids.tetgen_id.assign(front.nodes.size(), -1);
  for (const std::array<NodeId, 3>& t : front.triangles)
    for (NodeId v : t)
      if (ids.tetgen_id[v] < 0) {
        ids.tetgen_id[v] = static_cast<int>(ids.front_id.size());
        ids.front_id.push_back(v);
      }
  return ids;
}

// The piecewise linear complex: the used nodes, one facet per triangle with its tag + 1 as marker,
// and the hole points. tetgenio owns and delete[]s every list below, hence the bare new[] (tetgen.h
// deinitialize); it comes back behind a pointer because its implicit copy is shallow.
std::unique_ptr<tetgenio> build_plc(const LinearFront<3>& front, const PlcNumbering& ids,
                                    const std::vector<double>& node_sizes) {
  const int n_used = static_cast<int>(ids.front_id.size());
  const std::size_t n_tri = front.triangles.size();
  auto in = std::make_unique<tetgenio>();
  in->firstnumber = 0;
  in->numberofpoints = n_used;
  in->pointlist = new REAL[3 * static_cast<std::size_t>(n_used)];
  for (int i = 0; i < n_used; ++i)
    for (int d = 0; d < 3; ++d) in->pointlist[3 * i + d] = front.nodes[ids.front_id[i]][d];
  if (!node_sizes.empty()) {
    in->numberofpointmtrs = 1;
    in->pointmtrlist = new REAL[static_cast<std::size_t>(n_used)];
    for (int i = 0; i < n_used; ++i) in->pointmtrlist[i] = node_sizes[static_cast<std::size_t>(ids.front_id[i])];
  }
  in->facetlist = new tetgenio::facet[n_tri];
  for (std::size_t f = 0; f < n_tri; ++f) tetgenio::init(&in->facetlist[f]);
  in->numberoffacets = static_cast<int>(n_tri);
  in->facetmarkerlist = new int[n_tri];
  for (std::size_t f = 0; f < n_tri; ++f) {
    tetgenio::facet& facet = in->facetlist[f];
    facet.polygonlist = new tetgenio::polygon[1];
    tetgenio::init(&facet.polygonlist[0]);
    facet.numberofpolygons = 1;
    facet.polygonlist[0].vertexlist = new int[3];
    facet.polygonlist[0].numberofvertices = 3;
    for (int k = 0; k < 3; ++k) facet.polygonlist[0].vertexlist[k] = ids.tetgen_id[front.triangles[f][k]];
    in->facetmarkerlist[f] = front.triangle_tag[f] + 1;
  }
  if (!front.holes.empty()) {
    in->holelist = new REAL[3 * front.holes.size()];
    in->numberofholes = static_cast<int>(front.holes.size());
    for (std::size_t h = 0; h < front.holes.size(); ++h)
      for (int d = 0; d < 3; ++d) in->holelist[3 * h + d] = front.holes[h][d];
  }
  return in;
}

// p (PLC, carving from the hole points), Y (no Steiner point on the front), Q (quiet), z (ids from
// 0), J (no jettisoned points, so input ids stay), M0/1 (coplanar facets merged as by default,
// but no two points: TetGen replaces a point within 1e-8 of the box's diagonal of another by it,
// which drops the front's triangles on it; a flange's layers, 4e-7 apart at a bore's rim in a
// farfield 40 wide, lost 11), q/a bounds.
std::string tetgen_switches(const TetFillParams& params) {
  std::ostringstream sw;
  sw << "pYQzJM0/1";
  if (params.max_radius_edge > 0) sw << 'q' << params.max_radius_edge;
  if (params.max_volume > 0) sw << 'a' << params.max_volume;
  if (!params.node_sizes.empty()) sw << 'm';
  return sw.str();
}

// Back to front ids: TetGen keeps its input points first and unchanged (checked), and the points
// it adds become front.nodes.size(), ... in its order.
std::vector<Eigen::Vector3d> output_nodes(const LinearFront<3>& front, const PlcNumbering& ids, const TetGenOutput& out,
                                          const std::string& switches) {
  const int n_used = static_cast<int>(ids.front_id.size());
  const int n_out = static_cast<int>(out.points.size() / 3);
  if (n_out < n_used)
    throw MesherError("tetgen fill: TetGen returned " + std::to_string(n_out) + " points for " +
                      std::to_string(n_used) + " input points (switches -" + switches + ")");
  for (int i = 0; i < n_used; ++i) {
    const Eigen::Vector3d p(out.points[3 * i], out.points[3 * i + 1], out.points[3 * i + 2]);
    if (p != front.nodes[ids.front_id[i]])
      throw MesherError("tetgen fill: TetGen moved or renumbered front node " + std::to_string(ids.front_id[i]) + " " +
                        point_text(front.nodes[ids.front_id[i]]) + " (switches -" + switches + ")");
  }
  std::vector<Eigen::Vector3d> nodes = front.nodes;
  nodes.reserve(front.nodes.size() + static_cast<std::size_t>(n_out - n_used));
  for (int i = n_used; i < n_out; ++i)
    nodes.emplace_back(out.points[3 * i], out.points[3 * i + 1], out.points[3 * i + 2]);
  return nodes;
}

// TetGen's tets on `nodes` (from output_nodes), each checked for positive volume.
std::vector<std::array<NodeId, 4>> output_tets(const std::vector<Eigen::Vector3d>& nodes, std::size_t n_front,
                                               const PlcNumbering& ids, const TetGenOutput& out,
                                               const std::string& switches) {
  const int n_used = static_cast<int>(ids.front_id.size());
  const int n_out = static_cast<int>(out.points.size() / 3);
  auto node_id = [&](int i) {
    if (i < 0 || i >= n_out)
      throw MesherError("tetgen fill: TetGen returned a tet on point " + std::to_string(i) + " of " +
                        std::to_string(n_out) + " (switches -" + switches + ")");
    return i < n_used ? ids.front_id[i] : static_cast<NodeId>(n_front) + static_cast<NodeId>(i - n_used);
  };
  const std::size_t n_tets = out.tets.size() / 4;
  std::vector<std::array<NodeId, 4>> tets;
  tets.reserve(n_tets);
  for (std::size_t t = 0; t < n_tets; ++t) {
    const int* c = out.tets.data() + 4 * t;
    const std::array<NodeId, 4> tet{node_id(c[0]), node_id(c[1]), node_id(c[2]), node_id(c[3])};
    const std::array<Eigen::Vector3d, 4> p{nodes[tet[0]], nodes[tet[1]], nodes[tet[2]], nodes[tet[3]]};
    // TetGen 1.5 orders a tet with vertex 3 on the side of face 0-1-2's right-hand normal, which
    // is plaf's positive volume (predicates.h: orient3d < 0); checked exactly.
    if (sign_orient3d(p[0], p[1], p[2], p[3]) >= 0)
      throw MesherError("tetgen fill: TetGen returned tet " + std::to_string(t) + " with non-positive volume at " +
                        point_text((p[0] + p[1] + p[2] + p[3]) / 4) + " (switches -" + switches + ")");
    tets.push_back(tet);
  }
  return tets;
}

// The contract (tetgen_fill.h): every front triangle is a face of exactly one tet, on the side of
// its normal.
void check_front_preserved(const LinearFront<3>& front, const FaceIndex& front_faces, const TetFillResult& fill) {
  const std::size_t n_tri = front.triangles.size();
  std::vector<int> uses(n_tri, 0);
  std::vector<NodeId> apex(n_tri, -1);  // the vertex of the (last) tet on the triangle opposite it
  for (const std::array<NodeId, 4>& tet : fill.simplices)
    for (int k = 0; k < 4; ++k) {
      const auto it = front_faces.find(sorted_face(tet[(k + 1) % 4], tet[(k + 2) % 4], tet[(k + 3) % 4]));
      if (it == front_faces.end()) continue;
      ++uses[it->second];
      apex[it->second] = tet[k];
    }
  std::size_t missing = 0, doubled = 0, behind = 0, first_missing = 0, first_doubled = 0, first_behind = 0;
  for (std::size_t i = 0; i < n_tri; ++i) {
    const std::array<NodeId, 3>& t = front.triangles[i];
    if (uses[i] == 0) {
      if (missing++ == 0) first_missing = i;
    } else if (uses[i] > 1) {
      if (doubled++ == 0) first_doubled = i;
    } else if (sign_orient3d(front.nodes[t[0]], front.nodes[t[1]], front.nodes[t[2]], fill.nodes[apex[i]]) >= 0) {
      if (behind++ == 0) first_behind = i;
    }
  }
  auto where = [&](std::size_t i) {
    const std::array<NodeId, 3>& t = front.triangles[i];
    return "triangle " + std::to_string(i) + " " + ids_text(t) + " at " +
           point_text((front.nodes[t[0]] + front.nodes[t[1]] + front.nodes[t[2]]) / 3);
  };
  if (missing > 0)
    throw MesherError("tetgen fill: the front was not preserved: " + std::to_string(missing) + " of " +
                      std::to_string(n_tri) + " front triangles are a face of no tet, the first " +
                      where(first_missing) + " (TetGen split it, or a hole point carved the region next to " +
                      "it away; switches -" + fill.stats.switches + ")");
  if (doubled > 0)
    throw InputError("tetgen fill: " + std::to_string(doubled) + " front triangles are a face of two tets, the " +
                     "first " + where(first_doubled) + ": the region on both sides was filled (a body without a " +
                     "hole point inside it, or a surface that bounds no body)");
  if (behind > 0)
    throw InputError("tetgen fill: " + std::to_string(behind) + " front triangles have their tet behind them, " +
                     "the first " + where(first_behind) + ": a front normal must point into the region to fill " +
                     "(linear_front.h), and a hole point must lie inside a body");
}

}  // namespace

std::pair<double, double> tet_shape(const std::array<Eigen::Vector3d, 4>& p) {
  // Normals of the faces opposite each vertex, all pointing at that vertex (inward): the
  // dihedral angle at the edge of faces k and l is pi minus the angle between their normals.
  std::array<Eigen::Vector3d, 4> n;
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d& a = p[(k + 1) % 4];
    const Eigen::Vector3d& b = p[(k + 2) % 4];
    const Eigen::Vector3d& c = p[(k + 3) % 4];
    n[k] = (b - a).cross(c - a);
    if (n[k].dot(p[k] - a) < 0) n[k] = -n[k];
    n[k].normalize();
  }
  // A flat tet (zero volume: its face normals all parallel, their orientation undefined) has a
  // dihedral angle of 0.
  double min_dihedral = (p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0])) == 0 ? 0.0 : std::numbers::pi;
  for (int k = 0; k < 4; ++k)
    for (int l = k + 1; l < 4; ++l)
      min_dihedral = std::min(min_dihedral, std::numbers::pi - std::acos(std::clamp(n[k].dot(n[l]), -1.0, 1.0)));
  // Circumcentre relative to p[0]: (|u|^2 v x w + |v|^2 w x u + |w|^2 u x v) / (2 u . (v x w)).
  const Eigen::Vector3d u = p[1] - p[0], v = p[2] - p[0], w = p[3] - p[0];
  const Eigen::Vector3d centre =
      (u.squaredNorm() * v.cross(w) + v.squaredNorm() * w.cross(u) + w.squaredNorm() * u.cross(v)) /
      (2 * u.dot(v.cross(w)));
  double shortest = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 4; ++k)
    for (int l = k + 1; l < 4; ++l) shortest = std::min(shortest, (p[k] - p[l]).norm());
  return {min_dihedral, centre.norm() / shortest};
}

namespace {

// The stats of tetgen_fill.h, measured on the tets; `n_front` nodes came from the front.
TetFillStats measure_fill(const TetFillResult& fill, std::size_t n_front) {
  double min_dihedral = std::numbers::pi, max_radius_edge = 0;
  for (const std::array<NodeId, 4>& tet : fill.simplices) {
    const auto [dihedral, radius_edge] =
        tet_shape({fill.nodes[tet[0]], fill.nodes[tet[1]], fill.nodes[tet[2]], fill.nodes[tet[3]]});
    min_dihedral = std::min(min_dihedral, dihedral);
    max_radius_edge = std::max(max_radius_edge, radius_edge);
  }
  TetFillStats stats;
  stats.tets = fill.simplices.size();
  stats.new_points = fill.nodes.size() - n_front;
  stats.min_dihedral_deg = fill.simplices.empty() ? 0 : min_dihedral * 180 / std::numbers::pi;
  stats.max_radius_edge = max_radius_edge;
  stats.switches = fill.stats.switches;
  return stats;
}

}  // namespace

TetFillResult tetgen_fill(const LinearFront<3>& front, const TetFillParams& params) {
  // 1. The front, checked at entry; its triangles by sorted face, for step 5.
  const FaceIndex front_faces = check_front(front);
  if (!params.node_sizes.empty()) {
    if (params.node_sizes.size() != front.nodes.size())
      throw InputError("tetgen fill: " + std::to_string(params.node_sizes.size()) + " node sizes for " +
                       std::to_string(front.nodes.size()) + " front nodes");
    for (const std::array<NodeId, 3>& t : front.triangles)
      for (NodeId v : t)
        if (!(params.node_sizes[static_cast<std::size_t>(v)] > 0) || !std::isfinite(params.node_sizes[static_cast<std::size_t>(v)]))
          throw InputError("tetgen fill: the size at front node " + std::to_string(v) + " is not a positive number");
  }

  // 2. The piecewise linear complex: the points the triangles use, one facet per triangle with its
  //    tag + 1 as marker, and the hole points.
  const PlcNumbering ids = number_used_nodes(front);
  const std::unique_ptr<tetgenio> plc = build_plc(front, ids, params.node_sizes);

  // 3. Tetrahedralize, in a child process.
  TetFillResult result;
  result.stats.switches = tetgen_switches(params);
  const TetGenOutput out = run_tetgen(*plc, result.stats.switches);

  // 4. Back to plaf's nodes and tets, with the node-numbering contract and positive volumes checked.
  result.nodes = output_nodes(front, ids, out, result.stats.switches);
  result.simplices = output_tets(result.nodes, front.nodes.size(), ids, out, result.stats.switches);

  // 5. The front was preserved: each front triangle a face of exactly one tet, on its normal's side.
  check_front_preserved(front, front_faces, result);

  // 6. The stats, measured on the tets.
  result.stats = measure_fill(result, front.nodes.size());
  return result;
}

}  // namespace plaf::volume
