// Interpolated reduced parameters as one fused piecewise-cubic table: every column is a
// cubic a + b·dx + c·dx² + d·dx³ on each grid interval, so one index lookup serves all
// parameters at a q (allocation-free, a few multiply-adds per column).
#pragma once

#include <string>
#include <vector>

#include "reduced/samples.hpp"

namespace rdyn::reduced {

enum class Interpolation {
  CubicSpline,  // cubic spline: GSL periodic for a full turn, not-a-knot ends over a range
  Akima,        // GSL Akima (periodic variant for a full turn): local, no overshoot
  Linear,       // GSL linear
  Fourier,      // periodic only: trigonometric interpolant of the samples (spectral accuracy
                // for smooth periodic columns), resampled at ≤ 1° into the cubic table
};
Interpolation parse_interpolation(const std::string& name);  // throws TableError
std::string interpolation_name(Interpolation i);

struct Table {
  bool periodic = true;
  double q0 = 0.0;    // first grid point
  double step = 0.0;  // grid step
  // 1 / step, set with it by build_table: locate multiplies instead of dividing (a division's
  // latency sits on the chain from one RK stage to the next).
  double inv_step = 0.0;
  double period = 0.0;
  int intervals = 0;  // periodic: N (wrapping), otherwise N − 1
  int cols = 0;
  // The interpolant actually built: a range table takes a not-a-knot cubic spline for `cubic`
  // and in place of `fourier` (no period); `fourier` is resampled into the cubic table.
  std::string fit;
  std::vector<std::string> names;
  std::vector<double> coef;  // [interval][col][4]

  // Interval index and offset dx ∈ [0, step) of q (periodic: wrapped; otherwise clamped —
  // callers check in_range first).
  int locate(double q, double& dx) const;
  bool in_range(double q) const;
  double eval(int col, double q) const;
  double eval_deriv(int col, double q) const;  // d/dq
  // Evaluates the listed columns at q into out (one locate).
  void eval_cols(double q, const int* cols_idx, int n, double* out) const;
  int column(const std::string& name) const;  // −1 when absent
};

// A fixed list of a table's columns repacked for evaluating them together (the reduced
// model's right-hand-side and output columns): coefficients [interval][power 0..3][k], so one
// locate serves every column and the Horner sums run over contiguous memory, vectorized across
// columns. The same arithmetic as Table::eval_cols, hence the same values bit for bit.
struct ColumnBlock {
  std::vector<int> cols;     // table columns, in output order (repeats allowed)
  std::vector<double> coef;  // [interval][power][k]
};
ColumnBlock make_column_block(const Table& t, const std::vector<int>& cols);
// Evaluates every column of the block at q into out[0 .. b.cols.size()). Allocation-free.
void eval_block(const Table& t, const ColumnBlock& b, double q, double* out);

// Builds the table. Throws TableError when the samples are inconsistent (fewer than 4 points,
// a step that is not finite and positive, columns of another length than the grid).
// energy_consistent_m2
// replaces m2 by ½ dm1/dq of the m1 interpolant (Eksergian's identity) and Q_cons by −dV/dq of
// the V interpolant, so that ½ m1 q̇² + V is conserved exactly by the reduced equation when no
// non-conservative load acts.
Table build_table(const Samples& samples, Interpolation interp, bool energy_consistent_m2 = false);

}  // namespace rdyn::reduced
