#pragma once
// `shaping audit` as a library function (thesis §3.3, Theorem 1): is a tabular shaping reward
// potential-based? The report goes to `out`; with a run directory, summary.json, potential.csv, its chart
// and the counterexample MDPs too. Returns the verdict (true: potential-based); bad input throws
// InputError naming the file and field.
#include <ostream>
#include <string>

#include "pegasus/runs/run_directory.hpp"
#include "pegasus/shaping/audit.hpp"

namespace pegasus {

struct ShapingAuditRunOptions {
  std::string mdp_file;                         // pegasus-mdp JSON (mdp/mdp_json.hpp)
  std::string shaping_file;                     // pegasus-shaping JSON (shaping/shaping_table.hpp)
  double tolerance = AuditOptions{}.tolerance;  // relative (shaping/audit.hpp)
  int print_limit = 50;                         // print Phi for at most this many states
};

bool run_shaping_audit(const ShapingAuditRunOptions& options, std::ostream& out, const RunDirectory* run_dir);

}  // namespace pegasus
