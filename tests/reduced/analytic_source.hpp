// An analytic 1-DOF mechanism as a KinetostaticSource, independent of Simbody: a
// slider-crank (closed-form kinematics) plus a synthetic constraint line and loads chosen
// so that every term of the reduced model has a known value.
#pragma once

#include <cmath>

#include "models/scene.hpp"
#include "reduced/kinetostatic_source.hpp"

namespace rdyn::test {

// Slider-crank: crank r about O (inertia I_c), rod l (mass m_r, centre of mass d from the
// crank pin, inertia I_r), slider m_s on the line through O.
struct SliderCrank {
  double r = 0.05, l = 0.20, I_c = 2.0e-4, m_r = 0.6, d = 0.08, I_r = 2.0e-3, m_s = 1.5;

  // T = ½ m1 θ̇²: crank rotation + rod (translation of its centre of mass and rotation) + slider.
  double m1(double th) const {
    const double s = std::sin(th), c = std::cos(th);
    const double phi = -std::asin(r * s / l);
    const double dphi = -r * c / (l * std::cos(phi));
    const double Gx = -r * s - d * dphi * std::sin(phi), Gy = r * c + d * dphi * std::cos(phi);
    const double dx = -r * s - r * r * s * c / std::sqrt(l * l - r * r * s * s);
    return I_c + m_r * (Gx * Gx + Gy * Gy) + I_r * dphi * dphi + m_s * dx * dx;
  }
  // m2 = ½ dm1/dθ by a central difference (step 1e-5: error ~1e-11 relative).
  double m2(double th) const {
    const double h = 1e-5;
    return 0.25 * (m1(th + h) - m1(th - h)) / h;
  }
};

// Synthetic remaining terms, periodic in q:
//   constraint line: me1 = 0.3 + 0.1 cos q, me2 = 0.2 sin 2q
//   potential V = k (1 − cos q) → Q_cons = −k sin q; Qx_cons = 0.4 cos q
//   joints: 0 "crank" (ratio 1), 1 "lever" (ratio cos q: zero at ±90°, rx = 0.5)
class AnalyticSource : public reduced::KinetostaticSource {
 public:
  SliderCrank sc;
  double k = 0.0;  // spring-like potential stiffness [N·m/rad]
  int calls = 0;

  int num_constraint_forces() const override { return 1; }
  int num_joints() const override { return 2; }
  static double me1(double q) { return 0.3 + 0.1 * std::cos(q); }
  static double me2(double q) { return 0.2 * std::sin(2 * q); }
  reduced::ForcePoint inertial(double q, double qd, double qdd) override {
    ++calls;
    return {sc.m1(q) * qdd + sc.m2(q) * qd * qd, {me1(q) * qdd + me2(q) * qd * qd}, {qd, std::cos(q) * qd}};
  }
  reduced::ConservativePoint conservative(double q) override {
    ++calls;
    // At rest the actuators balance the loads: T_act = −Q, F_E = −Qx.
    return {{k * std::sin(q), {-0.4 * std::cos(q)}, {0.0, 0.0}}, k * (1 - std::cos(q))};
  }
  reduced::RatioPoint ratios(double q) override {
    ++calls;
    return {{1.0, std::cos(q)}, {{0.0, 0.5}}, {}, {}, {}, {}};
  }
  // Coordinates consistent with the ratios: crank q, lever sin q (d/dq sin q = cos q).
  std::optional<double> joint_coordinate(double q, int joint) override {
    ++calls;
    return joint == 0 ? q : std::sin(q);
  }
};

// A scene naming the analytic source's joints and constraint force; loads added by tests.
inline models::Scene analytic_scene() {
  models::Scene s;
  s.name = "analytic";
  s.bodies = {{"crank", 1, {}, 1, {}}, {"lever", 1, {}, 1, {}}};
  s.joints = {{"crank", models::JointType::Revolute, models::kGround, "crank", {}, {}, {1, 0}, 0, 0},
              {"lever", models::JointType::Revolute, models::kGround, "lever", {}, {}, {1, 0}, 0, 0}};
  s.independent = "crank";
  s.outputs.constraint_forces = {{"F", "lever", {1, 0}}};
  // The source supplies a potential: declare position-only loads so extraction asks for
  // them (it skips the static call for scenes without gravity or springs).
  s.gravity.enabled = true;
  return s;
}

}  // namespace rdyn::test
