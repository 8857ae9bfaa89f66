// SPDX-License-Identifier: MIT
// Surface readers (see read_surface.h).
//
// Triangle files go through OpenMesh's readers into SoupImporter, an importer that only records
// points and polygons: OpenMesh's own mesh importer would refuse non-manifold faces one by one
// (with a log line each), and validation (validate.h) must see them to name them. OpenMesh's
// readers trust their input, though. Measured on OpenMesh 9.0: a non-number in an ASCII STL or
// OFF keeps the previous value or leaves indices uninitialised; an OBJ vertex with a non-number
// or "nan" is silently skipped (shifting every later index); out-of-range face indices pass
// through; a binary STL whose triangle count disagrees with its size is read as ASCII (zero
// triangles); a huge OFF vertex count, an OFF comment or a PLY header token that is not a number
// loops for ever or ends in bad_alloc. So each format gets a structural scan of the text first
// (counts, numbers, index ranges, with the line of the first problem), then OpenMesh reads it,
// then the soup is checked against the scan (counts, index ranges, finite points). The scans
// check the format; OpenMesh still does the reading (in float for STL and OFF coordinates, as
// its readers do). OpenMesh also drops STL facets and OBJ faces with a repeated vertex; they
// would be dropped by validation anyway.
#include "surface3d/read_surface.h"

// MeshIO.hh registers OpenMesh's reader modules with the IOManager.
#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/IO/importer/BaseImporter.hh>
#include <OpenMesh/Core/IO/reader/OFFReader.hh>
#include <OpenMesh/Core/System/omstream.hh>
#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <sstream>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "modules/base/error.h"
#include "modules/io/text_cursor.h"

namespace plaf {
namespace {

namespace fs = std::filesystem;
using Vec3 = Eigen::Vector3d;

[[noreturn]] void fail(const fs::path& path, const std::string& reason) {
  throw InputError(path.string() + ": " + reason);
}

[[noreturn]] void fail_line(const fs::path& path, int line, const std::string& reason) {
  throw InputError(path.string() + ":" + std::to_string(line) + ": " + reason);
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

double bbox_diagonal(const std::vector<Vec3>& points) {
  if (points.empty()) return 0;
  Vec3 lo = points[0], hi = points[0];
  for (const Vec3& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return (hi - lo).norm();
}

// ---------------------------------------------------------------------------------------------
// Point clustering on a hash grid.

// For each point, the index of its cluster's representative: points are taken in order and each
// joins the nearest earlier representative within tol (ties: the lowest index), or becomes one.
// Greedy, so clusters do not chain: two points 1.5 tol apart with one in the middle stay two.
// The cells are at least tol wide, so a partner within tol is in one of the 27 cells around.
std::vector<int> cluster_points(const std::vector<Vec3>& points, double tol) {
  const std::size_t n = points.size();
  std::vector<int> rep(n);
  double extent = 0;
  for (const Vec3& p : points)
    if (p.allFinite()) extent = std::max(extent, p.cwiseAbs().maxCoeff());
  // A floor on the cell size keeps the cell coordinates within 2^40 for any tol (also tol = 0,
  // exact equality).
  const double cell = std::max({tol, extent * 0x1p-40, std::numeric_limits<double>::min()});
  const double tol2 = tol * tol;
  struct KeyHash {
    std::size_t operator()(const std::array<std::int64_t, 3>& k) const {
      const auto h = static_cast<std::uint64_t>(k[0]) * 0x9E3779B97F4A7C15ULL ^
                     static_cast<std::uint64_t>(k[1]) * 0xC2B2AE3D27D4EB4FULL ^
                     static_cast<std::uint64_t>(k[2]) * 0x165667B19E3779F9ULL;
      return static_cast<std::size_t>(h ^ (h >> 29));
    }
  };
  std::unordered_map<std::array<std::int64_t, 3>, std::vector<int>, KeyHash> grid;
  grid.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3& p = points[i];
    rep[i] = static_cast<int>(i);
    if (!p.allFinite()) continue;  // never merged (the readers reject such points before)
    std::array<std::int64_t, 3> key;
    for (int d = 0; d < 3; ++d) key[static_cast<std::size_t>(d)] = static_cast<std::int64_t>(std::floor(p[d] / cell));
    int best = -1;
    double best_d2 = 0;
    for (std::int64_t dx = -1; dx <= 1; ++dx)
      for (std::int64_t dy = -1; dy <= 1; ++dy)
        for (std::int64_t dz = -1; dz <= 1; ++dz) {
          const auto it = grid.find({key[0] + dx, key[1] + dy, key[2] + dz});
          if (it == grid.end()) continue;
          for (const int r : it->second) {
            const Vec3 diff = points[static_cast<std::size_t>(r)] - p;
            // The max-norm test keeps tol = 0 exact where the squared norm of a tiny difference
            // would underflow to zero.
            if (diff.cwiseAbs().maxCoeff() > tol) continue;
            const double d2 = diff.squaredNorm();
            if (d2 > tol2) continue;
            if (best < 0 || d2 < best_d2 || (d2 == best_d2 && r < best)) {
              best = r;
              best_d2 = d2;
            }
          }
        }
    if (best >= 0) {
      rep[i] = best;
    } else {
      grid[key].push_back(static_cast<int>(i));
    }
  }
  return rep;
}

// Renumbers the triangles through rep (old index -> old index of its representative) and keeps
// only the points that triangles use, in the order of their first old index.
void renumber_and_compact(TriangleSoup& soup, const std::vector<int>* rep) {
  std::vector<int> new_index(soup.points.size(), -1);
  for (auto& t : soup.triangles)
    for (int& v : t) {
      if (rep) v = (*rep)[static_cast<std::size_t>(v)];
      new_index[static_cast<std::size_t>(v)] = 0;
    }
  std::vector<Vec3> kept;
  for (std::size_t i = 0; i < soup.points.size(); ++i)
    if (new_index[i] == 0) {
      new_index[i] = static_cast<int>(kept.size());
      kept.push_back(soup.points[i]);
    }
  for (auto& t : soup.triangles)
    for (int& v : t) v = new_index[static_cast<std::size_t>(v)];
  soup.points = std::move(kept);
}

// ---------------------------------------------------------------------------------------------
// Number parsing for the line scans (std::from_chars does not take a leading '+').

bool parse_double(std::string_view t, double& v) {
  if (t.size() > 1 && t[0] == '+') t.remove_prefix(1);
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  return r.ec == std::errc() && r.ptr == t.data() + t.size();
}

bool parse_int(std::string_view t, std::int64_t& v) {
  if (t.size() > 1 && t[0] == '+') t.remove_prefix(1);
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  return r.ec == std::errc() && r.ptr == t.data() + t.size();
}

bool is_blank(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

// The white-space separated tokens of one line.
std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_blank(line[i])) ++i;
    const std::size_t b = i;
    while (i < line.size() && !is_blank(line[i])) ++i;
    if (i > b) out.push_back(line.substr(b, i - b));
  }
  return out;
}

// Calls f(line_number, line) for each line (without its '\n'), numbered from 1.
template <class F>
void for_each_line(std::string_view text, F&& f) {
  int number = 0;
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t e = text.find('\n', pos);
    if (e == std::string_view::npos) e = text.size();
    f(++number, text.substr(pos, e - pos));
    pos = e + 1;
  }
}

