// The exact minimum over a turn of a trigonometric polynomial: optimize's `nonnegative` shapes
// constrain it (validate/analysis/optimize.cpp).
#pragma once

#include <vector>

namespace rdyn::validate {

// min_θ of τ(θ) = a0 + Σ a_k cos kθ + b_k sin kθ (degree H = max(|a|, |b|)): the least of
// 16(H + 1) equally spaced samples, each local minimum among them refined by Newton on τ′ —
// the exact minimum to rounding, not a sample of it (`nonnegative` constrains this value).
double calc_fourier_minimum(double a0, const std::vector<double>& a, const std::vector<double>& b);

}  // namespace rdyn::validate
