// The design of `rdyn optimize`: which joint torques are shaped, grouped (same_as, shifted),
// and the parameter vector x of their Fourier series; the shaped scene a point x describes.
#pragma once

#include <string>
#include <vector>

#include "models/scene.hpp"
#include "validate/analysis/optimize.hpp"

namespace rdyn::validate {

// A shape group: design loads sharing one series (same_as), shifted per load.
struct Group {
  bool fixed_a0 = false;  // the first group's a0 ≡ 1 (the amplitude carries the scale)
  bool nonnegative = true;
  double bound = 0.0;     // max |value·τ| [N·m or N]
  int offset = 0;         // first parameter in x
  double a0_start = 1.0;
};
struct DesignLoad {
  size_t torque = 0;      // index into scene.joint_torques
  int group = 0;
  double shift = 0.0;     // [rad]: τ(θ) = τ_group(θ − shift)
};
struct Design {
  std::string of;
  int H = 3;
  std::vector<Group> groups;
  std::vector<DesignLoad> loads;
  int n = 0;  // parameters
};

struct Series {
  double a0 = 0.0;
  std::vector<double> a, b;
};

// τ(θ) of a series.
double eval_series(const Series& s, double th);
// min_θ τ(θ) of a series: the true minimum, not a sample (calc_fourier_minimum).
double series_minimum(const Series& s);
// Group g's series at the parameter vector x (the first group's a0 ≡ 1).
Series group_series(const Design& d, int g, const double* x);
// τ(θ − shift) as a series in θ.
Series shifted(const Series& s, double shift);
// The scene with every design load profiled by its group's series at x (shifted per load).
models::Scene shaped_scene(models::Scene s, const Design& d, const double* x);
// The design: groups, loads, their starting point, from the scene's optimize block and the
// options; SceneError naming the field.
Design resolve_design(const models::Scene& s, const models::OptimizeSpec& spec, const OptimizeOptions& opt);

}  // namespace rdyn::validate