// A coordinate that OpenMesh parses as a float (STL, OBJ): a finite number within float range.
void check_coordinate(const fs::path& path, int line, std::string_view t, bool as_float) {
  double v = 0;
  if (!parse_double(t, v)) fail_line(path, line, "bad coordinate " + TextCursor::quote(t));
  if (!std::isfinite(v)) fail_line(path, line, "non-finite coordinate " + TextCursor::quote(t));
  if (as_float && std::abs(v) > std::numeric_limits<float>::max())
    fail_line(path, line, "coordinate " + TextCursor::quote(t) + " is out of float range");
}

void skip_rest_of_line(TextCursor& c, int line) {
  while (!c.at_end() && c.next_line() == line) c.token("a token");
}

// ---------------------------------------------------------------------------------------------
// The structural scans. Each returns what OpenMesh must deliver (-1: not known).

struct Expected {
  std::int64_t vertices = -1;
  std::int64_t faces = -1;
  std::int64_t max_faces = -1;  // STL: OpenMesh drops facets with repeated points
  bool binary = false;          // STL and PLY: the reader's binary mode
};

bool looks_binary(std::string_view text) {
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if ((c < 0x20 && c != '\t' && c != '\n' && c != '\r' && c != '\v' && c != '\f') || c == 0x7f) return true;
  }
  return false;
}

std::uint32_t read_le32(const char* p) {
  std::uint32_t v = 0;
  for (int k = 3; k >= 0; --k) v = (v << 8) | static_cast<unsigned char>(p[k]);
  return v;
}

float read_le_float(const char* p) {
  const std::uint32_t bits = read_le32(p);
  float f;
  std::memcpy(&f, &bits, sizeof f);
  return f;
}

