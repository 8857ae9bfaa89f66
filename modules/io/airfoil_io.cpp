// SPDX-License-Identifier: MIT
// Implements the reading of 2D body contours in the UIUC airfoil database formats (Selig and
// Lednicer, m-selig.ae.illinois.edu/ads) and the simplicity and disjointness checks of the
// loops; see airfoil_io.h. Segment pairs are found with a uniform grid, so the checks cost about
// O(n) for contours whose segments have comparable lengths, not O(n^2).
#include "modules/io/airfoil_io.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <string_view>

#include "modules/base/error.h"
#include "modules/base/format.h"
#include "modules/geometry/predicates.h"

namespace plaf {
inline namespace io {

using Eigen::Vector2d;

namespace {

// Two points closer than this, relative to the contour's largest extent (its chord), coincide.
constexpr double coincident_rel = 1e-12;

struct DataPoint {
  Vector2d p;
  int line;
};

std::string location(const std::string& file, int line) {
  return file + ":" + std::to_string(line) + ": ";
}

std::vector<std::string_view> split_blanks(std::string_view text) {
  std::vector<std::string_view> tokens;
  size_t k = 0;
  while (k < text.size()) {
    while (k < text.size() && std::string_view(" \t\r\v\f").find(text[k]) != std::string_view::npos) ++k;
    const size_t start = k;
    while (k < text.size() && std::string_view(" \t\r\v\f").find(text[k]) == std::string_view::npos) ++k;
    if (k > start) tokens.push_back(text.substr(start, k - start));
  }
  return tokens;
}

// A whole token as a double (locale-independent; accepts `-.00316`, `1.5e-3`, `+2`, nan, inf).
bool parse_number(std::string_view token, double& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  if (token.empty() || token.front() == '+' || token.front() == ' ') return false;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  return ec == std::errc() && end == token.data() + token.size();
}

bool integral_count(double v) {
  return v > 1.0 && v < 1e9 && std::abs(v - std::round(v)) <= 1e-9 * v;
}

double cross(const Vector2d& a, const Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

int orientation(const Vector2d& a, const Vector2d& b, const Vector2d& c) {
  const double o = cross(b - a, c - a);
  return (o > 0) - (o < 0);
}

// c lies in the bounding box of segment ab (used when a, b, c are collinear).
bool in_box(const Vector2d& a, const Vector2d& b, const Vector2d& c) {
  return std::min(a.x(), b.x()) <= c.x() && c.x() <= std::max(a.x(), b.x()) && std::min(a.y(), b.y()) <= c.y() &&
         c.y() <= std::max(a.y(), b.y());
}

// Closed segments ab and cd share at least one point.
bool segments_intersect(const Vector2d& a, const Vector2d& b, const Vector2d& c, const Vector2d& d) {
  const int o1 = orientation(a, b, c), o2 = orientation(a, b, d);
  const int o3 = orientation(c, d, a), o4 = orientation(c, d, b);
  if (o1 * o2 < 0 && o3 * o4 < 0) return true;
  return (o1 == 0 && in_box(a, b, c)) || (o2 == 0 && in_box(a, b, d)) || (o3 == 0 && in_box(c, d, a)) ||
         (o4 == 0 && in_box(c, d, b));
}

// Segment `index` of contour `body` runs from its point index to point index + 1 (cyclically).
struct Segment {
  Vector2d a, b;
  int body;
  int index;
};

void append_segments(const std::vector<Vector2d>& points, int body, std::vector<Segment>& out) {
  const int n = static_cast<int>(points.size());
  for (int i = 0; i < n; ++i) out.push_back({points[i], points[(i + 1) % n], body, i});
}

// Calls visit(s, t) once for every pair of segments with overlapping bounding boxes. Segments are
// binned into a uniform grid whose cell is about the mean segment length (at most ~4 cells per
// segment in total); a pair is visited only in the cell holding the lower-left corner of the
// intersection of its two boxes, so no pair is seen twice.
template <class Visit>
void for_each_overlapping_pair(const std::vector<Segment>& segments, Visit visit) {
  const size_t n = segments.size();
  if (n < 2) return;
  Eigen::AlignedBox2d all;
  double total_length = 0;
  for (const Segment& s : segments) {
    all.extend(s.a).extend(s.b);
    total_length += (s.b - s.a).norm();
  }
  const Vector2d size = all.sizes();
  const double nd = static_cast<double>(n);
  double cell =
      std::max({total_length / nd, std::sqrt(size.x() * size.y() / (4.0 * nd)), size.maxCoeff() / (4.0 * nd)});
  if (!(cell > 0)) cell = 1.0;
  const long nx = static_cast<long>(size.x() / cell) + 1, ny = static_cast<long>(size.y() / cell) + 1;
  const auto cell_x = [&](double x) { return std::clamp(static_cast<long>((x - all.min().x()) / cell), 0L, nx - 1); };
  const auto cell_y = [&](double y) { return std::clamp(static_cast<long>((y - all.min().y()) / cell), 0L, ny - 1); };

  // Counting sort of (cell, segment) entries into compressed rows.
  std::vector<Eigen::AlignedBox2d> boxes(n);
  std::vector<long> start(static_cast<size_t>(nx * ny) + 1, 0);
  for (size_t k = 0; k < n; ++k) {
    boxes[k] = Eigen::AlignedBox2d(segments[k].a);
    boxes[k].extend(segments[k].b);
    for (long iy = cell_y(boxes[k].min().y()); iy <= cell_y(boxes[k].max().y()); ++iy)
      for (long ix = cell_x(boxes[k].min().x()); ix <= cell_x(boxes[k].max().x()); ++ix) ++start[iy * nx + ix + 1];
  }
  for (size_t c = 1; c < start.size(); ++c) start[c] += start[c - 1];
  std::vector<size_t> members(static_cast<size_t>(start.back()));
  std::vector<long> fill(start.begin(), start.end() - 1);
  for (size_t k = 0; k < n; ++k)
    for (long iy = cell_y(boxes[k].min().y()); iy <= cell_y(boxes[k].max().y()); ++iy)
      for (long ix = cell_x(boxes[k].min().x()); ix <= cell_x(boxes[k].max().x()); ++ix)
        members[fill[iy * nx + ix]++] = k;

  for (long c = 0; c + 1 < static_cast<long>(start.size()); ++c) {
    for (long p = start[c]; p < start[c + 1]; ++p) {
      for (long q = p + 1; q < start[c + 1]; ++q) {
        const size_t s = members[p], t = members[q];
        if (!boxes[s].intersects(boxes[t])) continue;
        const Eigen::AlignedBox2d common = boxes[s].intersection(boxes[t]);
        if (cell_y(common.min().y()) * nx + cell_x(common.min().x()) != c) continue;
        visit(segments[s], segments[t]);
      }
    }
  }
}

// The file line of point i; contours built in code without lines report point numbers from 1.
int line_of(const BodyContour& body, int i) {
  return i < static_cast<int>(body.lines.size()) ? body.lines[i] : i + 1;
}

std::string segment_lines(const BodyContour& body, int index) {
  const int n = static_cast<int>(body.points.size());
  return "lines " + std::to_string(line_of(body, index)) + "-" + std::to_string(line_of(body, (index + 1) % n));
}

// Throws if two non-adjacent segments of the contour meet, or two adjacent ones fold back.
void check_simple(const BodyContour& body) {
  const int n = static_cast<int>(body.points.size());
  for (int i = 0; i < n; ++i) {
    const Vector2d& a = body.points[i];
    const Vector2d& b = body.points[(i + 1) % n];
    const Vector2d& c = body.points[(i + 2) % n];
    if (cross(b - a, c - b) == 0.0 && (b - a).dot(c - b) < 0.0)
      throw InputError(location(body.file, line_of(body, (i + 1) % n)) +
                       "the contour turns back on itself (the segments of " + segment_lines(body, i) + " and " +
                       segment_lines(body, (i + 1) % n) + " overlap)");
  }
  std::vector<Segment> segments;
  append_segments(body.points, 0, segments);
  for_each_overlapping_pair(segments, [&](const Segment& s, const Segment& t) {
    const int gap = std::abs(s.index - t.index);
    if (gap == 1 || gap == n - 1) return;  // adjacent: they share a point, handled above
    if (!segments_intersect(s.a, s.b, t.a, t.b)) return;
    const Segment& first = s.index < t.index ? s : t;
    const Segment& second = s.index < t.index ? t : s;
    throw InputError(location(body.file, line_of(body, first.index)) +
                     "the contour intersects itself: the segment of " + segment_lines(body, first.index) +
                     " crosses the segment of " + segment_lines(body, second.index));
  });
}

// The data lines of a contour file: an optional title, then two numbers per line; blank lines
// separate blocks.
struct ContourLines {
  std::string title;
  std::vector<DataPoint> data;
  int last_line = 0;  // the last line that is not blank
};

// A token as an error may print it: printable ASCII kept, every other byte as \xNN (a binary or
// UTF-16 file, a NUL byte), at most 40 bytes.
std::string printable(std::string_view tok) {
  std::string out;
  for (std::size_t i = 0; i < tok.size() && i < 40; ++i) {
    const unsigned char c = static_cast<unsigned char>(tok[i]);
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      static const char* hex = "0123456789abcdef";
      out += "\\x";
      out += hex[c >> 4];
      out += hex[c & 15];
    }
  }
  if (tok.size() > 40) out += "...";
  return out;
}

ContourLines read_contour_lines(std::istream& in, const std::string& file) {
  ContourLines out;
  std::string text;
  int line = 0;
  bool seen_content = false;
  while (std::getline(in, text)) {
    ++line;
    const std::vector<std::string_view> tokens = split_blanks(text);
    if (tokens.empty()) continue;
    out.last_line = line;
    std::vector<double> values;
    std::string_view bad;
    for (std::string_view tok : tokens) {
      double v;
      if (parse_number(tok, v))
        values.push_back(v);
      else if (bad.empty())
        bad = tok;
    }
    if (!bad.empty() && !seen_content) {
      const size_t first = text.find_first_not_of(" \t");
      const size_t last = text.find_last_not_of(" \t\r");
      out.title = text.substr(first, last - first + 1);
      seen_content = true;
      continue;
    }
    seen_content = true;
    if (!bad.empty())
      throw InputError(location(file, line) + "'" + printable(bad) + "' is not a number (expected two numbers x y)");
    if (values.size() != 2)
      throw InputError(location(file, line) + "expected two numbers x y, found " + std::to_string(values.size()));
    if (!std::isfinite(values[0]) || !std::isfinite(values[1]))
      throw InputError(location(file, line) + "coordinate is not finite");
    for (double v : values)
      if (std::abs(v) > kMaxContourCoordinate)
        throw InputError(location(file, line) + "coordinate " + num(v) + " is beyond the range plaf meshes (|x|, |y| <= " +
                         num(kMaxContourCoordinate) + ")");
    out.data.push_back({Vector2d(values[0], values[1]), line});
  }
  if (!seen_content) throw InputError(location(file, 1) + "empty file (no coordinates)");
  return out;
}

// The points in Selig order, TE -> upper -> LE -> lower -> TE. Lednicer gives the point counts
// first, then upper LE -> TE and lower LE -> TE; joined, the LE given twice is kept once.
std::vector<DataPoint> selig_order(const std::vector<DataPoint>& data, const std::string& file) {
  std::vector<DataPoint> loop;
  const bool counts = !data.empty() && integral_count(data[0].p.x()) && integral_count(data[0].p.y());
  const bool matching =
      counts && static_cast<size_t>(std::round(data[0].p.x()) + std::round(data[0].p.y())) + 1 == data.size();
  // Two whole numbers followed by a blank line are Lednicer's counts, not a point: counts that do
  // not add up to the points that follow are an error, not the point (30, 40).
  if (counts && !matching && data.size() > 1 && data[1].line > data[0].line + 1 && data[0].p.x() >= 2 &&
      data[0].p.y() >= 2)
    throw InputError(location(file, data[0].line) + "Lednicer point counts " + num(data[0].p.x()) + " + " +
                     num(data[0].p.y()) + " do not match the " + std::to_string(data.size() - 1) +
                     " points that follow");
  if (matching) {
    const size_t upper = static_cast<size_t>(std::round(data[0].p.x()));
    loop.assign(data.rend() - static_cast<std::ptrdiff_t>(upper) - 1, data.rend() - 1);
    size_t lower_begin = upper + 1;
    Eigen::AlignedBox2d box;
    for (size_t k = 1; k < data.size(); ++k) box.extend(data[k].p);
    if ((data[lower_begin].p - data[1].p).norm() <= coincident_rel * box.sizes().maxCoeff()) ++lower_begin;
    loop.insert(loop.end(), data.begin() + static_cast<std::ptrdiff_t>(lower_begin), data.end());
  } else {
    loop = data;
  }
  return loop;
}

// The points of loop (no two consecutive ones may coincide) as the body's contour and its
// corners: a repeated first point means a sharp TE (one corner), otherwise the contour is closed
// by a straight segment between its end points (two corners).
void close_contour(std::vector<DataPoint> loop, BodyContour& body) {
  Eigen::AlignedBox2d box;
  for (const DataPoint& d : loop) box.extend(d.p);
  const double coincident_abs = coincident_rel * box.sizes().maxCoeff();
  for (size_t i = 0; i + 1 < loop.size(); ++i) {
    const DataPoint& a = loop[i];
    const DataPoint& b = loop[i + 1];
    if ((b.p - a.p).norm() <= coincident_abs) {
      const DataPoint& later = b.line > a.line ? b : a;
      const DataPoint& earlier = b.line > a.line ? a : b;
      throw InputError(location(body.file, later.line) + "repeats the point of line " + std::to_string(earlier.line) +
                       " (two consecutive points coincide)");
    }
  }
  if ((loop.back().p - loop.front().p).norm() <= coincident_abs) {
    loop.pop_back();
    body.corners = {0};
  } else {
    body.blunt = true;
    body.corners = {0, static_cast<int>(loop.size()) - 1};
  }
  for (const DataPoint& d : loop) {
    body.points.push_back(d.p);
    body.lines.push_back(d.line);
  }
}

// Clockwise orientation (the body convention of spline_loop.h). A sharp contour keeps its TE at
// index 0; a blunt one keeps its closing segment from the last point to the first.
void orient_clockwise(BodyContour& body) {
  const int n = static_cast<int>(body.points.size());
  double twice_area = 0.0;
  for (int i = 0; i < n; ++i) twice_area += cross(body.points[i], body.points[(i + 1) % n]);
  if (twice_area > 0.0) {
    const auto old_index = [&](int k) { return body.blunt ? n - 1 - k : (n - k) % n; };
    std::vector<Vector2d> points(n);
    std::vector<int> lines(n);
    for (int k = 0; k < n; ++k) {
      points[k] = body.points[old_index(k)];
      lines[k] = body.lines[old_index(k)];
    }
    body.points = std::move(points);
    body.lines = std::move(lines);
    for (int& c : body.corners) c = old_index(c);  // the map is an involution
    std::sort(body.corners.begin(), body.corners.end());
  }
}

}  // namespace

BodyContour read_body_contour(const std::filesystem::path& path) {
  BodyContour body;
  body.file = path.string();
  // A directory, a device or a FIFO is no contour: reading one would say "empty file", never end,
  // or block.
  std::error_code ec;
  if (std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec))
    throw InputError(body.file + ": not a regular file (a contour is a text file of x y lines)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(body.file + ": cannot open the contour file");
  // 1. The data lines and the title.
  ContourLines lines = read_contour_lines(in, body.file);
  body.title = std::move(lines.title);
  // 2. The points in Selig order.
  const std::vector<DataPoint> loop = selig_order(lines.data, body.file);
  if (loop.size() < 4)
    throw InputError(location(body.file, loop.empty() ? lines.last_line : loop.back().line) + "only " +
                     std::to_string(loop.size()) + " points, a contour needs at least 4");
  // 3. The closing point and the corners.
  close_contour(loop, body);
  // 4. The contour must be simple.
  check_simple(body);
  // 5. Clockwise orientation.
  orient_clockwise(body);
  return body;
}

BodyContour contour_from_points(const std::vector<Vector2d>& points, const std::string& name) {
  BodyContour body;
  body.file = name;
  body.title = name;
  std::vector<DataPoint> loop;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) throw InputError(location(name, static_cast<int>(i) + 1) + "coordinate is not finite");
    loop.push_back({points[i], static_cast<int>(i) + 1});
  }
  if (loop.size() < 4)
    throw InputError(name + ": only " + std::to_string(loop.size()) + " points, a contour needs at least 4");
  close_contour(loop, body);
  check_simple(body);
  orient_clockwise(body);
  return body;
}

