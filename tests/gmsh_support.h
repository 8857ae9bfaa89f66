// SPDX-License-Identifier: MIT
// Gmsh as an independent checker for the suites (`gmsh -check`, its AnalyseMeshQuality plugin's
// Jacobians), run through the `gmsh` binary when it is on PATH. Header-only; include it as
// "tests/gmsh_support.h".
#pragma once

#include <sys/wait.h>

#include <cstdlib>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "tests/test_support.h"

namespace plaf::test {

// What `gmsh` printed (stdout and stderr) on a command run in dir.
struct GmshRun {
  int code = -1;
  std::string out;
};

inline GmshRun run_gmsh(const std::string& args, const TempDir& dir) {
  const std::string cmd = "cd '" + dir.path.string() + "' && gmsh " + args + " > gmsh.txt 2>&1";
  const int status = std::system(cmd.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, read_text(dir / "gmsh.txt")};
}

inline bool gmsh_on_path() {
  return std::system("command -v gmsh > /dev/null 2>&1") == 0;
}

// Gmsh's error and warning lines (a duplicate node is a warning per node and an error for the
// count), except the error Gmsh 4.8 prints for every prism of order 3 or 4 in its
// duplicate-element and Jacobian checks ("FaceClosureFull not implemented for prisms of order
// N": its face closures stop at order 2; the checks still run).
inline std::vector<std::string> gmsh_complaints(const std::string& out) {
  std::vector<std::string> lines;
  std::istringstream in(out);
  for (std::string line; std::getline(in, line);)
    if ((line.rfind("Error", 0) == 0 || line.rfind("Warning", 0) == 0) &&
        line.find("FaceClosureFull not implemented for prisms of order") == std::string::npos)
      lines.push_back(line);
  return lines;
}

// Gmsh's AnalyseMeshQuality plugin on a mesh file (its own Bezier bounds on det J): the
// smallest minJ over the cells (negative for an inverted one) and the worst minJ/maxJ (which it
// takes as a ratio of like signs: an inverted cell need not lower it), NaN when not printed.
struct GmshJacobians {
  double min_j = std::numeric_limits<double>::quiet_NaN();
  double worst_ratio = std::numeric_limits<double>::quiet_NaN();
};

inline GmshJacobians gmsh_jacobians(const std::string& msh, const TempDir& dir) {
  write_text(dir / "jacobian.geo", "Merge \"" + msh +
                                             "\";\n"
                                             "Plugin(AnalyseMeshQuality).JacobianDeterminant = 1;\n"
                                             "Plugin(AnalyseMeshQuality).IGEMeasure = 0;\n"
                                             "Plugin(AnalyseMeshQuality).ICNMeasure = 0;\n"
                                             "Plugin(AnalyseMeshQuality).DimensionOfElements = 3;\n"
                                             "Plugin(AnalyseMeshQuality).Recompute = 1;\n"
                                             "Plugin(AnalyseMeshQuality).CreateView = 0;\n"
                                             "Plugin(AnalyseMeshQuality).Run;\n");
  const GmshRun run = run_gmsh("jacobian.geo -parse_and_exit", dir);
  GmshJacobians j;
  const auto number_after = [&](const std::string& key) {
    const auto at = run.out.find(key);
    return at == std::string::npos ? std::numeric_limits<double>::quiet_NaN()
                                   : std::stod(run.out.substr(at + key.size()));
  };
  j.min_j = number_after("minJ      =");
  // The (worst, avg, best) line: Gmsh may first print the average over its non-constant cells.
  std::istringstream in(run.out);
  for (std::string line; std::getline(in, line);) {
    const auto at = line.find("minJ/maxJ =");
    if (at != std::string::npos && line.find("(worst") != std::string::npos) j.worst_ratio = std::stod(line.substr(at + 11));
  }
  return j;
}


}  // namespace plaf::test