// Binary STL: an 80-byte header, a little-endian uint32 triangle count, 50 bytes per triangle
// (normal, three points, attribute). OpenMesh takes a file whose size is 84 + 50 count for binary
// and anything else for ASCII; here a text file starting with "solid" is ASCII even then.
Expected check_stl(const fs::path& path, std::string& text_to_read) {
  const std::string_view text = text_to_read;
  Expected e;
  const bool binary_bytes = looks_binary(text);
  std::size_t first = 0;
  while (first < text.size() && std::isspace(static_cast<unsigned char>(text[first]))) ++first;
  const bool solid = text.substr(first, 5) == "solid";
  if (binary_bytes || !solid) {
    const std::string not_stl = "not an STL file: neither ASCII (starting with 'solid') nor binary";
    if (text.size() < 84) {
      if (!binary_bytes) fail(path, not_stl);
      fail(path, "truncated binary STL: " + std::to_string(text.size()) + " bytes, less than the 84-byte header");
    }
    const std::uint64_t count = read_le32(text.data() + 80);
    const std::uint64_t size = 84 + 50 * count;
    if (size != text.size()) {
      if (!binary_bytes) fail(path, not_stl);
      fail(path, "binary STL header says " + std::to_string(count) + " triangles (" + std::to_string(size) +
                     " bytes) but the file has " + std::to_string(text.size()) + " bytes");
    }
    for (std::uint64_t t = 0; t < count; ++t)
      for (int k = 3; k < 12; ++k) {
        const float v = read_le_float(text.data() + 84 + 50 * t + 4 * static_cast<std::uint64_t>(k));
        if (!std::isfinite(v))
          fail(path, "triangle " + std::to_string(t + 1) + " has a non-finite coordinate (" + std::to_string(v) + ")");
      }
    e.binary = true;
    e.max_faces = static_cast<std::int64_t>(count);
    return e;
  }
  // ASCII. OpenMesh starts a facet at any line containing "outer" and reads the next three lines
  // as "<word> x y z"; anything else is skipped. The scan requires exactly that shape.
  std::int64_t facets = 0;
  int vertex_lines_due = 0;
  int outer_line = 0;
  for_each_line(text, [&](int number, std::string_view line) {
    const auto tokens = split(line);
    if (vertex_lines_due > 0) {
      if (tokens.empty() || lower(std::string(tokens[0])) != "vertex")
        fail_line(path, number,
                  "expected 'vertex x y z' (line " + std::to_string(4 - vertex_lines_due) +
                      " of the loop opened on line " + std::to_string(outer_line) + ")");
      if (tokens.size() != 4)
        fail_line(path, number, "a vertex needs 3 coordinates, found " + std::to_string(tokens.size() - 1));
      for (std::size_t k = 1; k < 4; ++k) check_coordinate(path, number, tokens[k], true);
      --vertex_lines_due;
      return;
    }
    if (line.find("outer") != std::string_view::npos || line.find("OUTER") != std::string_view::npos) {
      const std::string keyword = tokens.empty() ? "" : lower(std::string(tokens[0]));
      if (keyword == "solid" || keyword == "endsolid") {
        // A solid's name ("solid outer_mold_line") would start a facet: blank it for OpenMesh.
        const auto begin = static_cast<std::size_t>(tokens[0].data() + tokens[0].size() - text.data());
        const auto end = static_cast<std::size_t>(line.data() + line.size() - text.data());
        std::fill(text_to_read.begin() + static_cast<std::ptrdiff_t>(begin),
                  text_to_read.begin() + static_cast<std::ptrdiff_t>(end), ' ');
        return;
      }
      if (keyword != "outer")
        fail_line(path, number, "'outer' in a line that is not 'outer loop' (the STL reader would start a facet)");
      vertex_lines_due = 3;
      outer_line = number;
      ++facets;
      return;
    }
    if (!tokens.empty() && lower(std::string(tokens[0])) == "vertex")
      fail_line(path, number, "'vertex' outside an 'outer loop'");
  });
  if (vertex_lines_due > 0) fail_line(path, outer_line, "unexpected end of file in the loop opened here");
  e.max_faces = facets;
  return e;
}

// OBJ: "v x y z [w | r g b]" and "f i[/t][/n] ..." (1-based, negative: relative to the vertices
// read so far); every other line is skipped, as OpenMesh does.
Expected check_obj(const fs::path& path, std::string_view text) {
  std::int64_t vertices = 0, faces = 0;
  std::int64_t max_index = 0;
  int max_index_line = 0;
  for_each_line(text, [&](int number, std::string_view line) {
    const auto tokens = split(line);
    if (tokens.empty()) return;
    if (tokens[0] == "v") {
      if (tokens.size() < 4)
        fail_line(path, number, "a vertex needs 3 coordinates, found " + std::to_string(tokens.size() - 1));
      for (std::size_t k = 1; k < 4; ++k) check_coordinate(path, number, tokens[k], false);
      ++vertices;
    } else if (tokens[0] == "f") {
      if (tokens.size() < 4)
        fail_line(path, number, "a face needs at least 3 vertices, found " + std::to_string(tokens.size() - 1));
      for (std::size_t k = 1; k < tokens.size(); ++k) {
        const std::string_view t = tokens[k].substr(0, tokens[k].find('/'));
        std::int64_t i = 0;
        if (!parse_int(t, i) || i == 0)
          fail_line(path, number, "bad face vertex index " + TextCursor::quote(tokens[k]));
        if (i < 0 && vertices + i < 0)
          fail_line(path, number,
                    "face vertex index " + std::to_string(i) + " is out of range (" + std::to_string(vertices) +
                        " vertices so far)");
        if (i > max_index) {
          max_index = i;
          max_index_line = number;
        }
      }
      ++faces;
    }
  });
  if (max_index > vertices)
    fail_line(path, max_index_line,
              "face vertex index " + std::to_string(max_index) + " is out of range 1.." + std::to_string(vertices));
  Expected e;
  e.vertices = vertices;
  e.max_faces = faces;  // OpenMesh drops faces with a repeated vertex
  return e;
}