void check_disjoint(const std::vector<BodyContour>& bodies) {
  // 1. No two contours cross or touch.
  std::vector<Segment> segments;
  for (size_t b = 0; b < bodies.size(); ++b) append_segments(bodies[b].points, static_cast<int>(b), segments);
  for_each_overlapping_pair(segments, [&](const Segment& s, const Segment& t) {
    if (s.body == t.body || !segments_intersect(s.a, s.b, t.a, t.b)) return;
    const BodyContour& a = bodies[s.body];
    const BodyContour& b = bodies[t.body];
    throw InputError(location(a.file, line_of(a, s.index)) + "the contour intersects the contour of " + b.file +
                     ": the segment of " + segment_lines(a, s.index) + " crosses the segment of " + b.file + " " +
                     segment_lines(b, t.index));
  });
  // 2. Without crossings, a contour is inside another exactly when any of its points is.
  for (size_t i = 0; i < bodies.size(); ++i) {
    for (size_t j = 0; j < bodies.size(); ++j) {
      if (i == j || bodies[i].points.empty() || bodies[j].points.size() < 3) continue;
      if (!inside_polygon(bodies[i].points[0], bodies[j].points)) continue;
      const BodyContour& outer = bodies[j];
      int first_line = line_of(outer, 0), last_line = first_line;
      for (int k = 0; k < static_cast<int>(outer.points.size()); ++k) {
        first_line = std::min(first_line, line_of(outer, k));
        last_line = std::max(last_line, line_of(outer, k));
      }
      throw InputError(location(bodies[i].file, line_of(bodies[i], 0)) + "the contour lies inside the contour of " +
                       outer.file + " (lines " + std::to_string(first_line) + "-" + std::to_string(last_line) + ")");
    }
  }
}

}  // namespace io
}  // namespace plaf
