// The one instruction-set selection of the project's hand-vectorised kernels (the local-regression Gram sums,
// the dense Bellman sweep, Philox blocks for Sarsa). The build has no -march flags: each kernel is compiled
// for every set below through target regions and picked at run time from what the CPU has, detected once.
#pragma once

#include <vector>

// Compiled-in vector paths: x86-64 under GCC or clang. Elsewhere only the baseline exists.
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define PEGASUS_X86_KERNELS 1
#endif

// Target regions: every function defined between BEGIN and END is compiled for that instruction set. GCC and
// clang spell this differently (`#pragma GCC target` is not supported by clang, which the fuzz build uses).
#if defined(__clang__)
#define PEGASUS_BEGIN_AVX2_FMA_REGION \
  _Pragma("clang attribute push(__attribute__((target(\"avx2,fma,popcnt\"))), apply_to = function)")
#define PEGASUS_BEGIN_AVX512_REGION \
  _Pragma("clang attribute push(__attribute__((target(\"avx512f,avx2,fma,popcnt\"))), apply_to = function)")
#define PEGASUS_END_TARGET_REGION _Pragma("clang attribute pop")
#else
#define PEGASUS_BEGIN_AVX2_FMA_REGION _Pragma("GCC push_options") _Pragma("GCC target(\"avx2,fma,popcnt\")")
#define PEGASUS_BEGIN_AVX512_REGION \
  _Pragma("GCC push_options") _Pragma("GCC target(\"avx512f,avx2,fma,popcnt\")")
#define PEGASUS_END_TARGET_REGION _Pragma("GCC pop_options")
#endif

namespace pegasus {

// Ordered from narrowest to widest; each includes the ones before it.
enum class InstructionSet { kBaseline, kAvx2Fma, kAvx512 };

// True when the kernels were compiled with this set and the CPU running them has it.
bool instruction_set_supported(InstructionSet isa);
// The widest supported set, detected once per process.
InstructionSet best_instruction_set();
// "baseline", "avx2+fma" or "avx512": the name benchmarks and run.json report.
const char* instruction_set_name(InstructionSet isa);
// Every supported set, narrowest first (tests compare each path with the baseline).
std::vector<InstructionSet> supported_instruction_sets();

}  // namespace pegasus
