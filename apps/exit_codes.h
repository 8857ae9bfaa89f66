// SPDX-License-Identifier: MIT
// The exit codes of the `plaf` command, as the README and `plaf --help` promise them, and the
// message of the one code that means a bug in plaf rather than in its input.
#pragma once

#include <ostream>
#include <string_view>

namespace plaf::exit_code {

inline constexpr int ok = 0;           // success: every output written, every cell valid
inline constexpr int bad_input = 1;    // bad input or usage (or out of memory): one line naming it, nothing written
inline constexpr int invalid_mesh = 2; // failed: invalid / not conforming / boundary layer missing, or a stage that could
                                       // not finish (said loudly; OUTDIR/NAME.failed/: the report, and the picture
                                       // when there is a mesh)
inline constexpr int bug = 3;          // an exception plaf does not expect: a bug, nothing written

// Prints the two lines of an unexpected exception (what it said, and a request to report it)
// and returns `bug`. Any output set of the run has already been removed by then (OutputSet's
// destructor runs while the exception unwinds).
inline int report_bug(std::ostream& err, std::string_view what) {
  err << "plaf: internal error: " << what << '\n'
      << "plaf: this is a bug in plaf, not in your input; please report it (the command, the config and "
         "the files it reads, and this message) to the plaf issue tracker\n";
  return bug;
}

}  // namespace plaf::exit_code
