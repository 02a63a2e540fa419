#pragma once
// The sines and cosines of a turn by their Taylor series, on plain doubles in Horner's form,
// for "samples" (docs/solver.md, "Its own choices"): a double, or four in lanes (lanes.h),
// each lane the scalar's arithmetic, with no call into the library's sine and cosine, which
// took a tenth of a leafy tree's step where its leaves turn tenths of a radian.
#include <array>

namespace treeanim {

constexpr int kSeriesTerms = 12;  // the largest power of a2 below is kSeriesTerms - 1
// 1 / n!, n <= 2 kSeriesTerms
constexpr std::array<double, 2 * kSeriesTerms + 1> kInverseFactorials = [] {
  std::array<double, 2 * kSeriesTerms + 1> f{};
  f[0] = 1;
  for (int n = 1; n <= 2 * kSeriesTerms; ++n) f[n] = f[n - 1] / n;
  return f;
}();

// a2 = a^2 => sum, the sum of (-1)^k coefficient(k) a2^k over k < Terms, from the last term
// (by reference: lanes.h).
template <int Terms, typename T, typename Coefficient>
inline void alternating_series(const T& a2, Coefficient coefficient, T& sum) {
  static_assert(Terms >= 1 && Terms <= kSeriesTerms);
  sum = T{} + ((Terms - 1) % 2 ? -1.0 : 1.0) * coefficient(Terms - 1);
  for (int k = Terms - 1; k-- > 0;) sum = sum * a2 + (k % 2 ? -1.0 : 1.0) * coefficient(k);
}

// Rodrigues' factors sin a / a and (1 - cos a) / a^2 of a turn a, a2 = a^2 below 2.56 (1.6 rad,
// past the quarter turn that caps a joint of the bar chain): to a^22, the next terms below
// 1e-18 there.
template <typename T>
inline void rodrigues_factors(const T& a2, T& sine, T& versine) {
  alternating_series<kSeriesTerms>(a2, [](int k) { return kInverseFactorials[2 * k + 1]; }, sine);
  alternating_series<kSeriesTerms>(a2, [](int k) { return kInverseFactorials[2 * k + 2]; }, versine);
}

// A quaternion's factors sin(a/2) / a and cos(a/2) of a turn a, a2 = a^2 at most 1 (the trust
// region of a rotation's Newton step): to a^14, the next terms below 1e-18 there.
template <typename T>
inline void half_turn_factors(const T& a2, T& half_sinc, T& cosine) {
  constexpr int kTerms = 8;
  // (a/2)^2k / (2k)! = a2^k / (4^k (2k)!), and sin(a/2) / a = sum (a/2)^(2k+1) / ((2k+1)! a)
  constexpr auto quarter_power = [](int k) {
    double p = 1;
    for (int i = 0; i < k; ++i) p *= 0.25;
    return p;
  };
  alternating_series<kTerms>(a2, [=](int k) { return 0.5 * quarter_power(k) * kInverseFactorials[2 * k + 1]; },
                             half_sinc);
  alternating_series<kTerms>(a2, [=](int k) { return quarter_power(k) * kInverseFactorials[2 * k]; }, cosine);
}

}  // namespace treeanim
