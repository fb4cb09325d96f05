#pragma once
// The JSON file format of a finite MDP.
//
//   {
//     "format": "pegasus-mdp",          required, exactly this string
//     "version": 1,                     required
//     "num_states": 3,                  S >= 1; states are 0 .. S-1
//     "num_actions": 2,                 A >= 1; actions are 0 .. A-1
//     "gamma": 0.95,                    in [0, 1]; 1 requires a proper MDP (§2.1)
//     "absorbing": [2],                 optional; absorbing states need no transitions
//     "initial": [[0, 1.0]],            optional [state, probability] pairs; default uniform over
//                                       the non-absorbing states
//     "state_rewards": [0, 0, 0],       optional R(s) form, one number per state (reward of leaving s)
//     "transitions": [                  one object per non-absorbing (state, action), none missing
//       {"state": 0, "action": 0,
//        "reward": -1,                  optional R(s, a) form
//        "next": [[1, 0.8], [0, 0.2, 5.0]]}   [successor, probability] or
//     ]                                       [successor, probability, R(s, a, s')]
//   }
//
// The three reward forms add up: R(s, a, s') = state_rewards[s] + reward + the third element.
// save_mdp writes every reward in the R(s, a, s') form (and "reward" when a whole row shares one value),
// with the shortest decimal that reads back to the same double, so load(save(m)) == m exactly.
// Errors are InputError messages naming the file and the field, e.g.
//   "m.json: transitions[3].next[1][1]: probability 1.2 outside [0, 1]".
#include <nlohmann/json_fwd.hpp>
#include <string>

#include "pegasus/mdp/finite_mdp.hpp"

namespace pegasus {

FiniteMdp mdp_from_json(const nlohmann::json& j, const std::string& source = "mdp");
nlohmann::json mdp_to_json(const FiniteMdp& mdp);

FiniteMdp load_mdp(const std::string& path);
void save_mdp(const FiniteMdp& mdp, const std::string& path);

}  // namespace pegasus
