#include "validate/analysis/optimize_design.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "validate/analysis/fourier_minimum.hpp"

namespace rdyn::validate {

double eval_series(const Series& s, double th) {
  double v = s.a0;
  for (size_t k = 0; k < s.a.size(); ++k) v += s.a[k] * std::cos((k + 1) * th) + s.b[k] * std::sin((k + 1) * th);
  return v;
}

double series_minimum(const Series& s) { return calc_fourier_minimum(s.a0, s.a, s.b); }

Series group_series(const Design& d, int g, const double* x) {
  const Group& gr = d.groups[g];
  Series s;
  int i = gr.offset;
  s.a0 = gr.fixed_a0 ? 1.0 : x[i++];
  s.a.assign(x + i, x + i + d.H);
  s.b.assign(x + i + d.H, x + i + 2 * d.H);
  return s;
}

// τ(θ − s) as a series in θ: cos k(θ−s) = cos kθ cos ks + sin kθ sin ks, sin k(θ−s) = sin kθ cos ks − cos kθ sin ks.
Series shifted(const Series& s, double shift) {
  Series r = s;
  for (size_t k = 0; k < s.a.size(); ++k) {
    const double c = std::cos((k + 1) * shift), sn = std::sin((k + 1) * shift);
    r.a[k] = s.a[k] * c - s.b[k] * sn;
    r.b[k] = s.a[k] * sn + s.b[k] * c;
  }
  return r;
}

models::Scene shaped_scene(models::Scene s, const Design& d, const double* x) {
  for (const auto& dl : d.loads) {
    const Series sr = shifted(group_series(d, dl.group, x), dl.shift);
    models::LoadProfile p;
    p.of = d.of;
    p.a0 = sr.a0, p.a = sr.a, p.b = sr.b;
    s.joint_torques[dl.torque].profile = p;
  }
  return s;
}

Design resolve_design(const models::Scene& s, const models::OptimizeSpec& spec, const OptimizeOptions& opt) {
  auto fail = [&](const std::string& field, const std::string& msg) {
    const int line = s.line_of("optimize.loads") ? s.line_of("optimize.loads") : s.line_of("optimize");
    throw models::SceneError(s.source_file, line, field, msg);
  };
  Design d;
  d.H = opt.harmonics > 0 ? opt.harmonics : spec.harmonics;
  d.of = spec.of.empty() ? s.independent : spec.of;
  const double max_load = opt.max_load > 0 ? opt.max_load : spec.max_load;
  // `key`: the design entry's own key (its line, or its --set), when the name comes from the block.
  auto index_of = [&](const std::string& name, const std::string& key) {
    for (size_t i = 0; i < s.joint_torques.size(); ++i)
      if (s.joint_torques[i].name == name) return i;
    const std::string msg = "no joint_torque named '" + name + "' to design (design loads are the scene's joint "
                            "torques as loaded, --set overrides applied)";
    if (!key.empty() && (s.line_of(key) > 0 || s.field_of(key) != key))
      throw models::SceneError(s.source_file, s.line_of(key), s.field_of(key), msg);
    fail("optimize.loads", msg);
    return size_t(0);
  };
  std::vector<models::OptimizeLoad> listed = spec.loads;
  if (listed.empty())
    for (const auto& t : s.joint_torques)
      if (std::find(opt.add_torques.begin(), opt.add_torques.end(), t.joint) == opt.add_torques.end() ||
          t.name != "torque_" + t.joint)
        listed.push_back({t.name, "", 0.0});
  std::vector<std::string> group_of_name;
  for (size_t k = 0; k < listed.size(); ++k) {
    const auto& l = listed[k];
    DesignLoad dl;
    dl.torque = index_of(l.load, spec.loads.empty() ? "" : fmt::format("optimize.loads[{}].load", k));
    if (l.same_as.empty()) {
      dl.group = static_cast<int>(d.groups.size());
      Group g;
      g.fixed_a0 = d.groups.empty();
      g.nonnegative = spec.nonnegative;
      g.bound = max_load;
      d.groups.push_back(g);
      group_of_name.push_back(l.load);
    } else {
      const auto it = std::find(group_of_name.begin(), group_of_name.end(), l.same_as);
      if (it == group_of_name.end())
        fail("optimize.loads", "'" + l.load + "' takes the shape of '" + l.same_as + "', which is not listed before it");
      dl.group = static_cast<int>(it - group_of_name.begin());
      dl.shift = l.shift_rad;
    }
    d.loads.push_back(dl);
  }
  for (const auto& j : opt.add_torques) {  // signed shapes of their own, starting from zero
    DesignLoad dl;
    dl.torque = index_of("torque_" + j, "");
    dl.group = static_cast<int>(d.groups.size());
    Group g;
    g.fixed_a0 = d.groups.empty();
    g.nonnegative = false;
    g.bound = opt.add_torque_max;
    g.a0_start = 0.0;
    d.groups.push_back(g);
    d.loads.push_back(dl);
  }
  // Calibration scales every joint torque together: each must be a design load.
  for (size_t i = 0; i < s.joint_torques.size(); ++i)
    if (std::none_of(d.loads.begin(), d.loads.end(), [&](const DesignLoad& dl) { return dl.torque == i; }))
      fail("optimize.loads", fmt::format("joint torque '{}' is not a design load: the amplitude is calibrated for "
                                         "every joint torque together, so list it (a shape of its own or same_as)",
                                         s.joint_torques[i].name));
  for (auto& g : d.groups) {
    g.offset = d.n;
    d.n += (g.fixed_a0 ? 0 : 1) + 2 * d.H;
  }
  return d;
}

}  // namespace rdyn::validate
