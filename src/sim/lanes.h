#pragma once
// Short vectors of GCC's vector extension (Clang has it too) for sums that must stay in
// order: each lane runs the scalar IEEE operation it replaces, so several independent sums
// share one register with their values unchanged (docs/solver.md, "Instruction sets").
// Functions take and give them by reference: passed by value, a 32-byte vector's calling
// convention would depend on the instruction set.
#include <cmath>

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

// Four doubles, e.g. one value of four clusters; a comparison of two gives a Mask4, each lane
// all ones (true) or zero.
using Double4 = Lanes4<double>::type;
using Mask4 = decltype(Double4{} < Double4{});

// Row `row` of a 3 x 3 matrix times a vector, from its three products p0, p1, p2 => their sum
// as the library sums it: rows 0 and 1 in order (they run as one vector of two), row 2 alone,
// its last two products first. T: a double, or four in lanes.
template <typename T>
inline void matrix_row_sum(int row, const T& p0, const T& p1, const T& p2, T& sum) {
  sum = row < 2 ? (p0 + p1) + p2 : p0 + (p1 + p2);
}

// Four square roots, each the scalar one.
inline void sqrt_lanes(Double4& x) {
  for (int i = 0; i < 4; ++i) x[i] = std::sqrt(x[i]);
}

}  // namespace treeanim
