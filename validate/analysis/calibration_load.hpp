// The load a calibration sets (validate/analysis/calibrate.hpp): which scene loads `--load` names
// (one joint torque, one motor's stall torque, one point force's tension, or every joint torque
// together), their signs, and the magnitude applied to a scene or to a reduced model.
#pragma once

#include <string>
#include <vector>

#include "models/scene.hpp"
#include "reduced/reduced_model.hpp"
#include "validate/analysis/calibrate.hpp"

namespace rdyn::validate {

// The load being calibrated: one joint torque, one motor's stall torque, or every joint
// torque together. Each entry is applied as sign·T with T ≥ 0 the calibrated magnitude.
struct Entry {
  bool motor = false;
  size_t index = 0;    // into scene.joint_torques, scene.motors or scene.point_forces (same order in the reduced model)
  double sign = 1.0;   // the scene value's sign (a motor's: its no-load speed's)
  bool point_force = false;  // a point force's tension (index into point_forces)
};
struct Selection {
  std::vector<Entry> entries;
  std::string name, kind, unit;
  bool together = false;  // several loads, each set to sign·T: the result is the magnitude T
};

// Which load `opt.load` names (empty: every joint torque). Throws SceneError naming
// opt.load_field for an unknown load or one that is not a drive load.
Selection select_load(const models::Scene& scene, const CalibrationOptions& opt);

// The value of entry e in the scene / in the reduced model (its torques, motors and point forces
// are the scene's, in order), and its name.
double& value_of(models::Scene& s, const Entry& e);
double& value_of(reduced::ReducedModel& m, const Entry& e);
const std::string& name_of(const models::Scene& s, const Entry& e);
// "N" on a prismatic joint, "N·m" otherwise.
const char* unit_of(const models::Scene& s, const std::string& joint);

// The selected load set to magnitude T (signs kept) in a scene, and with a power the one
// resistance's coefficient (NaN: unchanged).
models::Scene with_load(models::Scene s, const Selection& sel, double T, double coefficient);
// The scene at a calibration's operating point: its load and resistance at the values found and
// its one initial state the point (steady_q, steady_qdot) of the reduced steady cycle (the scene's
// own initial speed and q replaced, never combined). What the full model confirms and a sweep's
// peak columns run.
models::Scene scene_at_operating_point(const models::Scene& scene, const CalibrationOptions& opt,
                                       const CalibrationResult& r);
// The same in the reduced model.
void set_load(reduced::ReducedModel& m, const Selection& sel, double T);

}  // namespace rdyn::validate
