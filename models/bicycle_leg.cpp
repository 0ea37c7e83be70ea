#include "models/bicycle_leg.hpp"

#include <fmt/format.h>

#include <cmath>

#include "models/anthropometry.hpp"

namespace rdyn::models {

namespace {

constexpr double kPi = 3.14159265358979323846;

Vec2 add(Vec2 a, Vec2 b) { return {a.x + b.x, a.y + b.y}; }
Vec2 sub(Vec2 a, Vec2 b) { return {a.x - b.x, a.y - b.y}; }
Vec2 mul(double s, Vec2 a) { return {s * a.x, s * a.y}; }
double norm(Vec2 a) { return std::hypot(a.x, a.y); }
double wrap(double a) { return std::remainder(a, 2.0 * kPi); }

// Shank+foot body (frame: origin at the knee, x toward the ankle) from de Leva's
// segments, with the ankle locked at ankle_angle between the shank (pointing up, −x)
// and the sole (heel → toe, pointing forward, −y in this frame).
struct ShankFoot {
  double mass_kg, inertia_kgm2;
  Vec2 com, ankle, pedal;
};

ShankFoot make_shank_foot(const BicycleLegParams& p, const LowerLimbFractions& f) {
  const double L_s = f.shank.length * p.height_m;
  const double L_f = f.foot.length * p.height_m;
  const double h_a = f.ankle_height * p.height_m;
  const double a = p.ankle_angle_deg * kPi / 180.0;
  const Vec2 sole{-std::cos(a), -std::sin(a)};  // heel → toe
  const Vec2 down{std::sin(a), -std::cos(a)};   // ankle → sole, normal to it
  // Where the ankle and ball of the foot sit along the sole are modelling assumptions
  // (de Leva gives heel–toe length only): malleolus 23 % and first metatarsal head 73 %
  // of foot length in front of the heel; the pedal spindle is under the ball of the foot.
  const double kAnkleAlongSole = 0.23, kBallAlongSole = 0.73;
  const Vec2 ankle{L_s, 0.0};
  const Vec2 sole_below_ankle = add(ankle, mul(h_a, down));
  const Vec2 ball = add(sole_below_ankle, mul((kBallAlongSole - kAnkleAlongSole) * L_f, sole));
  const Vec2 pedal = add(ball, mul(p.pedal_stack_m, down));
  // Foot centre of mass at de Leva's fraction of heel→toe, half the ankle height up.
  const Vec2 foot_com =
      add(add(ankle, mul(0.5 * h_a, down)), mul((f.foot.com - kAnkleAlongSole) * L_f, sole));
  const Vec2 shank_com{f.shank.com * L_s, 0.0};
  const double m_s = f.shank.mass * p.mass_kg, m_f = f.foot.mass * p.mass_kg;
  const double I_s = m_s * std::pow(f.shank.gyration * L_s, 2);
  const double I_f = m_f * std::pow(f.foot.gyration * L_f, 2);
  ShankFoot sf;
  sf.mass_kg = m_s + m_f;
  sf.com = mul(1.0 / sf.mass_kg, add(mul(m_s, shank_com), mul(m_f, foot_com)));
  // Parallel-axis theorem onto the composite centre of mass.
  sf.inertia_kgm2 = I_s + m_s * std::pow(norm(sub(shank_com, sf.com)), 2) + I_f +
                    m_f * std::pow(norm(sub(foot_com, sf.com)), 2);
  sf.ankle = ankle;
  sf.pedal = pedal;
  return sf;
}

// Closed-form leg pose: hip H, pedal P, thigh length L_t, knee→pedal distance L_kp in the
// shank frame at polar angle delta. Knee in front of the line H→P (smaller x: the rider
// faces −x). Returns false when the leg cannot reach.
struct LegPose {
  double thigh_angle, shank_angle;  // of the thigh and shank frames' x axes in ground
};
bool leg_pose(Vec2 H, Vec2 P, double L_t, double L_kp, double delta, LegPose& out) {
  const Vec2 HP = sub(P, H);
  const double d = norm(HP);
  if (d > L_t + L_kp || d < std::abs(L_t - L_kp) || d == 0.0) return false;
  const Vec2 e = mul(1.0 / d, HP);
  const double a = (L_t * L_t - L_kp * L_kp + d * d) / (2.0 * d);
  const double h = std::sqrt(std::max(0.0, L_t * L_t - a * a));
  const Vec2 n{-e.y, e.x};
  const Vec2 k1 = add(add(H, mul(a, e)), mul(h, n));
  const Vec2 k2 = add(add(H, mul(a, e)), mul(-h, n));
  const Vec2 K = k1.x < k2.x ? k1 : k2;
  out.thigh_angle = std::atan2(K.y - H.y, K.x - H.x);
  out.shank_angle = std::atan2(P.y - K.y, P.x - K.x) - delta;
  return true;
}

struct Fit {
  LowerLimbFractions f;
  double L_t;
  ShankFoot sf;
  double L_kp, delta;
};

Fit make_fit(const BicycleLegParams& p) {
  Fit fit{de_leva_1996(p.sex), 0, {}, 0, 0};
  fit.L_t = fit.f.thigh.length * p.height_m;
  fit.sf = make_shank_foot(p, fit.f);
  fit.L_kp = norm(fit.sf.pedal);
  fit.delta = std::atan2(fit.sf.pedal.y, fit.sf.pedal.x);
  return fit;
}

Vec2 pedal_position(const BicycleLegParams& p, double crank_angle_from_tdc) {
  // Crank x axis at q = 0 points up (offset π/2); the bottom bracket is the origin.
  const double a = kPi / 2.0 + crank_angle_from_tdc;
  return {p.crank_length_m * std::cos(a), p.crank_length_m * std::sin(a)};
}

[[noreturn]] void fail_leg(const Scene& s, const std::string& field, const std::string& msg) {
  throw SceneError(s.source_file, 0, "bicycle_leg." + field, msg);
}

// Every input in a range a human on a bicycle can have; nothing is silently replaced.
void check_leg_params(const BicycleLegParams& p, const Scene& s) {
  struct Range {
    const char* field;
    double value, lo, hi;
    bool lo_open;  // (lo, hi] instead of [lo, hi]: zero would mean "no such part"
    const char* unit;
  };
  const Range ranges[] = {
      // de Leva's (1996) fractions are adult proportions; this spans adult statures and masses.
      {"subject.height_m", p.height_m, 0.5, 2.6, false, "m"},
      {"subject.mass_kg", p.mass_kg, 10.0, 400.0, false, "kg"},
      {"crank_length_m", p.crank_length_m, 0.05, 0.4, false, "m"},
      {"crank_mass_kg", p.crank_mass_kg, 0.0, 20.0, true, "kg"},
      // Seat-tube angles of road, time-trial and upright stationary bikes lie within 65–80°;
      // the hip stays behind (or above) the bottom bracket for the closed-form leg pose.
      {"seat_tube_angle_deg", p.seat_tube_angle_deg, 45.0, 90.0, false, "degrees"},
      {"knee_flexion_at_extension_deg", p.knee_flexion_at_extension_deg, 0.0, 90.0, true,
       "degrees"},
      // Shank–sole angle: 90° neutral; the ankle's normal range is about 20° dorsiflexion to
      // 50° plantar flexion (AAOS, Greene & Heckman 1994), i.e. 70–140°.
      {"ankle_angle_deg", p.ankle_angle_deg, 70.0, 140.0, false, "degrees"},
      {"pedal_stack_m", p.pedal_stack_m, 0.0, 0.1, false, "m"},
      // 0: no drive (a coasting or stalling rider); peak isometric hip-extension torques of
      // strong adults are a few hundred N·m.
      {"hip_torque_Nm", p.hip_torque_Nm, 0.0, 1000.0, false, "N·m"},
      {"flywheel.gear_ratio", p.gear_ratio, 0.1, 20.0, false, ""},
      {"flywheel.inertia_kgm2", p.flywheel_inertia_kgm2.value_or(1.0), 0.0, 1000.0, true, "kg·m²"},
      {"flywheel.mass_kg", p.flywheel_mass_kg, 0.0, 1000.0, true, "kg"},
      {"flywheel.bike_mass_kg", p.bike_mass_kg, 0.0, 100.0, true, "kg"},
      {"flywheel.wheel_radius_m", p.wheel_radius_m, 0.1, 0.5, false, "m"},
      {"flywheel.wheel_inertia_kgm2", p.wheel_inertia_kgm2, 0.0, 1.0, true, "kg·m²"},
      {"resistance.power_W", p.resistance_power_W, 0.0, limits::kMaxPower_W, false,
       "W (0: no resistance)"},
      {"resistance.cadence_Hz", p.resistance_cadence_Hz, 0.0, limits::kMaxCadence_Hz, true, "Hz"},
  };
  for (const Range& r : ranges) {
    const bool ok =
        std::isfinite(r.value) && (r.lo_open ? r.value > r.lo : r.value >= r.lo) && r.value <= r.hi;
    if (!ok)
      fail_leg(s, r.field, fmt::format("must be in {}{:g}, {:g}]{}{} (got {:g})", r.lo_open ? "(" : "[",
                                       r.lo, r.hi, *r.unit ? " " : "", r.unit, r.value));
  }
  if (p.legs != 1 && p.legs != 2) fail_leg(s, "legs", "must be 1 or 2");
  if (!std::isfinite(s.initial.q) || std::abs(s.initial.q) > limits::kMaxAngle_rad)
    throw SceneError(s.source_file, 0, "initial.q",
                     fmt::format("must be finite with |q| ≤ {:g} rad", limits::kMaxAngle_rad));
}

// Saddle height: the most extended pose has the pedal farthest from the hip, at
// d = D + L_c on the seat-tube line. Bisection on d for the requested knee flexion
// (flexion falls monotonically as d grows). Returns the hip's position from the bottom bracket.
Vec2 calc_hip_position(const BicycleLegParams& p, const Fit& fit, const Scene& s) {
  const double target = p.knee_flexion_at_extension_deg * kPi / 180.0;
  const double sta = p.seat_tube_angle_deg * kPi / 180.0;
  const Vec2 seat_dir{std::cos(sta), std::sin(sta)};
  auto flexion_at = [&](double d) {
    LegPose pose{};
    if (!leg_pose({0, 0}, {0, -d}, fit.L_t, fit.L_kp, fit.delta, pose)) return -1.0;
    return std::abs(wrap(pose.shank_angle - pose.thigh_angle));
  };
  double lo = std::abs(fit.L_t - fit.L_kp) + 1e-9, hi = fit.L_t + fit.L_kp - 1e-12;
  if (!(flexion_at(lo) > target && flexion_at(hi) < target))
    fail_leg(s, "knee_flexion_at_extension_deg", "no saddle height gives this knee flexion");
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (flexion_at(mid) > target ? lo : hi) = mid;
  }
  const double D = 0.5 * (lo + hi) - p.crank_length_m;
  if (D <= p.crank_length_m)
    fail_leg(s, "knee_flexion_at_extension_deg", "the hip would sit inside the crank circle");
  return mul(D, seat_dir);
}

// The crank, the flywheel and the chain that gears them.
void add_crank_and_flywheel(const BicycleLegParams& p, Scene& s) {
  // Crank (arms + chainring): assumed uniform arms, inertia m L²/3 about the spindle.
  Body crank{
      "crank", p.crank_mass_kg, {0, 0}, p.crank_mass_kg * std::pow(p.crank_length_m, 2) / 3.0, {}};
  crank.points["pedal_r"] = {p.crank_length_m, 0.0};
  crank.points["pedal_l"] = {-p.crank_length_m, 0.0};
  s.bodies.push_back(crank);
  s.joints.push_back({"crank",
                      JointType::Revolute,
                      kGround,
                      "crank",
                      {0, 0},
                      {0, 0},
                      {1, 0},
                      kPi / 2.0,
                      s.initial.q});

  const double I_road = (p.mass_kg + p.bike_mass_kg) * p.wheel_radius_m * p.wheel_radius_m +
                        2.0 * p.wheel_inertia_kgm2;
  const double I_fly = p.flywheel_inertia_kgm2.value_or(I_road);
  s.bodies.push_back({"flywheel", p.flywheel_mass_kg, {0, 0}, I_fly, {}});
  s.joints.push_back({"flywheel",
                      JointType::Revolute,
                      kGround,
                      "flywheel",
                      s.ground_points["flywheel_axle"],
                      {0, 0},
                      {1, 0},
                      0.0,
                      p.gear_ratio * s.initial.q});
  s.gears.push_back({"chain", "crank", "flywheel", p.gear_ratio});
}

// One leg (`leg` 0: right, 1: left, half a turn behind): thigh and shank posed to reach the
// pedal at the initial crank angle, hip and knee joints, the pedal loop and the hip torque.
void add_leg(const BicycleLegParams& p, const Fit& fit, Vec2 hip, int leg, Scene& s) {
  const double m_t = fit.f.thigh.mass * p.mass_kg;
  const std::string side = leg == 0 ? "r" : "l";
  const double q_leg = s.initial.q + (leg == 0 ? 0.0 : kPi);
  LegPose pose{};
  if (!leg_pose(hip, pedal_position(p, q_leg), fit.L_t, fit.L_kp, fit.delta, pose))
    fail_leg(s, "legs", "the leg cannot reach the pedal at the initial crank angle");
  Body thigh{"thigh_" + side,
             m_t,
             {fit.f.thigh.com * fit.L_t, 0},
             m_t * std::pow(fit.f.thigh.gyration * fit.L_t, 2),
             {}};
  thigh.points["hip"] = {0, 0};
  thigh.points["knee"] = {fit.L_t, 0};
  Body shank{"shank_" + side, fit.sf.mass_kg, fit.sf.com, fit.sf.inertia_kgm2, {}};
  shank.points["knee"] = {0, 0};
  shank.points["ankle"] = fit.sf.ankle;
  shank.points["pedal"] = fit.sf.pedal;
  s.bodies.push_back(thigh);
  s.bodies.push_back(shank);
  s.joints.push_back({"hip_" + side,
                      JointType::Revolute,
                      kGround,
                      thigh.name,
                      hip,
                      {0, 0},
                      {1, 0},
                      0.0,
                      pose.thigh_angle});
  s.joints.push_back({"knee_" + side,
                      JointType::Revolute,
                      thigh.name,
                      shank.name,
                      {fit.L_t, 0},
                      {0, 0},
                      {1, 0},
                      0.0,
                      wrap(pose.shank_angle - pose.thigh_angle)});
  s.loops.push_back({"pedal_" + side, shank.name, fit.sf.pedal, "crank",
                     s.find_body("crank")->points.at("pedal_" + side), std::nullopt});
  // Hip torque pushes the thigh down (counter-clockwise: the knee is in front, at −x),
  // and acts only while the thigh descends, i.e. while its angle increases.
  if (p.hip_torque_Nm != 0.0)
    s.joint_torques.push_back(
        {"hip_torque_" + side, "hip_" + side, p.hip_torque_Nm, RateGate{"hip_" + side, +1}});
}

}  // namespace

