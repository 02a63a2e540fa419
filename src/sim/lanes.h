#pragma once
// Short vectors of GCC's vector extension (Clang has it too) for sums that must stay in
// order: each lane runs the scalar IEEE operation it replaces, so several independent sums
// share one register with their values unchanged (docs/solver.md, "Instruction sets").
namespace treeanim {

// Four lanes of Real.
template <typename Real>
struct Lanes4;
template <>
struct Lanes4<float> {
  using type = float __attribute__((vector_size(16)));
};
template <>
struct Lanes4<double> {
  using type = double __attribute__((vector_size(32)));
};

}  // namespace treeanim
