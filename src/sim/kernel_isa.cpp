#include "sim/kernel_isa.h"

#include <algorithm>
#include <cstdlib>
#include <string>

#include "common/message_text.h"

namespace treeanim {

namespace {

KernelIsa widest_supported() {
#if defined(__x86_64__) && defined(__GNUC__)
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f")) return KernelIsa::kAvx512;
  if (__builtin_cpu_supports("avx2")) return KernelIsa::kAvx2;
#endif
  return KernelIsa::kPortable;
}

// AVX2 where the CPU runs it, unless TREEANIM_ISA names another set: AVX-512 was slower on
// the machines measured (docs/solver.md, "Instruction sets").
KernelIsa pick() {
  const KernelIsa widest = widest_supported();
  const char* asked = std::getenv("TREEANIM_ISA");
  if (!asked) return std::min(KernelIsa::kAvx2, widest);
  for (KernelIsa isa : {KernelIsa::kPortable, KernelIsa::kAvx2, KernelIsa::kAvx512})
    if (std::string(asked) == kernel_isa_name(isa)) return isa < widest ? isa : widest;
  return KernelIsa::kPortable;  // the command line refused it (asked_isa_error)
}

}  // namespace

std::string asked_isa_error() {
  const char* asked = std::getenv("TREEANIM_ISA");
  if (!asked) return "";
  for (KernelIsa isa : {KernelIsa::kPortable, KernelIsa::kAvx2, KernelIsa::kAvx512})
    if (std::string(asked) == kernel_isa_name(isa)) return "";
  return std::string("TREEANIM_ISA: expected portable, avx2 or avx512 (or unset: avx2 where the CPU "
                     "has it, else portable), got '") + excerpt(asked) + "'";
}

KernelIsa kernel_isa() {
  static const KernelIsa isa = pick();
  return isa;
}

const char* kernel_isa_name(KernelIsa isa) {
  switch (isa) {
    case KernelIsa::kAvx512: return "avx512";
    case KernelIsa::kAvx2: return "avx2";
    case KernelIsa::kPortable: break;
  }
  return "portable";
}

}  // namespace treeanim
