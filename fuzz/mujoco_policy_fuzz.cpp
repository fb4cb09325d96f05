// libFuzzer harness: MuJoCo policy files (mujoco/mujoco_policy: parse_mujoco_policy_file), the policy.json
// that `pegasus mujoco rollout --policy` reads. Any bytes are accepted or refused with one InputError line
// naming the file; an accepted file holds finite numbers, a normaliser of matching sizes and a positive clip,
// and is written back (mujoco_policy_file_json) into a file that reads as the same policy. Built only where
// MuJoCo is.
#include <cmath>
#include <string>

#include "fuzz_contract.hpp"
#include "pegasus/io/atomic_file.hpp"
#include "pegasus/io/json_input.hpp"
#include "pegasus/mujoco/mujoco_policy.hpp"

namespace {
bool same(const pegasus::MujocoPolicyFile& a, const pegasus::MujocoPolicyFile& b) {
  return a.model == b.model && a.task == b.task && a.policy_class == b.policy_class && a.hidden == b.hidden &&
         a.phase == b.phase && a.theta == b.theta && a.normalizer.mean == b.normalizer.mean &&
         a.normalizer.inverse_std == b.normalizer.inverse_std && a.normalizer.clip == b.normalizer.clip;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  pegasus::fuzz::refuses_input_past_its_limit(
      [](const std::string& file) { (void)pegasus::read_mujoco_policy_file(file); },
      pegasus::kMaxDataFileBytes);
  const std::string_view text = pegasus::fuzz::as_text(data, size);
  pegasus::fuzz::keeps_error_contract("policy.json", [&] {
    const pegasus::MujocoPolicyFile f = pegasus::parse_mujoco_policy_file(
        pegasus::parse_json_input(text, "policy.json", "policy"), "policy.json");
    for (const double x : f.theta)
      if (!std::isfinite(x))
        pegasus::fuzz::violation("an accepted file with a theta that is not finite", text);
    if (f.normalizer.mean.size() != f.normalizer.inverse_std.size() || !(f.normalizer.clip > 0))
      pegasus::fuzz::violation("an accepted file with a normaliser that does not fit", text);
    const pegasus::MujocoPolicyFile again = pegasus::parse_mujoco_policy_file(
        pegasus::parse_json_input(pegasus::mujoco_policy_file_json(f).dump(), "again.json", "policy"),
        "again.json");
    if (!same(f, again)) pegasus::fuzz::violation("a policy that does not read back as itself", text);
  });
  return 0;
}