double bicycle_knee_flexion(const BicycleLegParams& p, const Scene& scene, double crank_q) {
  const Fit fit = make_fit(p);
  LegPose pose{};
  if (!leg_pose(scene.ground_points.at("hip"), pedal_position(p, crank_q), fit.L_t, fit.L_kp,
                fit.delta, pose))
    return NAN;
  return std::abs(wrap(pose.shank_angle - pose.thigh_angle));
}

void make_bicycle_leg(const BicycleLegParams& p, Scene& s) {
  check_leg_params(p, s);
  Fit fit;
  try {
    fit = make_fit(p);
  } catch (const std::invalid_argument& e) {
    fail_leg(s, "subject.sex", e.what());
  }
  const Vec2 hip = calc_hip_position(p, fit, s);
  s.ground_points["bottom_bracket"] = {0.0, 0.0};
  s.ground_points["hip"] = hip;
  s.ground_points["flywheel_axle"] = {0.40, 0.0};
  add_crank_and_flywheel(p, s);
  for (int leg = 0; leg < p.legs; ++leg) add_leg(p, fit, hip, leg, s);

  // Resistance on the flywheel dissipating P at the cadence f of the crank.
  const double omega = p.gear_ratio * 2.0 * kPi * p.resistance_cadence_Hz;  // flywheel [rad/s]
  if (p.resistance_power_W > 0.0) {
    if (!(omega > 0.0)) fail_leg(s, "resistance.cadence_Hz", "must be positive");
    s.resistances.push_back(
        {"flywheel_resistance", "flywheel", p.resistance_law,
         p.resistance_power_W / std::pow(omega, dissipation_exponent(p.resistance_law))});
  }
  s.independent = "crank";
}

}  // namespace rdyn::models
