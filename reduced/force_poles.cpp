// check_force_poles (declared in reduced/reduced_model.hpp): a requested force whose table
// parameters have a pole near q is refused, named as the scene names it.
#include <cmath>
#include <string>

#include <fmt/format.h>

#include "models/scene.hpp"
#include "reduced/reduced_model.hpp"

namespace rdyn::reduced {

void check_force_poles(const ReducedModel& m, double q, double t) {
  for (size_t k = 0; k < m.force_poles.size(); ++k)
    for (double p : m.force_poles[k]) {
      const double d = m.table.periodic ? std::remainder(q - p, 2 * M_PI) : q - p;
      if (!(std::abs(d) < m.pole_band)) continue;
      const bool deg = m.revolute;
      // A reaction's internal line (R_<joint>_gx, _gy: reduced/joint_outputs.hpp) is named as the user
      // asked for it (a flat parallelogram was told to leave out 'R_crank_gx', a name never written).
      const std::string& f = m.force_names[k];
      const std::string tail = f.size() > 5 ? f.substr(f.size() - 3) : "";
      const bool line = f.rfind("R_", 0) == 0 && (tail == "_gx" || tail == "_gy");
      const std::string j = line ? f.substr(2, f.size() - 5) : "";
      const std::string what = line ? fmt::format("the reaction of joint '{0}' (R_{0}_x, R_{0}_y)", j)
                                    : fmt::format("constraint force '{}'", f);
      const std::string leave = line ? fmt::format("leave joint '{}' out of outputs.reactions (list the joints)", j)
                                     : fmt::format("leave '{}' out of the scene's outputs", f);
      throw models::NumericalError(fmt::format(
          "the reduced model cannot give {} at t = {:.6g} s, q = {}: its parameters have a pole "
          "at the singular configuration q = {} (the constraint actuator's rates diverge there) and no "
          "interpolation of the table represents it within {} of it; use --model full, or {}",
          what, t, deg ? fmt::format("{:.6g}°", q * 180 / M_PI) : fmt::format("{:.6g} m", q),
          deg ? fmt::format("{:.6g}°", p * 180 / M_PI) : fmt::format("{:.6g} m", p),
          std::isinf(m.pole_band) ? std::string("a whole turn (fourier)")
                                  : deg ? fmt::format("{:.6g}°", m.pole_band * 180 / M_PI)
                                        : fmt::format("{:.6g} m", m.pole_band),
          leave));
    }
}

}  // namespace rdyn::reduced