// ASCII OFF: "[ST][C][N]OFF" at the very start, then "nv nf ne", nv vertex lines starting with
// x y z (then normal, color and texture values in the variants), nf faces "n i1 .. in" (then a
// color on the line in the C variants). OpenMesh reads the header as the first line, the rest as
// a stream of numbers (colors as the rest of a line), and knows no comments: read_surface_file
// blanks '#' comments before handing the text over.
Expected check_off(const fs::path& path, std::string_view text) {
  TextCursor c(path, text, true);
  const std::string header(c.token("the OFF header"));
  if (text.substr(0, header.size()) != header || header.size() < 3 || header.compare(header.size() - 3, 3, "OFF") != 0)
    c.fail("not an OFF file: it does not start with OFF");
  const std::string prefix = header.substr(0, header.size() - 3);
  if (prefix.find_first_of("4n") != std::string::npos)
    c.fail("OFF variant " + TextCursor::quote(header) + " (not 3D) is not supported");
  if (!c.at_end() && c.next_line() == 1 && c.peek() == "BINARY")
    c.fail("binary OFF is not supported (use ASCII OFF, PLY or STL)");
  if (prefix != "" && prefix != "C" && prefix != "N" && prefix != "CN" && prefix != "ST" && prefix != "STC" &&
      prefix != "STN" && prefix != "STCN")
    c.fail("unknown OFF variant " + TextCursor::quote(header));
  const bool face_colors = prefix.find('C') != std::string::npos;
  const std::int64_t nv = c.count("vertex count", 6);
  const std::int64_t nf = c.count("face count", 8);
  c.integer("edge count");
  const auto coordinate = [&c](const char* what) {
    const double v = c.real(what);
    if (std::abs(v) > std::numeric_limits<float>::max()) c.fail(std::string(what) + " out of float range");
  };
  for (std::int64_t v = 0; v < nv; ++v) {
    for (int k = 0; k < 3; ++k) coordinate("vertex coordinate");
    skip_rest_of_line(c, c.line());
  }
  for (std::int64_t f = 0; f < nf; ++f) {
    const std::int64_t n = c.integer("face size");
    if (n < 3) c.fail("face " + std::to_string(f) + " has " + std::to_string(n) + " vertices (at least 3)");
    for (std::int64_t k = 0; k < n; ++k) c.integer("face vertex index", 0, nv - 1);
    const int line = c.line();
    if (face_colors) {
      skip_rest_of_line(c, line);
    } else if (!c.at_end() && c.next_line() == line) {
      c.fail("unexpected " + TextCursor::quote(c.peek()) + " after face " + std::to_string(f) +
             " (face colors need the COFF header)");
    }
  }
  if (!c.at_end()) c.fail("unexpected " + TextCursor::quote(c.peek()) + " after the last face");
  Expected e;
  e.vertices = nv;
  e.faces = nf;
  return e;
}

// '#' to the end of the line becomes blanks (the lines stay where they are).
void blank_comments(std::string& text) {
  bool comment = false;
  for (char& ch : text) {
    if (ch == '\n')
      comment = false;
    else if (ch == '#')
      comment = true;
    if (comment) ch = ' ';
  }
}

// PLY: "ply", "format <ascii|binary_little_endian|binary_big_endian> <version>", then comments,
// elements with their counts and properties, "end_header". OpenMesh parses the header token by
// token and loops for ever on a token it cannot parse (a count or version that is not a number,
// a missing end_header), so the scan is strict there. The body is then walked value by value
// (ASCII tokens or binary bytes): counts, finite coordinates, face lists of >= 3 vertices in range.
struct PlyType {
  int bytes = 0;  // 0: unknown type
  bool integral = false;
  bool is_signed = false;
};

PlyType ply_type(std::string_view t) {
  if (t == "char" || t == "int8") return {1, true, true};
  if (t == "uchar" || t == "uint8") return {1, true, false};
  if (t == "short" || t == "int16") return {2, true, true};
  if (t == "ushort" || t == "uint16") return {2, true, false};
  if (t == "int" || t == "int32") return {4, true, true};
  if (t == "uint" || t == "uint32") return {4, true, false};
  if (t == "float" || t == "float32") return {4, false, true};
  if (t == "double" || t == "float64") return {8, false, true};
  return {};
}

double ply_binary_value(const char* p, const PlyType& t, bool big_endian) {
  unsigned char b[8];
  for (int k = 0; k < t.bytes; ++k) b[k] = static_cast<unsigned char>(p[big_endian ? t.bytes - 1 - k : k]);
  std::uint64_t u = 0;
  for (int k = t.bytes - 1; k >= 0; --k) u = (u << 8) | b[k];
  if (!t.integral) {
    if (t.bytes == 4) {
      float f;
      const auto u32 = static_cast<std::uint32_t>(u);
      std::memcpy(&f, &u32, 4);
      return f;
    }
    double d;
    std::memcpy(&d, &u, 8);
    return d;
  }
  if (t.is_signed && t.bytes < 8 && (u >> (8 * t.bytes - 1)) != 0) {
    return static_cast<double>(static_cast<std::int64_t>(u) - (std::int64_t{1} << (8 * t.bytes)));
  }
  return static_cast<double>(u);
}

