#include "pegasus/mdp/mdp_json.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>

#include "pegasus/core/error.hpp"
#include "pegasus/io/json_input.hpp"

namespace pegasus {

namespace {

using nlohmann::json;

[[noreturn]] void fail(const std::string& src, const std::string& field, const std::string& msg) {
  throw InputError(fmt::format("{}: {}: {}", src, field, msg));
}

// An MDP's size (states or actions): a positive int (what the file holds bounds it further, below).
int mdp_size(const json& j, const std::string& src, const char* field) {
  return static_cast<int>(
      json_integer(json_member(j, field, src, field), src, field, 1, std::numeric_limits<int>::max()));
}

// Every state is listed as absorbing or has one transitions entry per action, so the sizes the file
// declares are bounded by what it holds: checked before anything of size S*A is allocated (issue 16:
// num_states 2147483647 gave std::bad_alloc).
void check_sizes_against_contents(const json& j, const std::string& src, int S, int A) {
  const auto entries =
      j.contains("transitions") && j.at("transitions").is_array() ? j.at("transitions").size() : 0;
  const auto listed = j.contains("absorbing") && j.at("absorbing").is_array() ? j.at("absorbing").size() : 0;
  if (static_cast<std::size_t>(S) > entries + listed)
    fail(src, "num_states",
         fmt::format("expected at most {} (the states its transitions and absorbing list describe), got {}",
                     entries + listed, S));
  if (static_cast<std::size_t>(A) > std::max<std::size_t>(entries, 1))
    fail(src, "num_actions",
         fmt::format("expected at most {} (one transitions entry per state and action), got {}",
                     std::max<std::size_t>(entries, 1), A));
}

// "absorbing": the states that end an episode; returns a flag per state.
std::vector<std::uint8_t> read_absorbing(const json& j, const std::string& src, int S, FiniteMdpBuilder& b) {
  std::vector<std::uint8_t> absorbing(static_cast<std::size_t>(S), 0);
  if (!j.contains("absorbing")) return absorbing;
  const auto& abs = j.at("absorbing");
  if (!abs.is_array()) json_field_error(src, "absorbing", "an array of state indices", abs);
  for (std::size_t i = 0; i < abs.size(); ++i) {
    const int s = json_index(abs[i], src, fmt::format("absorbing[{}]", i), S, "state");
    absorbing[static_cast<std::size_t>(s)] = 1;
    b.set_absorbing(s);
  }
  return absorbing;
}

// "initial": [state, probability] pairs.
void read_initial(const json& j, const std::string& src, int S, FiniteMdpBuilder& b) {
  if (!j.contains("initial")) return;
  const auto& init = j.at("initial");
  if (!init.is_array() || init.empty())
    json_field_error(src, "initial", "a non-empty array of [state, probability]", init);
  for (std::size_t i = 0; i < init.size(); ++i) {
    const std::string f = fmt::format("initial[{}]", i);
    if (!init[i].is_array() || init[i].size() != 2) json_field_error(src, f, "[state, probability]", init[i]);
    const int s = json_index(init[i][0], src, f + "[0]", S, "state");
    const double p = json_number_in(init[i][1], src, f + "[1]", 0.0, 1.0);
    b.set_initial(s, p);
  }
}

// "state_rewards": one number per state, 0 for an absorbing one.
void read_state_rewards(const json& j, const std::string& src, int S,
                        const std::vector<std::uint8_t>& absorbing, FiniteMdpBuilder& b) {
  if (!j.contains("state_rewards")) return;
  const auto& sr = j.at("state_rewards");
  if (!sr.is_array() || sr.size() != static_cast<std::size_t>(S))
    json_field_error(src, "state_rewards", fmt::format("an array of {} numbers", S), sr);
  for (int s = 0; s < S; ++s) {
    const double r =
        json_finite_number(sr[static_cast<std::size_t>(s)], src, fmt::format("state_rewards[{}]", s));
    if (!absorbing[static_cast<std::size_t>(s)])
      b.set_state_reward(s, r);
    else if (r != 0.0)
      fail(src, fmt::format("state_rewards[{}]", s), "absorbing states must have reward 0");
  }
}

// One transitions entry's "next": [successor, probability(, reward)] rows whose probabilities sum to 1.
void read_successors(const json& next, const std::string& src, const std::string& f, int S, int s, int a,
                     FiniteMdpBuilder& b) {
  if (!next.is_array() || next.empty())
    json_field_error(src, f + ".next", "a non-empty array of [successor, probability(, reward)]", next);
  double sum = 0.0;
  for (std::size_t k = 0; k < next.size(); ++k) {
    const std::string fk = fmt::format("{}.next[{}]", f, k);
    const auto& e = next[k];
    if (!e.is_array() || (e.size() != 2 && e.size() != 3))
      json_field_error(src, fk, "[successor, probability] or [successor, probability, reward]", e);
    const int n = json_index(e[0], src, fk + "[0]", S, "successor");
    const double p = json_number_in(e[1], src, fk + "[1]", 0.0, 1.0);
    const double r = e.size() == 3 ? json_finite_number(e[2], src, fk + "[2]") : 0.0;
    sum += p;
    b.add_transition(s, a, n, p, r);
  }
  if (std::abs(sum - 1.0) > 1e-9)
    fail(src, f + ".next", fmt::format("probabilities sum to {:.12g}, expected 1 within 1e-9", sum));
}

// "transitions": one entry per non-absorbing state and action, each once.
void read_transitions(const json& j, const std::string& src, int S, int A,
                      const std::vector<std::uint8_t>& absorbing, FiniteMdpBuilder& b) {
  const auto& tr = json_member(j, "transitions", src, "transitions");
  if (!tr.is_array()) json_field_error(src, "transitions", "an array", tr);
  std::vector<std::uint8_t> seen(static_cast<std::size_t>(S) * A, 0);
  for (std::size_t i = 0; i < tr.size(); ++i) {
    const std::string f = fmt::format("transitions[{}]", i);
    const auto& t = tr[i];
    if (!t.is_object()) json_field_error(src, f, "an object with state, action, next", t);
    json_only_keys(t, {"state", "action", "reward", "next"}, src, f);
    const int s = json_index(json_member(t, "state", src, f + ".state"), src, f + ".state", S, "state");
    const int a = json_index(json_member(t, "action", src, f + ".action"), src, f + ".action", A, "action");
    if (absorbing[static_cast<std::size_t>(s)])
      fail(src, f + ".state", fmt::format("state {} is absorbing and takes no transitions", s));
    auto& flag = seen[static_cast<std::size_t>(s) * A + a];
    if (flag) fail(src, f, fmt::format("state {} action {} given twice", s, a));
    flag = 1;
    if (t.contains("reward"))
      b.set_state_action_reward(s, a, json_finite_number(t.at("reward"), src, f + ".reward"));
    read_successors(json_member(t, "next", src, f + ".next"), src, f, S, s, a, b);
  }
  for (int s = 0; s < S; ++s) {
    if (absorbing[static_cast<std::size_t>(s)]) continue;
    for (int a = 0; a < A; ++a)
      if (!seen[static_cast<std::size_t>(s) * A + a])
        fail(src, "transitions", fmt::format("no entry for state {} action {}", s, a));
  }
}

}  // namespace

FiniteMdp mdp_from_json(const json& j, const std::string& src) {
  json_format_header(j, src, "pegasus-mdp", 1);
  json_only_keys(j,
                 {"format", "version", "num_states", "num_actions", "gamma", "absorbing", "initial",
                  "state_rewards", "transitions"},
                 src, "");
  const int S = mdp_size(j, src, "num_states");
  const int A = mdp_size(j, src, "num_actions");
  const double gamma = json_number_in(json_member(j, "gamma", src, "gamma"), src, "gamma", 0.0, 1.0);
  check_sizes_against_contents(j, src, S, A);

  FiniteMdpBuilder b(S, A, gamma);
  const std::vector<std::uint8_t> absorbing = read_absorbing(j, src, S, b);
  read_initial(j, src, S, b);
  read_state_rewards(j, src, S, absorbing, b);
  read_transitions(j, src, S, A, absorbing, b);
  try {
    return b.build();
  } catch (const InputError& e) {
    std::string msg = e.what();
    if (msg.rfind("mdp: ", 0) == 0) msg = msg.substr(5);
    throw InputError(fmt::format("{}: {}", src, msg));
  }
}

json mdp_to_json(const FiniteMdp& m) {
  json j;
  j["format"] = "pegasus-mdp";
  j["version"] = 1;
  j["num_states"] = m.num_states;
  j["num_actions"] = m.num_actions;
  j["gamma"] = m.gamma;
  json abs = json::array();
  for (int s = 0; s < m.num_states; ++s)
    if (m.is_absorbing(s)) abs.push_back(s);
  j["absorbing"] = abs;
  json init = json::array();
  for (int s = 0; s < m.num_states; ++s)
    if (m.initial[static_cast<std::size_t>(s)] > 0.0)
      init.push_back(json::array({s, m.initial[static_cast<std::size_t>(s)]}));
  j["initial"] = init;
  json tr = json::array();
  for (int s = 0; s < m.num_states; ++s) {
    if (m.is_absorbing(s)) continue;
    for (int a = 0; a < m.num_actions; ++a) {
      const std::size_t r = m.row(s, a);
      const std::uint32_t b = m.row_start[r], e = m.row_start[r + 1];
      bool shared = true;
      for (std::uint32_t k = b; k < e; ++k) shared = shared && m.reward[k] == m.reward[b];
      json t;
      t["state"] = s;
      t["action"] = a;
      if (shared && e > b) t["reward"] = m.reward[b];
      json next = json::array();
      for (std::uint32_t k = b; k < e; ++k) {
        if (shared)
          next.push_back(json::array({m.next_state[k], m.probability[k]}));
        else
          next.push_back(json::array({m.next_state[k], m.probability[k], m.reward[k]}));
      }
      t["next"] = next;
      tr.push_back(std::move(t));
    }
  }
  j["transitions"] = tr;
  return j;
}

FiniteMdp load_mdp(const std::string& path) { return mdp_from_json(read_json_input(path, "MDP"), path); }

void save_mdp(const FiniteMdp& mdp, const std::string& path) {
  // Written to a temporary name and renamed, so a reader never sees half a file.
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp);
    if (!out) throw InputError(fmt::format("{}: cannot write MDP file", path));
    out << mdp_to_json(mdp).dump(1) << '\n';
    if (!out) throw InputError(fmt::format("{}: write failed", path));
  }
  std::filesystem::rename(tmp, path);
}

}  // namespace pegasus
