// SPDX-License-Identifier: MIT
// The structural scans of STL, OBJ, OFF and PLY files (see read_surface_detail.h). OpenMesh's
// readers trust their input. Measured on OpenMesh 9.0: a non-number in an ASCII STL or OFF keeps
// the previous value or leaves indices uninitialised; an OBJ vertex with a non-number or "nan" is
// silently skipped (shifting every later index); out-of-range face indices pass through; a binary
// STL whose triangle count disagrees with its size is read as ASCII (zero triangles); a huge OFF
// vertex count, an OFF comment or a PLY header token that is not a number loops for ever or ends
// in bad_alloc. So each format gets a scan of the text first (counts, numbers, index ranges, with
// the line of the first problem); the scans check the format, OpenMesh still does the reading.
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>

#include "modules/io/text_cursor.h"
#include "surface3d/read_surface_detail.h"

namespace plaf::read_detail {

namespace fs = std::filesystem;

namespace {

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
// STL.

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
// and anything else for ASCII. binary_bytes: the text has bytes no ASCII STL has.
Expected check_binary_stl(const fs::path& path, std::string_view text, bool binary_bytes) {
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
  Expected e;
  e.binary = true;
  e.max_faces = static_cast<std::int64_t>(count);
  return e;
}

// ASCII STL. OpenMesh starts a facet at any line containing "outer" and reads the next three
// lines as "<word> x y z"; anything else is skipped. The scan requires exactly that shape.
Expected check_ascii_stl(const fs::path& path, std::string& text_to_read) {
  const std::string_view text = text_to_read;
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
  Expected e;
  e.max_faces = facets;
  return e;
}

// ---------------------------------------------------------------------------------------------
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

struct PlyProperty {
  std::string name;
  bool list = false;
  PlyType count_type;  // list only
  PlyType type;        // value, or list item
};

struct PlyElement {
  std::string name;
  std::int64_t count = 0;
  int line = 0;
  std::vector<PlyProperty> props;
};

struct PlyHeader {
  std::string format;
  std::vector<PlyElement> elements;
  std::size_t body = 0;  // the byte offset of the body: just after the end_header line
};

// The byte offset just after the end of line `line` (1-based) of text (its size if it has fewer).
std::size_t after_line(std::string_view text, int line) {
  std::size_t pos = 0;
  for (int l = 0; l < line && pos < text.size(); ++l) {
    const std::size_t eol = text.find('\n', pos);
    pos = eol == std::string_view::npos ? text.size() : eol + 1;
  }
  return pos;
}

bool is_face_list(const PlyElement& el, const PlyProperty& p) {
  return el.name == "face" && p.list && (p.name == "vertex_indices" || p.name == "vertex_index");
}

bool is_coordinate(const PlyElement& el, const PlyProperty& p) {
  return el.name == "vertex" && !p.list && (p.name == "x" || p.name == "y" || p.name == "z");
}

// The header, read through c up to the end_header line.
PlyHeader parse_ply_header(TextCursor& c, std::string_view text) {
  const std::size_t first_eol = text.find('\n');
  std::string_view first = text.substr(0, first_eol);
  while (!first.empty() && is_blank(first.back())) first.remove_suffix(1);
  if (first != "ply" && first != "PLY") c.fail("not a PLY file: the first line is not 'ply'");
  c.token("ply");
  const auto rest_must_be_empty = [&c](int line) {
    if (!c.at_end() && c.next_line() == line) c.fail("unexpected " + TextCursor::quote(c.peek()));
  };
  PlyHeader h;
  int line = c.next_line();
  c.expect("format");
  h.format = c.token("the PLY format");
  if (h.format != "ascii" && h.format != "binary_little_endian" && h.format != "binary_big_endian")
    c.fail("unknown PLY format " + TextCursor::quote(h.format));
  c.real("PLY version");
  rest_must_be_empty(line);
  std::vector<PlyElement>& elements = h.elements;
  for (;;) {
    line = c.next_line();
    const std::string_view kw = c.token("end_header");
    if (kw == "comment") {
      skip_rest_of_line(c, line);
      continue;
    }
    if (kw == "element") {
      PlyElement el;
      el.name = c.token("an element name");
      el.count = c.integer("element count", 0, std::numeric_limits<std::uint32_t>::max());
      el.line = line;
      elements.push_back(el);
    } else if (kw == "property") {
      if (elements.empty()) c.fail("property before any element");
      PlyProperty p;
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
      // By lines, not by a search for the word: "comment end_header" is a comment.
      h.body = after_line(text, line);
      break;
    } else {
      c.fail("unknown PLY header keyword " + TextCursor::quote(kw));
    }
    rest_must_be_empty(line);
  }
  return h;
}

// The ASCII body, token by token through c; nv: the vertex count.
void check_ply_ascii(TextCursor& c, const std::vector<PlyElement>& elements, std::int64_t nv) {
  for (const PlyElement& el : elements) {
    if (static_cast<std::uint64_t>(el.count) > c.remaining() / (2 * el.props.size() + 1) + 1)
      c.fail_at(el.line, "element " + el.name + " count " + std::to_string(el.count) +
                             " exceeds what the rest of the file can hold (truncated file?)");
    for (std::int64_t i = 0; i < el.count; ++i)
      for (const PlyProperty& p : el.props) {
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
}

// The binary body, which starts after the end_header line; nv: the vertex count.
void check_ply_binary(const fs::path& path, std::string_view text, const std::vector<PlyElement>& elements, bool big,
                      std::int64_t nv, std::size_t body) {
  std::size_t pos = body;
  const auto truncated = [&](const PlyElement& el, std::int64_t i) {
    fail(path, "truncated binary PLY: the file ends in " + el.name + " " + std::to_string(i) + " of " +
                   std::to_string(el.count));
  };
  for (const PlyElement& el : elements)
    for (std::int64_t i = 0; i < el.count; ++i)
      for (const PlyProperty& p : el.props) {
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
}

}  // namespace

// Binary STL when the text has bytes no ASCII STL has or does not start with "solid"; a text file
// starting with "solid" is ASCII even when its size would fit the binary layout.
Expected check_stl(const fs::path& path, std::string& text_to_read) {
  const std::string_view text = text_to_read;
  const bool binary_bytes = looks_binary(text);
  std::size_t first = 0;
  while (first < text.size() && std::isspace(static_cast<unsigned char>(text[first]))) ++first;
  const bool solid = text.substr(first, 5) == "solid";
  if (binary_bytes || !solid) return check_binary_stl(path, text, binary_bytes);
  return check_ascii_stl(path, text_to_read);
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

Expected check_ply(const fs::path& path, std::string_view text) {
  TextCursor c(path, text);
  const PlyHeader header = parse_ply_header(c, text);
  Expected e;
  std::int64_t nv = 0;
  for (const PlyElement& el : header.elements) {
    if (el.props.empty() && el.count > 0) c.fail_at(el.line, "element " + el.name + " has no properties");
    if (el.name == "vertex") e.vertices = nv = el.count;
    if (el.name == "face") e.faces = el.count;
  }
  if (header.format == "ascii") {
    check_ply_ascii(c, header.elements, nv);
    return e;
  }
  check_ply_binary(path, text, header.elements, header.format == "binary_big_endian", nv, header.body);
  e.binary = true;
  return e;
}

}  // namespace plaf::read_detail