Expected check_ply(const fs::path& path, std::string_view text) {
  struct Property {
    std::string name;
    bool list = false;
    PlyType count_type;  // list only
    PlyType type;        // value, or list item
  };
  struct Element {
    std::string name;
    std::int64_t count = 0;
    int line = 0;
    std::vector<Property> props;
  };
  TextCursor c(path, text);
  const std::size_t first_eol = text.find('\n');
  std::string_view first = text.substr(0, first_eol);
  while (!first.empty() && is_blank(first.back())) first.remove_suffix(1);
  if (first != "ply" && first != "PLY") c.fail("not a PLY file: the first line is not 'ply'");
  c.token("ply");
  const auto rest_must_be_empty = [&c](int line) {
    if (!c.at_end() && c.next_line() == line) c.fail("unexpected " + TextCursor::quote(c.peek()));
  };
  int line = c.next_line();
  c.expect("format");
  const std::string format(c.token("the PLY format"));
  if (format != "ascii" && format != "binary_little_endian" && format != "binary_big_endian")
    c.fail("unknown PLY format " + TextCursor::quote(format));
  c.real("PLY version");
  rest_must_be_empty(line);
  std::vector<Element> elements;
  for (;;) {
    line = c.next_line();
    const std::string_view kw = c.token("end_header");
    if (kw == "comment") {
      skip_rest_of_line(c, line);
      continue;
    }
    if (kw == "element") {
      Element el;
      el.name = c.token("an element name");
      el.count = c.integer("element count", 0, std::numeric_limits<std::uint32_t>::max());
      el.line = line;
      elements.push_back(el);
    } else if (kw == "property") {
      if (elements.empty()) c.fail("property before any element");
      Property p;
      std::string_view type = c.token("a property type");
      if (type == "list") {
        p.list = true;
        const std::string_view count_type = c.token("the list count type");
        // The counts OpenMesh reads.
        if (count_type != "uchar" && count_type != "uint8" && count_type != "uint16" && count_type != "int")
          c.fail("unsupported list count type " + TextCursor::quote(count_type) + " (uchar, uint8, uint16 or int)");
        p.count_type = ply_type(count_type);
        type = c.token("the list item type");
      }
      p.type = ply_type(type);
      if (p.type.bytes == 0) c.fail("unknown property type " + TextCursor::quote(type));
      p.name = c.token("a property name");
      elements.back().props.push_back(p);
    } else if (kw == "end_header") {
      rest_must_be_empty(line);
      break;
    } else {
      c.fail("unknown PLY header keyword " + TextCursor::quote(kw));
    }
    rest_must_be_empty(line);
  }
  Expected e;
  std::int64_t nv = 0;
  for (const Element& el : elements) {
    if (el.props.empty() && el.count > 0) c.fail_at(el.line, "element " + el.name + " has no properties");
    if (el.name == "vertex") e.vertices = nv = el.count;
    if (el.name == "face") e.faces = el.count;
  }
  const auto is_face_list = [](const Element& el, const Property& p) {
    return el.name == "face" && p.list && (p.name == "vertex_indices" || p.name == "vertex_index");
  };
  const auto is_coordinate = [](const Element& el, const Property& p) {
    return el.name == "vertex" && !p.list && (p.name == "x" || p.name == "y" || p.name == "z");
  };
  if (format == "ascii") {
    for (const Element& el : elements) {
      if (static_cast<std::uint64_t>(el.count) > c.remaining() / (2 * el.props.size() + 1) + 1)
        c.fail_at(el.line, "element " + el.name + " count " + std::to_string(el.count) +
                               " exceeds what the rest of the file can hold (truncated file?)");
      for (std::int64_t i = 0; i < el.count; ++i)
        for (const Property& p : el.props) {
          if (!p.list) {
            if (is_coordinate(el, p)) {
              c.real("vertex coordinate");
            } else {
              double ignored = 0;
              const std::string_view t = c.token("a property value");
              if (!parse_double(t, ignored)) c.fail("bad " + p.name + " value " + TextCursor::quote(t));
            }
            continue;
          }
          const std::int64_t n = c.integer("list count", 0, static_cast<std::int64_t>(c.remaining() / 2 + 1));
          if (is_face_list(el, p) && n < 3)
            c.fail(el.name + " " + std::to_string(i) + " has " + std::to_string(n) + " vertices (at least 3)");
          for (std::int64_t k = 0; k < n; ++k) {
            if (is_face_list(el, p)) {
              c.integer("face vertex index", 0, nv - 1);
            } else {
              double ignored = 0;
              const std::string_view t = c.token("a list item");
              if (!parse_double(t, ignored)) c.fail("bad " + p.name + " item " + TextCursor::quote(t));
            }
          }
        }
    }
    if (!c.at_end()) c.fail("unexpected " + TextCursor::quote(c.peek()) + " after the last element");
    return e;
  }
  // Binary: the body starts after the end_header line.
  const bool big = format == "binary_big_endian";
  std::size_t pos = text.find('\n', text.find("end_header")) + 1;
  const auto truncated = [&](const Element& el, std::int64_t i) {
    fail(path, "truncated binary PLY: the file ends in " + el.name + " " + std::to_string(i) + " of " +
                   std::to_string(el.count));
  };
  for (const Element& el : elements)
    for (std::int64_t i = 0; i < el.count; ++i)
      for (const Property& p : el.props) {
        if (!p.list) {
          if (text.size() - pos < static_cast<std::size_t>(p.type.bytes)) truncated(el, i);
          if (is_coordinate(el, p) && !std::isfinite(ply_binary_value(text.data() + pos, p.type, big)))
            fail(path, "vertex " + std::to_string(i) + " has a non-finite " + p.name);
          pos += static_cast<std::size_t>(p.type.bytes);
          continue;
        }
        if (text.size() - pos < static_cast<std::size_t>(p.count_type.bytes)) truncated(el, i);
        const double n = ply_binary_value(text.data() + pos, p.count_type, big);
        pos += static_cast<std::size_t>(p.count_type.bytes);
        if (n < 0) fail(path, el.name + " " + std::to_string(i) + " has a negative list count");
        if (is_face_list(el, p) && n < 3)
          fail(path, "face " + std::to_string(i) + " has " + std::to_string(static_cast<std::int64_t>(n)) +
                         " vertices (at least 3)");
        if (n * p.type.bytes > static_cast<double>(text.size() - pos)) truncated(el, i);
        const auto items = static_cast<std::size_t>(n);
        if (is_face_list(el, p))
          for (std::size_t k = 0; k < items; ++k) {
            const double v =
                ply_binary_value(text.data() + pos + k * static_cast<std::size_t>(p.type.bytes), p.type, big);
            if (!(v >= 0 && v < static_cast<double>(nv)))
              fail(path, "face " + std::to_string(i) + " refers to vertex " +
                             std::to_string(static_cast<std::int64_t>(v)) + " of " + std::to_string(nv));
          }
        pos += items * static_cast<std::size_t>(p.type.bytes);
      }
  if (pos != text.size())
    fail(path, "unexpected " + std::to_string(text.size() - pos) + " bytes after the last element of the binary PLY");
  e.binary = true;
  return e;
}

