// Whether a periodic table resolves its mechanism: a cheap check from the table alone, no
// further kinetostatic calls. No Simbody.
#pragma once

#include <vector>

namespace rdyn::reduced {

// The half-grid miss of a periodic column sampled at n equally spaced points over a turn (n
// even, ≥ 8): the trigonometric interpolant through the even-indexed samples (a table of twice
// the step) evaluated at the odd-indexed ones, largest |miss| relative to max |y| (0 for a zero
// column). A trig polynomial of degree below n/4 gives rounding; a column whose harmonics reach
// n/4 and beyond gives O(1). Measured on m1 at 10° against the reduced model's q̈ error over a
// run (full model as reference): slider-crank 1.7e-7, fourbar 1.4e-4 (q̈ 1e-5), bicycle 8e-5,
// a geared quick-return 1e-3 (2.4e-4), the light-flywheel bicycle 9.8e-3 (1.1e-2), a Jansen leg
// 0.10 (6e-2) and a five-bar geared 2:1 0.10 (0.40): the table's own error is of the order of
// the miss or larger. NaN when n is odd or below 8.
double calc_half_grid_miss(const std::vector<double>& y);

// Above this half-grid miss of m1 the reduced model warns that its table is likely too coarse.
// (2 %: the shipped scenes stay at least 2× below it, the two coarse cases above 5× above).
inline constexpr double kCoarseTableMiss = 2e-2;

}  // namespace rdyn::reduced
