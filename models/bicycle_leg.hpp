// Bicycle-leg generator: a subject on a stationary bicycle as a planar four-bar per leg
// (ground hip–thigh–knee–shank+foot–pedal–crank), the foot fixed to the pedal (ankle
// locked), and a flywheel geared to the crank.
//
// Frames: ground x points to the REAR of the bicycle, y up; the rider faces −x, so
// forward pedalling is a positive (counter-clockwise) crank rotation. The crank angle q
// is measured from top dead centre of the right pedal. The thigh frame has x from hip to
// knee; the shank+foot frame has x from knee to ankle (the anatomical shank axis).
#pragma once

#include <optional>
#include <string>

#include "models/scene.hpp"

namespace rdyn::models {

struct BicycleLegParams {
  // Subject (defaults: de Leva's 1996 reference male).
  double height_m = 1.741;
  double mass_kg = 73.0;
  std::string sex = "male";
  int legs = 2;  // 1 or 2; the second leg is 180° out of phase

  // Bike fit. The hip sits on the seat-tube line behind the bottom bracket at the
  // distance that gives `knee_flexion_at_extension_deg` at the most extended pose.
  double crank_length_m = 0.170;
  double crank_mass_kg = 1.0;
  double seat_tube_angle_deg = 73.0;
  double knee_flexion_at_extension_deg = 30.0;
  double ankle_angle_deg = 100.0;  // locked angle between shank (up) and sole (forward)
  double pedal_stack_m = 0.02;     // pedal spindle below the sole

  // Flywheel: turns at gear_ratio × crank. Without inertia_kgm2, the "road equivalent":
  // the kinetic energy of rider + bicycle moving on the road plus the two wheels
  // spinning, I = (m_rider + m_bike)·r_wheel² + 2·I_wheel (as the original authors did).
  double gear_ratio = 3.0;  // chainring/sprocket, e.g. 48/16
  std::optional<double> flywheel_inertia_kgm2;
  double flywheel_mass_kg = 10.0;
  double bike_mass_kg = 9.0;
  double wheel_radius_m = 0.335;
  double wheel_inertia_kgm2 = 0.09;

  // Loads: hip torque while the thigh descends; flywheel resistance.
  double hip_torque_Nm = 69.7;
  ResistanceLaw resistance_law = ResistanceLaw::Viscous;
  double resistance_power_W = 125.0;
  double resistance_cadence_Hz = 1.0;
};

// Builds bodies, joints, loops, gear, independent coordinate and loads into `scene`
// (which must not already have any). Names: thigh_r/l, shank_r/l, crank, flywheel;
// joints hip_r/l, knee_r/l, crank, flywheel; loops pedal_r/l; shank points knee,
// ankle, pedal. Every parameter is checked first (ranges in docs/scene-format.md); throws
// SceneError naming the field ("bicycle_leg.flywheel.gear_ratio") and its range, or an
// impossible fit.
void make_bicycle_leg(const BicycleLegParams& p, Scene& scene);

// Knee flexion [rad] of the right leg at crank angle q (closed-form leg pose); exposed
// for tests and the bike-fit search.
double bicycle_knee_flexion(const BicycleLegParams& p, const Scene& scene, double crank_q);

}  // namespace rdyn::models