// ---------------------------------------------------------------------------------------------
// OpenMesh.

// Turns OpenMesh's log streams off while it reads (its messages are replaced by ours).
class QuietOpenMesh {
 public:
  QuietOpenMesh() : err_(omerr().is_enabled()), log_(omlog().is_enabled()), out_(omout().is_enabled()) {
    omerr().disable();
    omlog().disable();
    omout().disable();
  }
  ~QuietOpenMesh() {
    if (err_) omerr().enable();
    if (log_) omlog().enable();
    if (out_) omout().enable();
  }
  QuietOpenMesh(const QuietOpenMesh&) = delete;
  QuietOpenMesh& operator=(const QuietOpenMesh&) = delete;

 private:
  bool err_, log_, out_;
};

// Records points and polygons as the readers deliver them; everything else is ignored.
class SoupImporter final : public OpenMesh::IO::BaseImporter {
 public:
  using VertexHandle = OpenMesh::VertexHandle;
  using FaceHandle = OpenMesh::FaceHandle;
  using HalfedgeHandle = OpenMesh::HalfedgeHandle;
  using EdgeHandle = OpenMesh::EdgeHandle;
  using Vec2f = OpenMesh::Vec2f;
  using Vec3f = OpenMesh::Vec3f;
  using Vec3d = OpenMesh::Vec3d;
  using Vec4f = OpenMesh::Vec4f;
  using Vec3uc = OpenMesh::Vec3uc;
  using Vec4uc = OpenMesh::Vec4uc;
  using Status = OpenMesh::Attributes::StatusInfo;

  std::vector<Vec3> points;
  std::vector<std::vector<int>> faces;

  VertexHandle add_vertex(const Vec3f& p) override { return add(Vec3(p[0], p[1], p[2])); }
  VertexHandle add_vertex(const Vec3d& p) override { return add(Vec3(p[0], p[1], p[2])); }
  VertexHandle add_vertex() override { return add(Vec3::Zero()); }
  void set_point(VertexHandle v, const Vec3f& p) override {
    if (v.is_valid() && static_cast<std::size_t>(v.idx()) < points.size())
      points[static_cast<std::size_t>(v.idx())] = Vec3(p[0], p[1], p[2]);
  }
  FaceHandle add_face(const VHandles& vs) override {
    std::vector<int> f;
    f.reserve(vs.size());
    for (const VertexHandle& v : vs) f.push_back(v.idx());
    faces.push_back(std::move(f));
    return FaceHandle(static_cast<int>(faces.size() - 1));
  }
  std::size_t n_vertices() const override { return points.size(); }
  std::size_t n_faces() const override { return faces.size(); }
  std::size_t n_edges() const override { return 0; }

  // Half-edge level construction is used only by OpenMesh's own .om format, which is not read.
  HalfedgeHandle add_edge(VertexHandle, VertexHandle) override { return HalfedgeHandle(); }
  FaceHandle add_face(HalfedgeHandle) override { return FaceHandle(); }
  void set_halfedge(VertexHandle, HalfedgeHandle) override {}
  void set_next(HalfedgeHandle, HalfedgeHandle) override {}
  void set_face(HalfedgeHandle, FaceHandle) override {}

