#pragma once
// ModuleString: a derived L-system word as flat arrays (one symbol per module, its actual
// parameters as CSR), shared by the deriver (which writes it) and the turtle (which reads it).
#include <cstdint>
#include <span>
#include <vector>

namespace treeanim {

// A module's parameter as cpfg keeps it in its string, a 32-bit float (generate.c,
// AppendParameter): a sum that creeps toward a threshold (t < 1 in steps of 0.1) crosses it at
// the step cpfg's does. Expressions and variables compute in double, as cpfg's Eval does.
inline double stored_parameter(double value) { return static_cast<double>(static_cast<float>(value)); }

struct ModuleString {
  std::vector<char> symbols;             // (n) one character per module, as in ABOP
  std::vector<uint32_t> param_offsets;   // (n+1) CSR into params; param_offsets[0] == 0
  std::vector<double> params;            // (p) actual parameters, in module order

  size_t size() const { return symbols.size(); }
  std::span<const double> params_of(size_t i) const {
    return {params.data() + param_offsets[i], params.data() + param_offsets[i + 1]};
  }
  void clear() {
    symbols.clear();
    params.clear();
    param_offsets.assign(1, 0);
  }
  void push(char symbol, std::span<const double> module_params = {}) {
    if (param_offsets.empty()) param_offsets.push_back(0);
    symbols.push_back(symbol);
    params.insert(params.end(), module_params.begin(), module_params.end());
    param_offsets.push_back(static_cast<uint32_t>(params.size()));
  }
};

}  // namespace treeanim
