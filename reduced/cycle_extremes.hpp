// The largest values of several quantities over a periodic cycle split into smooth pieces:
// sampled, then refined beside each quantity's largest sample (Brent's method, golden section)
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

// Max of f over [lo, hi] by Brent's method (parabolic steps, golden section where a parabola
// does not shrink the bracket; Brent, Algorithms for Minimization without Derivatives, 1973,
// ch. 5, as in Numerical Recipes §10.3), from x inside with f(x) = fx ≥ f(lo), f(hi): stops when
// the bracket is at most xtol wide. The maximum of a smooth f is found in ~10 evaluations where
// golden section takes ~35 for the same bracket; its value differs from golden section's by
// ~f''·xtol² (rounding), its place by at most xtol.
template <typename F>
void brent_max(F&& f, double lo, double hi, double x, double fx, double xtol, double& x_best, double& f_best) {
  constexpr double c = 0.3819660112501051;  // (3 − √5)/2
  const double tol = 0.25 * xtol;           // the bracket ends ≤ 4·tol wide
  double w = x, v = x, gx = -fx, gw = gx, gv = gx, d = 0.0, e = 0.0;  // minimises g = −f
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    if (std::abs(x - mid) <= 2 * tol - 0.5 * (hi - lo)) break;
    bool parabolic = false;
    if (std::abs(e) > tol) {  // the parabola through x, w, v
      const double r = (x - w) * (gx - gv);
      double q = (x - v) * (gx - gw), p = (x - v) * q - (x - w) * r;
      q = 2 * (q - r);
      if (q > 0) p = -p;
      q = std::abs(q);
      const double e_old = e;
      e = d;
      if (std::abs(p) < std::abs(0.5 * q * e_old) && p > q * (lo - x) && p < q * (hi - x)) {
        d = p / q;
        if (x + d - lo < 2 * tol || hi - (x + d) < 2 * tol) d = mid >= x ? tol : -tol;
        parabolic = true;
      }
    }
    if (!parabolic) {
      e = x >= mid ? lo - x : hi - x;
      d = c * e;
    }
    const double u = std::abs(d) >= tol ? x + d : x + (d >= 0 ? tol : -tol);
    const double gu = -f(u);
    if (gu <= gx) {
      (u >= x ? lo : hi) = x;
      v = w, gv = gw, w = x, gw = gx, x = u, gx = gu;
    } else {
      (u < x ? lo : hi) = u;
      if (gu <= gw || w == x) {
        v = w, gv = gw, w = u, gw = gu;
      } else if (gu <= gv || v == x || v == w) {
        v = u, gv = gu;
      }
    }
  }
  if (-gx > f_best) f_best = -gx, x_best = x;
}

// The cycle split into pieces [a_j, b_j] of θ (inside a piece every load is smooth); eval(j, θ,
// out) gives the followed quantities at θ with piece j's gates. Samples every piece at
// ≥ `samples` points per period P, then refines each quantity's largest sample over the
// sub-intervals on either side of it: by Brent's method over both when they lie in one piece and
// the sample is above both neighbours, else by golden section over each (in the neighbouring
// piece when the sample is a piece's end; the pieces wrap around: the cycle is periodic).
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
    auto f_in = [&](int j) {
      return [&, j](double th) {
        eval(j, th, out.data());
        return out[k];
      };
    };
    if (bk.i > 0 && bk.i < subs[bk.piece]) {
      // Both sub-intervals in the piece: if eval confirms the sample is above its neighbours,
      // Brent's method over the two at once, from the sample (~10 evaluations, not ~70).
      const int j = bk.piece;
      const double lo = sample_theta(a[j], b[j], bk.i - 1, subs[j]), hi = sample_theta(a[j], b[j], bk.i + 1, subs[j]);
      auto f = f_in(j);
      const double x = where[k], fx = value[k], f_lo = f(lo), f_hi = f(hi);
      if (fx >= f_lo && fx >= f_hi) {
        brent_max(f, lo, hi, x, fx, xtol, where[k], value[k]);
        continue;
      }
      golden_max(f, lo, x, f_lo, fx, xtol, where[k], value[k]);  // each side alone, as below
      golden_max(f, x, hi, fx, f_hi, xtol, where[k], value[k]);
      continue;
    }
    for (const auto& [j, i] : side) {
      const double lo = sample_theta(a[j], b[j], i, subs[j]), hi = sample_theta(a[j], b[j], i + 1, subs[j]);
      auto f = f_in(j);
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