  void add_face_texcoords(FaceHandle, VertexHandle, const std::vector<Vec2f>&) override {}
  void add_face_texcoords(FaceHandle, VertexHandle, const std::vector<Vec3f>&) override {}
  void set_face_texindex(FaceHandle, int) override {}
  void set_normal(VertexHandle, const Vec3f&) override {}
  void set_normal(VertexHandle, const Vec3d&) override {}
  void set_color(VertexHandle, const Vec3uc&) override {}
  void set_color(VertexHandle, const Vec4uc&) override {}
  void set_color(VertexHandle, const Vec3f&) override {}
  void set_color(VertexHandle, const Vec4f&) override {}
  void set_texcoord(VertexHandle, const Vec2f&) override {}
  void set_texcoord(VertexHandle, const Vec3f&) override {}
  void set_texcoord(HalfedgeHandle, const Vec2f&) override {}
  void set_texcoord(HalfedgeHandle, const Vec3f&) override {}
  void set_status(VertexHandle, const Status&) override {}
  void set_status(HalfedgeHandle, const Status&) override {}
  void set_status(EdgeHandle, const Status&) override {}
  void set_status(FaceHandle, const Status&) override {}
  void request_face_texcoords2D() override {}
  void set_color(EdgeHandle, const Vec3uc&) override {}
  void set_color(EdgeHandle, const Vec4uc&) override {}
  void set_color(EdgeHandle, const Vec3f&) override {}
  void set_color(EdgeHandle, const Vec4f&) override {}
  void set_normal(FaceHandle, const Vec3f&) override {}
  void set_normal(FaceHandle, const Vec3d&) override {}
  void set_color(FaceHandle, const Vec3uc&) override {}
  void set_color(FaceHandle, const Vec4uc&) override {}
  void set_color(FaceHandle, const Vec3f&) override {}
  void set_color(FaceHandle, const Vec4f&) override {}
  void add_texture_information(int, std::string) override {}
  // The readers' size hints come from the file's header; the scans have checked them, but
  // nothing is reserved from them anyway.
  void reserve(unsigned int, unsigned int, unsigned int) override {}

 private:
  VertexHandle add(const Vec3& p) {
    points.push_back(p);
    return VertexHandle(static_cast<int>(points.size() - 1));
  }
};

// Reads `text` (the contents of `path`) with OpenMesh's reader for `ext` and checks the result
// against the scan: counts, then indices and coordinates.
TriangleSoup read_with_openmesh(const fs::path& path, const std::string& ext, const std::string& text,
                                const Expected& expected) {
  SoupImporter importer;
  bool ok = false;
  try {
    const QuietOpenMesh quiet;
    // The OFF reader takes the header's variant (colors, normals, texture coordinates) from its
    // can_u_read(file name), which a read from a stream does not call: without it the variant of
    // the previous OFF file would be used.
    if (ext == "off" && !OpenMesh::IO::OFFReader().can_u_read(path.string()))
      fail(path, "the OpenMesh off reader does not accept the header");
    std::istringstream in(text, std::ios::binary);
    OpenMesh::IO::Options options;
    if (expected.binary) options += OpenMesh::IO::Options::Binary;
    ok = OpenMesh::IO::IOManager().read(in, ext, importer, options);
  } catch (const std::exception& e) {
    fail(path, std::string("the OpenMesh reader failed: ") + e.what());
  }
  if (!ok) fail(path, "the OpenMesh " + ext + " reader could not read the file");
  const std::size_t nv = importer.points.size(), nf = importer.faces.size();
  if (expected.vertices >= 0 && nv != static_cast<std::size_t>(expected.vertices))
    fail(path, "the OpenMesh reader delivered " + std::to_string(nv) + " vertices, the file has " +
                   std::to_string(expected.vertices));
  if (expected.faces >= 0 && nf != static_cast<std::size_t>(expected.faces))
    fail(path, "the OpenMesh reader delivered " + std::to_string(nf) + " faces, the file has " +
                   std::to_string(expected.faces));
  if (expected.max_faces >= 0 && nf > static_cast<std::size_t>(expected.max_faces))
    fail(path, "the OpenMesh reader delivered " + std::to_string(nf) + " faces, the file has " +
                   std::to_string(expected.max_faces));
  for (std::size_t v = 0; v < nv; ++v)
    if (!importer.points[v].allFinite()) fail(path, "vertex " + std::to_string(v) + " has a non-finite coordinate");
  TriangleSoup soup;
  soup.source = path.string();
  soup.points = std::move(importer.points);
  for (std::size_t f = 0; f < nf; ++f) {
    const std::vector<int>& poly = importer.faces[f];
    if (poly.size() < 3) fail(path, "face " + std::to_string(f) + " has " + std::to_string(poly.size()) + " vertices");
    for (const int v : poly)
      if (v < 0 || static_cast<std::size_t>(v) >= nv)
        fail(path,
             "face " + std::to_string(f) + " refers to vertex " + std::to_string(v) + " of " + std::to_string(nv));
    // A fan from the polygon's first vertex keeps its orientation.
    for (std::size_t k = 1; k + 1 < poly.size(); ++k) soup.triangles.push_back({poly[0], poly[k], poly[k + 1]});
  }
  return soup;
}

}  // namespace

// ---------------------------------------------------------------------------------------------

std::size_t weld_points(TriangleSoup& soup, double tol) {
  const std::size_t before = soup.points.size();
  const std::vector<int> rep = cluster_points(soup.points, std::max(tol, 0.0));
  renumber_and_compact(soup, &rep);
  return before - soup.points.size();
}

