// SPDX-License-Identifier: MIT
#include "modules/io/airfoil_io.h"

#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "modules/base/error.h"
#include "modules/geometry/spline_loop.h"
#include "tests/published_data.h"
#include "tests/test_support.h"

using namespace plaf;
using Eigen::Vector2d;
using test::read_lines;
using test::TempDir;
using test::write_text;
namespace fs = std::filesystem;

namespace {

// A contour file: absolute as given, or a published one in the data root (tests/published_data.h).
fs::path airfoil(const fs::path& file) {
  if (file.is_absolute()) return file;
  return plaf::test::published("airfoils/" + file.string());
}

double signed_area(const std::vector<Vector2d>& p) {
  double twice = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    const Vector2d& a = p[i];
    const Vector2d& b = p[(i + 1) % p.size()];
    twice += a.x() * b.y() - a.y() * b.x();
  }
  return 0.5 * twice;
}

std::string error_of(const fs::path& p) {
  try {
    read_body_contour(p);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

std::string disjoint_error(const std::vector<BodyContour>& bodies) {
  try {
    check_disjoint(bodies);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

BodyContour transformed(BodyContour b, double scale, const Vector2d& shift, const std::string& file) {
  for (Vector2d& p : b.points) p = scale * p + shift;
  b.file = file;
  return b;
}

// The coordinate lines of `from` (a Selig file with one title line) in reverse order, without the
// title: the same contour, clockwise.
fs::path write_reversed(const fs::path& from, const fs::path& to) {
  std::vector<std::string> lines = read_lines(from);
  lines.erase(lines.begin());
  std::string text;
  for (auto it = lines.rbegin(); it != lines.rend(); ++it) text += *it + "\n";
  return write_text(to, text);
}

}  // namespace

TEST_CASE("airfoil: every real file reads with the point count and trailing edge of docs/data.md") {
  PLAF_NEEDS_PUBLISHED("airfoils/e387.dat", "airfoils/rae2822.dat", "airfoils/naca0012.dat", "airfoils/n0012.dat",
                       "airfoils/nlr7301.dat", "airfoils/naca0012_sharp.dat");
  // All facts from docs/data.md: file points, header, TE closed (first == last) or the
  // two open TE end points, and whether the file runs counter-clockwise (Selig) or clockwise.
  // Every shipped file runs counter-clockwise: the clockwise ones are two of them reversed.
  const TempDir dir("airfoil_clockwise");
  const fs::path e387_cw = write_reversed(airfoil("e387.dat"), dir / "e387_cw.dat");
  const fs::path naca0012_cw = write_reversed(airfoil("naca0012.dat"), dir / "naca0012_cw.dat");
  struct Case {
    fs::path file;
    int file_points;
    bool closed;
    const char* title;
    Vector2d te_first, te_last;  // the first and last file points
    bool ccw;
  };
  const Case cases[] = {
      {"e387.dat", 61, true, "E387", {1.0, 0.0}, {1.0, 0.0}, true},
      {"rae2822.dat", 129, true, "RAE 2822 AIRFOIL", {1.0, 0.0}, {1.0, 0.0}, true},
      {"naca0012.dat", 69, false, "Naca 0012 By Naca.exe D. LEDNICER", {1.0, 0.00126}, {1.0, -0.00126}, true},
      {"n0012.dat", 131, false, "NACA 0012 AIRFOILS", {1.0, 0.00126}, {1.0, -0.00126}, true},
      {"naca0012_sharp.dat", 200, true, "", {1.0, 0.0}, {1.0, 0.0}, true},
      {"nlr7301.dat", 79, false, "NLR-7301 AIRFOIL", {1.0, 0.00055}, {1.0, -0.00055}, true},
      {e387_cw, 61, true, "", {1.0, 0.0}, {1.0, 0.0}, false},
      {naca0012_cw, 69, false, "", {1.0, -0.00126}, {1.0, 0.00126}, false},
  };
  for (const Case& k : cases) {
    const fs::path path = airfoil(k.file);
    CAPTURE(path.string());
    const BodyContour b = read_body_contour(path);
    const int n = static_cast<int>(b.points.size());
    const int title_lines = std::string(k.title).empty() ? 0 : 1;
    CHECK(b.file == path.string());
    CHECK(b.title == k.title);
    CHECK(n == (k.closed ? k.file_points - 1 : k.file_points));
    CHECK(b.blunt == !k.closed);
    CHECK(b.lines.size() == b.points.size());
    CHECK(signed_area(b.points) < 0);  // clockwise
    if (k.closed) {
      REQUIRE(b.corners == std::vector<int>{0});
      CHECK((b.points[0] - k.te_first).norm() <= 1e-12);
      CHECK(b.lines[0] == 1 + title_lines);
    } else {
      // The closing straight segment runs from the last point to the first.
      REQUIRE(b.corners == std::vector<int>{0, n - 1});
      const Vector2d& first = k.ccw ? k.te_last : k.te_first;  // reversed when the file is CCW
      const Vector2d& last = k.ccw ? k.te_first : k.te_last;
      CHECK((b.points[0] - first).norm() <= 1e-12);
      CHECK((b.points[n - 1] - last).norm() <= 1e-12);
    }
    // Counter-clockwise files come out reversed, clockwise ones in file order.
    CHECK((b.lines[2] < b.lines[1]) == k.ccw);
    for (int line : b.lines) {
      CHECK(line >= 1 + title_lines);
      CHECK(line <= k.file_points + title_lines);
    }
    const SplineLoop loop(b.points, b.corners, b.file);
    CHECK(loop.signed_area() < 0);
  }
  // docs/data.md: E387 shoelace area +0.0573 in file order.
  CHECK(signed_area(read_body_contour(airfoil("e387.dat")).points) == doctest::Approx(-0.0573).epsilon(1e-3));
  // A file and its reverse read to the same clockwise points, sharp or blunt.
  CHECK(read_body_contour(e387_cw).points == read_body_contour(airfoil("e387.dat")).points);
  CHECK(read_body_contour(naca0012_cw).points == read_body_contour(airfoil("naca0012.dat")).points);
}

TEST_CASE("airfoil: the Lednicer layout reads to the same loop as the Selig layout") {
  TempDir dir("airfoil_lednicer");
  SUBCASE("separate LE points (naca0012_sharp: the upper surface ends where y turns negative)") {
    PLAF_NEEDS_PUBLISHED("airfoils/naca0012_sharp.dat");
    const std::vector<std::string> lines = read_lines(airfoil("naca0012_sharp.dat"));
    size_t split = 0;
    while (split < lines.size() && std::stod(lines[split].substr(lines[split].find(' '))) >= 0) ++split;
    std::string text = "NACA 0012 sharp, Lednicer layout\n" + std::to_string(split) + ".\t" +
                       std::to_string(lines.size() - split) + ".\n\n";
    for (size_t k = split; k-- > 0;) text += lines[k] + "\n";  // upper LE -> TE
    text += "\n";
    for (size_t k = split; k < lines.size(); ++k) text += lines[k] + "\n";  // lower LE -> TE
    write_text(dir / "lednicer.dat", text);
    const BodyContour selig = read_body_contour(airfoil("naca0012_sharp.dat"));
    const BodyContour lednicer = read_body_contour(dir / "lednicer.dat");
    CHECK(lednicer.title == "NACA 0012 sharp, Lednicer layout");
    CHECK(lednicer.points == selig.points);
    CHECK(lednicer.corners == selig.corners);
    CHECK(lednicer.blunt == selig.blunt);
  }
  SUBCASE("a shared LE point given in both blocks (rae2822: 65 upper and 65 lower points)") {
    PLAF_NEEDS_PUBLISHED("airfoils/rae2822.dat");
    const std::vector<std::string> lines = read_lines(airfoil("rae2822.dat"));  // title + 129
    std::string text = "RAE 2822, Lednicer layout\n65. 65.\n\n";
    for (size_t k = 65; k >= 1; --k) text += lines[k] + "\n";  // upper LE -> TE
    text += "\n";
    for (size_t k = 65; k <= 129; ++k) text += lines[k] + "\n";  // lower LE -> TE
    write_text(dir / "rae_lednicer.dat", text);
    const BodyContour selig = read_body_contour(airfoil("rae2822.dat"));
    const BodyContour lednicer = read_body_contour(dir / "rae_lednicer.dat");
    CHECK(lednicer.points.size() == 128);
    CHECK(lednicer.points == selig.points);
    CHECK(lednicer.corners == selig.corners);
  }
}

TEST_CASE("airfoil: numbers in UIUC styles, tabs, CRLF and scales from 1e-8 to 1e8") {
  PLAF_NEEDS_PUBLISHED("airfoils/e387.dat");
  TempDir dir("airfoil_styles");
  write_text(dir / "styles.dat", "title\r\n 1.0\t0.0\r\n.5   .05\r\n\t0 0\r\n5E-1 -.05\r\n+1. -0\r\n");
  const BodyContour b = read_body_contour(dir / "styles.dat");
  CHECK(b.title == "title");
  // (1, 0) and (+1., -0) close the contour; counter-clockwise, so reversed with the TE kept first.
  CHECK(b.points == std::vector<Vector2d>{{1.0, 0.0}, {0.5, -0.05}, {0.0, 0.0}, {0.5, 0.05}});
  CHECK(b.lines == std::vector<int>{2, 5, 4, 3});
  CHECK(b.corners == std::vector<int>{0});

  // Coincidence tolerances are relative to the chord.
  const std::vector<std::string> lines = read_lines(airfoil("e387.dat"));
  for (double scale : {1e-8, 1e8}) {
    std::ostringstream text;
    text.precision(17);
    text << lines[0] << "\n";
    for (size_t k = 1; k < lines.size(); ++k) {
      std::istringstream in(lines[k]);
      double x, y;
      in >> x >> y;
      text << x * scale << " " << y * scale << "\n";
    }
    write_text(dir / "scaled.dat", text.str());
    const BodyContour s = read_body_contour(dir / "scaled.dat");
    CHECK(s.points.size() == 60);
    CHECK(s.corners == std::vector<int>{0});
    CHECK(signed_area(s.points) == doctest::Approx(-0.0573 * scale * scale).epsilon(1e-3));
  }
}

TEST_CASE("airfoil: bad files are rejected with file:line and the reason") {
  TempDir dir("airfoil_bad");
  struct Case {
    const char* file;
    const char* text;
    int line;  // 0: the message names only the file
    const char* reason;
  };
  const Case cases[] = {
      {"empty.dat", "", 1, "empty file"},
      {"blank.dat", "\n  \t\n\n", 1, "empty file"},
      {"one_column.dat", "title\n1.0 0.0\n0.5\n0.0 0.0\n0.5 -0.1\n", 3, "expected two numbers x y, found 1"},
      {"three_columns.dat", "1.0 0.0 0.0\n0.5 0.1\n0.0 0.0\n0.5 -0.1\n", 1, "expected two numbers x y, found 3"},
      {"text.dat", "title\n1 0\n0.5 0.1\n0.0 abc\n0.5 -0.1\n1 0\n", 4, "'abc' is not a number"},
      {"nan.dat", "title\n1 0\n0.5 nan\n0 0\n0.5 -0.1\n", 3, "coordinate is not finite"},
      {"inf.dat", "title\n1 0\n0.5 0.1\n-inf 0\n0.5 -0.1\n", 4, "coordinate is not finite"},
      {"three_points.dat", "title\n1 0\n0 0.1\n0 -0.1\n", 4, "only 3 points, a contour needs at least 4"},
      {"title_only.dat", "just a title\n", 1, "only 0 points"},
      {"repeated.dat", "title\n1 0\n0.5 0.1\n0.5 0.1\n0 0\n0.5 -0.1\n1 0\n", 4, "repeats the point of line 3"},
      {"repeated_closing.dat", "1 0\n0.5 0.1\n0 0\n0.5 -0.1\n1 0\n1 0\n", 6, "repeats the point of line 5"},
      {"bow_tie.dat", "0 0\n1 1\n1 0\n0 1\n", 1,
       "the contour intersects itself: the segment of lines 1-2 crosses the segment of lines 3-4"},
      {"crossing_te.dat", "title\n1 0.01\n0.5 0.1\n0 0\n0.5 -0.1\n0.9 0.05\n", 2,
       "the contour intersects itself: the segment of lines 2-3 crosses the segment of lines 5-6"},
      {"fold_back.dat", "0 0\n1 0\n0.5 0\n0.5 1\n", 2, "the contour turns back on itself"},
  };
  for (const Case& k : cases) {
    CAPTURE(k.file);
    write_text(dir / k.file, k.text);
    const std::string where = (dir / k.file).string() + ":" + std::to_string(k.line) + ": ";
    const std::string message = error_of(dir / k.file);
    CHECK(message.rfind(where, 0) == 0);
    CHECK(message.find(k.reason) != std::string::npos);
  }
  const std::string missing = error_of(dir / "no_such_file.dat");
  CHECK(missing == (dir / "no_such_file.dat").string() + ": cannot open the contour file");
}

TEST_CASE("airfoil: check_disjoint accepts close bodies and rejects crossing and nested contours") {
  PLAF_NEEDS_PUBLISHED("airfoils/e387.dat");
  const BodyContour e387 = read_body_contour(airfoil("e387.dat"));
  CHECK_NOTHROW(check_disjoint({e387, transformed(e387, 1.0, Vector2d(1.5, 0.0), "e387_behind.dat")}));
  // A slat and a flap of 0.3 chord, 0.05 ahead of the LE and 0.002 behind the TE (E387's y range
  // [-0.01502, 0.08247] scaled: [-0.0045, 0.0247]; the copies sit 0.03 lower).
  const BodyContour slat = transformed(e387, 0.3, Vector2d(-0.35, -0.03), "slat.dat");
  const BodyContour flap = transformed(e387, 0.3, Vector2d(1.002, -0.03), "flap.dat");
  CHECK_NOTHROW(check_disjoint({slat, e387, flap}));

  const std::string crossing = disjoint_error({e387, transformed(e387, 1.0, Vector2d(0.5, 0.01), "e387_shifted.dat")});
  CHECK(crossing.find("e387.dat:") != std::string::npos);
  CHECK(crossing.find("e387_shifted.dat") != std::string::npos);
  CHECK(crossing.find("intersects the contour of") != std::string::npos);

  // E387 is 0.09 thick near x = 0.3 (docs/data.md); a 0.1-chord copy at (0.25, 0.02) spans
  // y in [0.0185, 0.0283], well inside.
  const BodyContour small = transformed(e387, 0.1, Vector2d(0.25, 0.02), "small.dat");
  for (const auto& bodies : {std::vector<BodyContour>{e387, small}, std::vector<BodyContour>{small, e387}}) {
    const std::string nested = disjoint_error(bodies);
    CHECK(nested.rfind("small.dat:2: the contour lies inside the contour of " + e387.file + " (lines 2-61)", 0) == 0);
  }
}

TEST_CASE("airfoil: a 20000-point contour is read and checked with the segment grid") {
  TempDir dir("airfoil_big");
  const int n = 20000;
  std::ostringstream text;
  text.precision(17);
  text << "big ellipse\n";
  for (int k = 0; k < n; ++k) {
    const double a = 2.0 * M_PI * k / n;
    text << 0.5 + 0.5 * std::cos(a) << " " << 0.06 * std::sin(a) << "\n";
  }
  write_text(dir / "big.dat", text.str());
  const BodyContour b = read_body_contour(dir / "big.dat");
  CHECK(b.points.size() == n);
  CHECK(b.blunt);  // first != last: closed by a (tiny) straight segment
  CHECK(signed_area(b.points) == doctest::Approx(-M_PI * 0.5 * 0.06).epsilon(1e-6));
  CHECK_NOTHROW(check_disjoint({b, transformed(b, 1.0, Vector2d(0.0, 0.2), "above.dat")}));
  // Reversed to clockwise, the blunt contour starts at the last file line, 20001.
  CHECK(disjoint_error({b, transformed(b, 0.5, Vector2d(0.25, 0.0), "inner.dat")}) ==
        "inner.dat:20001: the contour lies inside the contour of " + b.file + " (lines 2-20001)");
}

TEST_CASE("airfoil: a directory or a device as the contour file is an InputError saying so") {
  const plaf::test::TempDir d("airfoil_not_regular");
  CHECK_THROWS_WITH_AS(plaf::read_body_contour(d.path),
                       (d.path.string() + ": not a regular file (a contour is a text file of x y lines)").c_str(),
                       plaf::InputError);
  CHECK_THROWS_WITH_AS(plaf::read_body_contour("/dev/zero"),
                       "/dev/zero: not a regular file (a contour is a text file of x y lines)", plaf::InputError);
}

TEST_CASE("airfoil: unprintable tokens are printed escaped, coordinates beyond 1e12 are refused, with file:line") {
  TempDir d("airfoil_tokens");
  // A NUL byte, a control byte and UTF-8 in the bad token; the error line stays printable ASCII.
  const std::string binary = std::string("title\n0 0\n1 0\n1") + '\0' + "x\x01\xc3\xa9 1\n0 1\n";
  const std::string e = error_of(write_text(d / "binary.dat", binary));
  CHECK(e.find("binary.dat:4:") != std::string::npos);
  CHECK(e.find("\\x00x\\x01\\xc3\\xa9") != std::string::npos);
  CHECK(std::all_of(e.begin(), e.end(), [](char c) { return c >= 0x20 && c < 0x7f; }));
  // A long garbage token is cut at 40 bytes.
  const std::string longer = error_of(write_text(d / "long.dat", "title\n0 0\n1 " + std::string(100, 'z') + "\n"));
  CHECK(longer.find(std::string(40, 'z') + "...") != std::string::npos);
  CHECK(longer.find(std::string(41, 'z')) == std::string::npos);
  // Huge but finite coordinates (two bodies at 1.5e308 overflowed a bounding box before).
  const std::string huge = error_of(write_text(d / "huge.dat", "0 0\n1.5e308 0\n1 1\n0 1\n"));
  CHECK(huge.find("huge.dat:2:") != std::string::npos);
  CHECK(huge.find("beyond the range plaf meshes") != std::string::npos);
  CHECK(error_of(write_text(d / "e200.dat", "0 0\n1e200 0\n1e200 1e200\n0 1\n")).find("e200.dat:2:") != std::string::npos);
  // 1e12 itself is in range.
  CHECK(error_of(write_text(d / "edge.dat", "0 0\n1e12 0\n1e12 1e12\n0 1e12\n")) == "no error");
}

TEST_CASE("airfoil: Lednicer counts that do not match the points are an error naming them, not a point") {
  TempDir d("airfoil_lednicer_counts");
  const std::string e = error_of(write_text(d / "counts.dat", "title\n30. 40.\n\n0 0\n0.5 0.1\n1 0\n\n0 0\n0.5 -0.1\n1 0\n"));
  CHECK(e.find("counts.dat:2:") != std::string::npos);
  CHECK(e.find("Lednicer point counts 30 + 40 do not match the 6 points that follow") != std::string::npos);
  // Whole numbers without the blank line after them are a point, as before.
  CHECK(error_of(write_text(d / "square.dat", "0 0\n2 0\n2 2\n0 2\n")) == "no error");
}
