#pragma once
// The instruction set the solver's hot loops run in, picked once at run time (docs/solver.md,
// "Instruction sets"). Every path gives the same bytes: the build never contracts a * b + c
// (-ffp-contract=off), no loop is reassociated, and a wider vector only runs more lanes of
// the same elementwise arithmetic.
#include <string>
#include <utility>

namespace treeanim {

enum class KernelIsa { kPortable, kAvx2, kAvx512 };

// AVX2 (the baseline, x86-64's SSE2, on a CPU without it), or the set named by the
// environment variable TREEANIM_ISA (portable, avx2, avx512), narrowed to what this CPU
// runs. Read on the first call.
KernelIsa kernel_isa();
// => "portable", "avx2" or "avx512".
const char* kernel_isa_name(KernelIsa isa);
// What is wrong with TREEANIM_ISA ("" when it is unset or names a set), for the command line
// to refuse before kernel_isa() would fall back to portable unseen.
std::string asked_isa_error();

#if defined(__x86_64__) && defined(__GNUC__)
// f() compiled for the set: `flatten` inlines everything it calls (the kernels, the lambdas)
// into the clone, so its loops are vectorised for that set.
template <typename F>
[[gnu::target("avx2"), gnu::flatten]] inline decltype(auto) call_avx2(F& f) {
  return f();
}
template <typename F>
[[gnu::target("avx512f"), gnu::flatten]] inline decltype(auto) call_avx512(F& f) {
  return f();
}
#endif

// f() in the loops of kernel_isa().
template <typename F>
inline decltype(auto) with_kernel_isa(F&& f) {
#if defined(__x86_64__) && defined(__GNUC__)
  switch (kernel_isa()) {
    case KernelIsa::kAvx512: return call_avx512(f);
    case KernelIsa::kAvx2: return call_avx2(f);
    case KernelIsa::kPortable: break;
  }
#endif
  return f();
}

}  // namespace treeanim
