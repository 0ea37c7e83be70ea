// The largest values of several quantities over a periodic cycle split into smooth pieces:
// sampled, then refined by golden-section search beside each quantity's largest sample
// (reduced/steady_cycle.cpp: speed extremes and peak constraint forces of a steady cycle).
#pragma once

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace rdyn::reduced {

// Point i of m equal sub-intervals of [a, b] (the end exactly b).
inline double sample_theta(double a, double b, int i, int m) { return i == m ? b : a + (b - a) * i / m; }

// Max of f over [lo, hi] by golden-section search, given f at both ends, to a bracket of xtol
// (at most 200 evaluations). A maximum at an end (a monotone piece, or a load switch at the
// piece's end) is found as that end.
template <typename F>
void golden_max(F&& f, double lo, double hi, double f_lo, double f_hi, double xtol, double& x_best,
                double& f_best) {
  auto keep = [&](double x, double v) {
    if (v > f_best) f_best = v, x_best = x;
  };
  keep(lo, f_lo);
  keep(hi, f_hi);
  constexpr double r = 0.6180339887498949;  // (√5 − 1)/2
  double x1 = hi - r * (hi - lo), x2 = lo + r * (hi - lo);
  double f1 = f(x1), f2 = f(x2);
  for (int it = 0; it < 200 && hi - lo > xtol; ++it) {
    if (f1 < f2) {
      lo = x1, x1 = x2, f1 = f2;
      x2 = lo + r * (hi - lo);
      f2 = f(x2);
    } else {
      hi = x2, x2 = x1, f2 = f1;
      x1 = hi - r * (hi - lo);
      f1 = f(x1);
    }
  }
  keep(x1, f1);
  keep(x2, f2);
}

// The cycle split into pieces [a_j, b_j] of θ (inside a piece every load is smooth); eval(j, θ,
// out) gives the followed quantities at θ with piece j's gates. Samples every piece at
// ≥ `samples` points per period P, then refines each quantity's largest sample by golden
// section over the sub-intervals on either side of it (in the neighbouring piece when the
// sample is a piece's end; the pieces wrap around: the cycle is periodic).
// `scan(j, θ, out)` gives the samples (it may be a cheap approximation of eval: it only picks
// which sample each refinement starts beside); every value returned comes from `eval`.
template <typename Scan, typename Eval>
void find_extremes(const std::vector<double>& a, const std::vector<double>& b, int samples, double P, int nq,
                   Scan&& scan, Eval&& eval, std::vector<double>& value, std::vector<double>& where) {
  const int pieces = static_cast<int>(a.size());
  std::vector<int> subs(pieces);
  struct Best {
    double v = -INFINITY;
    int piece = 0, i = 0;
  };
  std::vector<Best> best(nq);
  std::vector<double> out(nq);
  for (int j = 0; j < pieces; ++j) {
    subs[j] = std::max(1, static_cast<int>(std::ceil((b[j] - a[j]) * samples / P - 1e-9)));
    for (int i = 0; i <= subs[j]; ++i) {
      scan(j, sample_theta(a[j], b[j], i, subs[j]), out.data());
      for (int k = 0; k < nq; ++k)
        if (out[k] > best[k].v) best[k] = {out[k], j, i};
    }
  }
  value.assign(nq, 0.0);
  where.assign(nq, 0.0);
  const double xtol = 1e-10 * std::max(1.0, P);
  for (int k = 0; k < nq; ++k) {
    const Best& bk = best[k];
    where[k] = sample_theta(a[bk.piece], b[bk.piece], bk.i, subs[bk.piece]);
    eval(bk.piece, where[k], out.data());  // the scan's value may be an approximation
    value[k] = out[k];
    // Sub-intervals (piece, i_lo) on either side of the best sample.
    std::pair<int, int> side[2];
    const int jl = (bk.piece + pieces - 1) % pieces, jr = (bk.piece + 1) % pieces;
    side[0] = bk.i > 0 ? std::make_pair(bk.piece, bk.i - 1) : std::make_pair(jl, subs[jl] - 1);
    side[1] = bk.i < subs[bk.piece] ? std::make_pair(bk.piece, bk.i) : std::make_pair(jr, 0);
    for (const auto& [j, i] : side) {
      const double lo = sample_theta(a[j], b[j], i, subs[j]), hi = sample_theta(a[j], b[j], i + 1, subs[j]);
      auto f = [&](double th) {
        eval(j, th, out.data());
        return out[k];
      };
      const double f_lo = f(lo), f_hi = f(hi);
      golden_max(f, lo, hi, f_lo, f_hi, xtol, where[k], value[k]);
    }
  }
}

// Samples and refinement both from eval.
template <typename Eval>
void find_extremes(const std::vector<double>& a, const std::vector<double>& b, int samples, double P, int nq,
                   Eval&& eval, std::vector<double>& value, std::vector<double>& where) {
  find_extremes(a, b, samples, P, nq, eval, eval, value, where);
}

}  // namespace rdyn::reduced
