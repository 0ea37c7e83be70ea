#include "validate/analysis/table_check.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "reduced/extract.hpp"
#include "validate/analysis/build_reduced.hpp"

namespace rdyn::validate {

namespace {

constexpr double kPi = 3.14159265358979323846;

[[noreturn]] void refuse(const reduced::Samples& t, long line, const std::string& what) {
  throw reduced::TableError(fmt::format("{}:{}: {}; the table has no content checksum, so it was compared with a "
                                        "fresh extraction of scene '{}': extract it again with `rdyn extract`",
                                        t.file.empty() ? std::string("table") : t.file, line, what, t.scene));
}

// Two sorted lists of grid points [rad or m] agree to `tol`.
bool same_points(const std::vector<double>& a, const std::vector<double>& b, double tol) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (std::abs(a[i] - b[i]) > tol) return false;
  return true;
}

std::string q_text(const reduced::Samples& t, double q) {
  return t.revolute ? fmt::format("{:g}°", q * 180.0 / kPi) : fmt::format("{:g} m", q);
}

// The --grid-deg the table was extracted with: its step for a full turn; a range table has as
// many intervals as a full turn at that grid, kDeadPointRefinement times as many when an edge is
// a dead point (reduced::range_intervals). The grid whose intervals those are; else 360/n, and
// the re-extraction's grid then differs and is refused as such.
double extraction_grid_deg(const reduced::Samples& t) {
  if (t.periodic || t.q.size() < 2) return t.step * 180.0 / kPi;
  const long n = static_cast<long>(t.q.size()) - 1;
  const bool dead = t.min_edge == "dead point" || t.max_edge == "dead point";
  for (long per_turn : {n, n / reduced::kDeadPointRefinement}) {
    if (per_turn < 4) continue;
    const double g = 360.0 / static_cast<double>(per_turn);
    try {
      if (reduced::range_intervals(t.q.back() - t.q.front(), g * kPi / 180.0, t.revolute, dead) == n) return g;
    } catch (const reduced::TableError&) {
      // not this grid
    }
  }
  return 360.0 / static_cast<double>(n);
}

}  // namespace

void check_table_against_scene(const reduced::Samples& t, const models::Scene& scene) {
  const Extraction fresh = extract_from_full(scene, extraction_grid_deg(t), reduced::parse_method(t.method));
  const reduced::Samples& f = fresh.samples;
  const double q_tol = 1e-9 * std::max(1.0, std::abs(t.q0) + t.step * static_cast<double>(t.q.size()));
  if (f.periodic != t.periodic)
    refuse(t, 1, fmt::format("its header says periodic={} where the scene's table is {}", t.periodic ? 1 : 0,
                             f.periodic ? "periodic (periodic=1: a full turn)" : "a range (periodic=0)"));
  if (f.q.size() != t.q.size() || !same_points(f.q, t.q, q_tol))
    refuse(t, 1,
           fmt::format("its grid ({} points from {}) is not the one the scene gives ({} points from {})", t.q.size(),
                       q_text(t, t.q.empty() ? 0.0 : t.q.front()), f.q.size(), q_text(f, f.q.empty() ? 0.0 : f.q.front())));
  for (size_t c = 0; c < f.names.size(); ++c) {
    const int tc = t.column(f.names[c]);
    if (tc < 0) refuse(t, t.header_line, fmt::format("the column header has no column '{}', which the scene needs", f.names[c]));
    const auto& want = f.columns[c];
    const auto& got = t.columns[tc];
    double scale = 0.0;
    for (double v : want) scale = std::max(scale, std::abs(v));
    for (size_t i = 0; i < want.size(); ++i)
      if (!(std::abs(got[i] - want[i]) <= kTableCheckRelTol * std::max(scale, 1e-12)))
        refuse(t, t.header_line + 1 + static_cast<long>(i),
               fmt::format("column '{}' at q = {} is {:.10g}, the scene gives {:.10g}", f.names[c], q_text(t, t.q[i]),
                           got[i], want[i]));
  }
  if (t.names.size() != f.names.size())
    refuse(t, t.header_line, fmt::format("it has {} columns, the scene gives {}", t.names.size(), f.names.size()));
  if (!same_points(f.singular_q, t.singular_q, q_tol)) {
    if (t.singular_q.empty())  // line 2 is where it belongs
      refuse(t, 2, fmt::format("it has no '# singular' line where the scene has {} singular configuration(s), the "
                               "first at q = {}",
                               f.singular_q.size(), q_text(f, f.singular_q.front())));
    if (f.singular_q.size() != t.singular_q.size())
      refuse(t, 2, fmt::format("its '# singular' line lists {} configuration(s) where the scene has {}", t.singular_q.size(),
                               f.singular_q.size()));
    size_t i = 0;  // same count: name the first configuration that moved
    while (i + 1 < f.singular_q.size() && std::abs(f.singular_q[i] - t.singular_q[i]) <= q_tol) ++i;
    refuse(t, 2, fmt::format("its '# singular' line lists q = {} where the scene's singular configuration is at q = {}",
                             q_text(t, t.singular_q[i]), q_text(f, f.singular_q[i])));
  }
  // `rdyn extract` writes the '# singular' line on line 2, then one '# pole' line per force.
  const long first_pole_line = t.singular_q.empty() ? 2 : 3;
  for (const auto& [force, qs] : f.poles) {
    const auto it = std::find_if(t.poles.begin(), t.poles.end(), [&](const auto& p) { return p.first == force; });
    const long line = first_pole_line + (it == t.poles.end() ? 0 : static_cast<long>(it - t.poles.begin()));
    if (it == t.poles.end() || !same_points(it->second, qs, q_tol))
      refuse(t, line, fmt::format("its '# pole {}' line is missing or changed: the scene's force '{}' grows without bound "
                               "at q = {}",
                               force, force, q_text(t, qs.front())));
  }
  if (t.poles.size() != f.poles.size()) refuse(t, first_pole_line, "it lists a '# pole' line the scene does not give");
}

}  // namespace rdyn::validate
