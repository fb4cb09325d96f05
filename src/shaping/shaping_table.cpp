#include "pegasus/shaping/shaping_table.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <tuple>

#include "pegasus/core/error.hpp"
#include "pegasus/io/json_input.hpp"
#include "pegasus/shaping/potential_shaping.hpp"

namespace pegasus {

namespace {
auto key(const ShapingEntry& e) { return std::tie(e.state, e.action, e.next); }
}  // namespace

ShapingTable::ShapingTable(int num_states, int num_actions, std::vector<ShapingEntry> entries)
    : S_(num_states), A_(num_actions), entries_(std::move(entries)) {
  if (S_ < 1 || A_ < 1) throw InputError("shaping: expected at least 1 state and 1 action");
  for (std::size_t i = 0; i < entries_.size(); ++i) {
    const auto& e = entries_[i];
    if (e.state < 0 || e.state >= S_ || e.next < 0 || e.next >= S_ || e.action < 0 || e.action >= A_)
      throw InputError(fmt::format("shaping: entry ({}, {}, {}) outside {} states x {} actions", e.state,
                                   e.action, e.next, S_, A_));
    if (!std::isfinite(e.value))
      throw InputError(fmt::format("shaping: F({}, {}, {}) is not finite", e.state, e.action, e.next));
  }
  std::sort(entries_.begin(), entries_.end(), [](const auto& x, const auto& y) { return key(x) < key(y); });
  for (std::size_t i = 1; i < entries_.size(); ++i)
    if (key(entries_[i]) == key(entries_[i - 1]))
      throw InputError(fmt::format("shaping: triple ({}, {}, {}) listed twice", entries_[i].state,
                                   entries_[i].action, entries_[i].next));
}

double ShapingTable::operator()(int s, int a, int next) const {
  const ShapingEntry probe{s, a, next, 0.0};
  const auto it = std::lower_bound(entries_.begin(), entries_.end(), probe,
                                   [](const auto& x, const auto& y) { return key(x) < key(y); });
  return (it != entries_.end() && key(*it) == key(probe)) ? it->value : 0.0;
}

bool ShapingTable::contains(int s, int a, int next) const {
  const ShapingEntry probe{s, a, next, 0.0};
  return std::binary_search(entries_.begin(), entries_.end(), probe,
                            [](const auto& x, const auto& y) { return key(x) < key(y); });
}

ShapingTable ShapingTable::from_potential(const FiniteMdp& mdp, std::span<const double> phi) {
  if (phi.size() != static_cast<std::size_t>(mdp.num_states))
    throw InputError(fmt::format("potential: expected {} values, got {}", mdp.num_states, phi.size()));
  auto p = [&](int s) { return mdp.is_absorbing(s) ? 0.0 : phi[static_cast<std::size_t>(s)]; };
  std::vector<ShapingEntry> e;
  for (int s = 0; s < mdp.num_states; ++s) {
    if (mdp.is_absorbing(s)) continue;
    for (int a = 0; a < mdp.num_actions; ++a) {
      const std::size_t r = mdp.row(s, a);
      for (std::uint32_t k = mdp.row_start[r]; k < mdp.row_start[r + 1]; ++k) {
        const int n = mdp.next_state[k];
        e.push_back({s, a, n, potential_shaping_reward(mdp.gamma, p(s), p(n))});
      }
    }
  }
  return ShapingTable(mdp.num_states, mdp.num_actions, std::move(e));
}

ShapingTable ShapingTable::progress_bonus(const FiniteMdp& mdp, std::span<const double> distance,
                                          double bonus) {
  if (distance.size() != static_cast<std::size_t>(mdp.num_states))
    throw InputError(
        fmt::format("progress bonus: expected {} distances, got {}", mdp.num_states, distance.size()));
  std::vector<ShapingEntry> e;
  for (int s = 0; s < mdp.num_states; ++s) {
    if (mdp.is_absorbing(s)) continue;
    for (int a = 0; a < mdp.num_actions; ++a) {
      const std::size_t r = mdp.row(s, a);
      for (std::uint32_t k = mdp.row_start[r]; k < mdp.row_start[r + 1]; ++k) {
        const int n = mdp.next_state[k];
        if (distance[static_cast<std::size_t>(n)] < distance[static_cast<std::size_t>(s)])
          e.push_back({s, a, n, bonus});
      }
    }
  }
  return ShapingTable(mdp.num_states, mdp.num_actions, std::move(e));
}

FiniteMdp add_shaping(const FiniteMdp& mdp, const ShapingTable& f) {
  if (f.num_states() != mdp.num_states || f.num_actions() != mdp.num_actions)
    throw InputError(fmt::format("shaping: table is {} states x {} actions, the MDP {} x {}", f.num_states(),
                                 f.num_actions(), mdp.num_states, mdp.num_actions));
  return add_shaping(mdp, [&f](int s, int a, int n) { return f(s, a, n); });
}

ShapingTable shaping_from_json(const nlohmann::json& j, const std::string& src) {
  json_format_header(j, src, "pegasus-shaping", 1);
  json_only_keys(j, {"format", "version", "num_states", "num_actions", "entries"}, src, "");
  const auto count = [&](const char* k) {
    return static_cast<int>(json_integer(json_member(j, k, src, k), src, k, 1, 1LL << 30));
  };
  const int S = count("num_states"), A = count("num_actions");
  const auto& en = json_member(j, "entries", src, "entries");
  if (!en.is_array()) json_field_error(src, "entries", "an array of [state, action, next_state, F]", en);
  std::vector<ShapingEntry> out;
  out.reserve(en.size());
  for (std::size_t i = 0; i < en.size(); ++i) {
    const std::string f = fmt::format("entries[{}]", i);
    const auto& e = en[i];
    if (!e.is_array() || e.size() != 4) json_field_error(src, f, "[state, action, next_state, F]", e);
    const int state = json_index(e[0], src, f + "[0]", S, "state");
    const int action = json_index(e[1], src, f + "[1]", A, "action");
    const int next_state = json_index(e[2], src, f + "[2]", S, "next_state");
    out.push_back({state, action, next_state, json_finite_number(e[3], src, f + "[3]")});
  }
  try {
    return ShapingTable(S, A, std::move(out));
  } catch (const InputError& e) {
    std::string msg = e.what();
    if (msg.rfind("shaping: ", 0) == 0) msg = msg.substr(9);
    throw InputError(fmt::format("{}: entries: {}", src, msg));
  }
}

nlohmann::json shaping_to_json(const ShapingTable& f) {
  nlohmann::json j;
  j["format"] = "pegasus-shaping";
  j["version"] = 1;
  j["num_states"] = f.num_states();
  j["num_actions"] = f.num_actions();
  auto en = nlohmann::json::array();
  for (const auto& e : f.entries()) en.push_back(nlohmann::json::array({e.state, e.action, e.next, e.value}));
  j["entries"] = en;
  return j;
}

ShapingTable load_shaping(const std::string& path) {
  return shaping_from_json(read_json_input(path, "shaping"), path);
}

void save_shaping(const ShapingTable& f, const std::string& path) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp);
    if (!out) throw InputError(fmt::format("{}: cannot write shaping file", path));
    out << shaping_to_json(f).dump(1) << '\n';
    if (!out) throw InputError(fmt::format("{}: write failed", path));
  }
  std::filesystem::rename(tmp, path);
}

}  // namespace pegasus