TriangleSoup read_plot3d(const fs::path& path, const ReadSurfaceOptions& options) {
  const std::string text = read_whole_file(path);
  if (text.empty()) fail(path, "the file is empty");
  TextCursor c(path, text);
  const std::int64_t nblocks = c.count("block count", 18);
  if (nblocks == 0) c.fail("no blocks");
  struct Block {
    std::int64_t ni, nj;
    std::size_t first;  // index of its first point
  };
  std::vector<Block> blocks(static_cast<std::size_t>(nblocks));
  std::size_t total = 0;
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    const std::int64_t ni = c.integer("ni", 1, std::numeric_limits<int>::max());
    const std::int64_t nj = c.integer("nj", 1, std::numeric_limits<int>::max());
    const std::int64_t nk = c.integer("nk", 1, std::numeric_limits<int>::max());
    if (nk != 1)
      c.fail("block " + std::to_string(b + 1) + " has nk = " + std::to_string(nk) + ": a surface grid has nk = 1");
    // Each value takes at least two characters ("0 ").
    if (static_cast<std::uint64_t>(ni) * static_cast<std::uint64_t>(nj) > text.size() / 6 + 1)
      c.fail("block " + std::to_string(b + 1) + " of " + std::to_string(ni) + " x " + std::to_string(nj) +
             " points exceeds what the file can hold (truncated file?)");
    blocks[b] = {ni, nj, total};
    total += static_cast<std::size_t>(ni * nj);
  }
  if (total > text.size() / 6 + 1)
    c.fail("the blocks' " + std::to_string(total) + " points exceed what the file can hold");
  std::vector<Vec3> raw(total);
  static constexpr const char* axis_name[3] = {"x coordinate", "y coordinate", "z coordinate"};
  for (const Block& bl : blocks) {
    const auto n = static_cast<std::size_t>(bl.ni * bl.nj);
    for (int d = 0; d < 3; ++d)
      for (std::size_t k = 0; k < n; ++k) raw[bl.first + k][d] = c.real(axis_name[d]);
  }
  if (!c.at_end())
    c.fail("unexpected " + TextCursor::quote(c.peek()) + " after the last block (IBLANK is not supported)");

  // Coincident nodes on block interfaces (and at poles or collapsed block edges) become one.
  const std::vector<int> rep = cluster_points(raw, options.weld_rel * bbox_diagonal(raw));
  TriangleSoup soup;
  soup.source = path.string();
  soup.points = raw;
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    const Block& bl = blocks[b];
    const auto node = [&](std::int64_t i, std::int64_t j) {
      return rep[bl.first + static_cast<std::size_t>(j * bl.ni + i)];
    };
    for (std::int64_t j = 0; j + 1 < bl.nj; ++j)
      for (std::int64_t i = 0; i + 1 < bl.ni; ++i) {
        // The quad in i, j order (outward in these files); both triangles keep its orientation.
        const std::array<int, 4> q = {node(i, j), node(i + 1, j), node(i + 1, j + 1), node(i, j + 1)};
        const auto at = [&](int k) -> const Vec3& {
          return raw[static_cast<std::size_t>(q[static_cast<std::size_t>(k)])];
        };
        std::array<std::array<int, 3>, 2> tris;
        if ((at(2) - at(0)).squaredNorm() <= (at(3) - at(1)).squaredNorm()) {
          tris = {{{q[0], q[1], q[2]}, {q[0], q[2], q[3]}}};
        } else {
          tris = {{{q[0], q[1], q[3]}, {q[1], q[2], q[3]}}};
        }
        for (const auto& t : tris) {
          // A collapsed quad (merged corners) leaves a triangle with a repeated node: no area.
          if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;
          soup.triangles.push_back(t);
          soup.patch.push_back(static_cast<int>(b));
        }
      }
  }
  renumber_and_compact(soup, nullptr);
  if (soup.triangles.empty()) fail(path, "no triangles (every block is a line or collapsed)");
  return soup;
}

TriangleSoup read_surface_file(const fs::path& path, const ReadSurfaceOptions& options) {
  const std::string ext = lower(path.extension().string());
  const bool plot3d = ext == ".fmt" || ext == ".p3d";
  if (!plot3d && ext != ".stl" && ext != ".obj" && ext != ".off" && ext != ".ply")
    fail(path, "unknown surface format " + TextCursor::quote(ext.empty() ? path.filename().string() : ext) +
                   " (expected .stl, .obj, .off, .ply, .fmt or .p3d)");
  std::error_code ec;
  if (!fs::exists(path, ec)) fail(path, "no such file");
  if (!fs::is_regular_file(path, ec)) fail(path, "not a regular file");
  if (plot3d) return read_plot3d(path, options);

  std::string text = read_whole_file(path);
  if (text.empty()) fail(path, "the file is empty");
  Expected expected;
  if (ext == ".stl") expected = check_stl(path, text);
  if (ext == ".obj") expected = check_obj(path, text);
  if (ext == ".off") {
    expected = check_off(path, text);
    blank_comments(text);
  }
  if (ext == ".ply") expected = check_ply(path, text);
  TriangleSoup soup = read_with_openmesh(path, ext.substr(1), text, expected);
  if (soup.triangles.empty()) fail(path, "no triangles");
  if (ext == ".stl") {
    // OpenMesh has merged exactly equal points already; close ones are merged here.
    weld_points(soup, options.weld_rel * bbox_diagonal(soup.points));
  } else {
    // Indexed formats keep their vertices as given; unreferenced ones are dropped.
    renumber_and_compact(soup, nullptr);
  }
  return soup;
}

}  // namespace plaf
