#include "pegasus/core/instruction_set.hpp"

namespace pegasus {

bool instruction_set_supported(InstructionSet isa) {
  switch (isa) {
    case InstructionSet::kBaseline:
      return true;
#ifdef PEGASUS_X86_KERNELS
    case InstructionSet::kAvx2Fma:
      return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") &&
             __builtin_cpu_supports("popcnt");
    case InstructionSet::kAvx512:
      return instruction_set_supported(InstructionSet::kAvx2Fma) && __builtin_cpu_supports("avx512f");
#endif
    default:
      return false;
  }
}

InstructionSet best_instruction_set() {
  static const InstructionSet best =
      instruction_set_supported(InstructionSet::kAvx512)    ? InstructionSet::kAvx512
      : instruction_set_supported(InstructionSet::kAvx2Fma) ? InstructionSet::kAvx2Fma
                                                            : InstructionSet::kBaseline;
  return best;
}

const char* instruction_set_name(InstructionSet isa) {
  switch (isa) {
    case InstructionSet::kAvx2Fma:
      return "avx2+fma";
    case InstructionSet::kAvx512:
      return "avx512";
    default:
      return "baseline";
  }
}

std::vector<InstructionSet> supported_instruction_sets() {
  std::vector<InstructionSet> sets;
  for (const InstructionSet isa :
       {InstructionSet::kBaseline, InstructionSet::kAvx2Fma, InstructionSet::kAvx512})
    if (instruction_set_supported(isa)) sets.push_back(isa);
  return sets;
}

}  // namespace pegasus
