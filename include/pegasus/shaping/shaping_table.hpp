#pragma once
// A tabular shaping function F(s, a, s'), the input of the shaping audit.
//
// JSON file format:
//   {
//     "format": "pegasus-shaping",   required, exactly this string
//     "version": 1,
//     "num_states": 3, "num_actions": 2,   must match the MDP it is used with
//     "entries": [[0, 1, 2, 0.5], ...]     [state, action, next_state, F]; each triple at most once
//   }
// A triple that is not listed has F = 0. Errors name the file and the field
// ("f.json: entries[4][2]: next_state 9 outside [0, 3)").
#include <nlohmann/json_fwd.hpp>
#include <span>
#include <string>
#include <vector>

#include "pegasus/mdp/finite_mdp.hpp"

namespace pegasus {

struct ShapingEntry {
  int state = 0, action = 0, next = 0;
  double value = 0.0;
};

class ShapingTable {
 public:
  ShapingTable() = default;
  // Throws InputError on an index out of range, a non-finite value or a repeated triple.
  ShapingTable(int num_states, int num_actions, std::vector<ShapingEntry> entries);

  int num_states() const { return S_; }
  int num_actions() const { return A_; }
  // F(s, a, s'); 0 for unlisted triples.
  double operator()(int s, int a, int next) const;
  bool contains(int s, int a, int next) const;
  // Sorted by (state, action, next).
  const std::vector<ShapingEntry>& entries() const { return entries_; }

  // F = gamma Phi(s') - Phi(s) on every transition of `mdp` (Phi(absorbing) = 0).
  static ShapingTable from_potential(const FiniteMdp& mdp, std::span<const double> phi);
  // The progress bonus (+bonus when distance(s') < distance(s)) on every transition of `mdp`.
  static ShapingTable progress_bonus(const FiniteMdp& mdp, std::span<const double> distance, double bonus);

 private:
  int S_ = 0, A_ = 0;
  std::vector<ShapingEntry> entries_;
};

// M + F on M's transitions (unlisted triples add 0).
FiniteMdp add_shaping(const FiniteMdp& mdp, const ShapingTable& f);

ShapingTable shaping_from_json(const nlohmann::json& j, const std::string& source = "shaping");
nlohmann::json shaping_to_json(const ShapingTable& f);
ShapingTable load_shaping(const std::string& path);
void save_shaping(const ShapingTable& f, const std::string& path);

}  // namespace pegasus
