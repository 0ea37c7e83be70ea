// Every joint's motion and reaction and the shaking load in the full model, from Simbody at a
// state realized to Acceleration: joint coordinates and rates, mobilizer reaction forces
// (SimbodyMatterSubsystem::calcMobilizerReactionForces: the force across each mobilizer, felt by
// its outboard body at M, in Ground), loop-closure forces from the constraints' multipliers, and
// the Newton–Euler balance of all bodies for the load on the ground.
#include <cmath>

#include "engine/full_model_impl.hpp"

namespace rdyn::engine {

using namespace SimTK;

namespace {

// Rate derivative of a scene joint (folded joints through their gear).
double joint_udot(const FullModel::Impl& m, const State& s, int j) {
  if (const auto& f = m.joint_fold[j]) return f->ratio * joint_udot(m, s, f->driver_joint);
  return m.joint_mobod[j].getOneUDot(s, MobilizerUIndex(0));
}

// Force of a loop's body_a on its body_b, in Ground [N]. PointOnLine's constrained bodies are
// the line body (body_a) and the follower (body_b), in that order; Simbody reports the forces
// with its multipliers' sign (M u̇ + Gᵀλ = f: the force the constraint applies is the negative),
// in the constraint's ancestor frame.
Vec3 loop_force_on_b(const FullModel::Impl& m, const State& s, size_t loop) {
  const Constraint& c = m.constraints[loop].second;
  const Vector_<SpatialVec> F = c.getConstrainedBodyForcesAsVector(s);
  const Rotation& R_GA = c.getAncestorMobilizedBody().getBodyRotation(s);
  return -(R_GA * F[1][1]);
}

}  // namespace

void calc_joint_outputs(const FullModel::Impl& m, const State& s, std::vector<double>& out) {
  out.clear();
  const auto& sc = m.scene;
  for (const auto& name : sc.outputs.joints) {
    const int j = sc.joint_index(name);
    out.push_back(m.joint_q(s, j));
    out.push_back(m.joint_u(s, j));
    out.push_back(joint_udot(m, s, j));
  }
  Vector_<SpatialVec> reactions;
  if (!sc.outputs.reactions.empty()) m.matter.calcMobilizerReactionForces(s, reactions);
  for (const auto& name : sc.outputs.reactions) {
    const int j = sc.joint_index(name);
    if (j < 0) {  // a loop (loops are the first constraints, in scene order)
      size_t l = 0;
      while (sc.loops[l].name != name) ++l;
      const Vec3 F = loop_force_on_b(m, s, l);
      out.push_back(F[0]);
      out.push_back(F[1]);
      continue;
    }
    const auto& jt = sc.joints[j];
    const int b = sc.body_index(jt.child);
    if (m.body_fold[b]) {
      // A folded body turns about its centre of mass on a ground joint: the joint carries its
      // weight only (m a_com = 0: R = −m g).
      const double g = sc.gravity.enabled ? 1.0 : 0.0;
      out.push_back(-g * sc.bodies[b].mass_kg * sc.gravity.g_m_s2.x);
      out.push_back(-g * sc.bodies[b].mass_kg * sc.gravity.g_m_s2.y);
      continue;
    }
    const SpatialVec& R = reactions[m.body_mobod[b].getMobilizedBodyIndex()];  // [moment, force] at M, in G
    out.push_back(R[1][0]);
    out.push_back(R[1][1]);
    if (jt.type == models::JointType::Prismatic) {
      // Normal: the axis (parent frame) turned into Ground, then +90°.
      const Vec3 axis_G = m.mobod_of(jt.parent).getBodyRotation(s) * Vec3(jt.axis.x, jt.axis.y, 0);
      out.push_back(-axis_G[1] * R[1][0] + axis_G[0] * R[1][1]);
      out.push_back(R[0][2]);  // about the child point (the mobilizer's M frame origin)
    }
  }
  if (sc.outputs.shaking) {
    // Newton–Euler for all moving bodies: ground's force on them = Σ m a_c − Σ m g, its moment
    // about O = Σ (I α + r_c × m a_c) − Σ r_c × m g; the mechanism's load on the ground is the
    // opposite (Newton's third law).
    const Vec3 g = sc.gravity.enabled ? Vec3(sc.gravity.g_m_s2.x, sc.gravity.g_m_s2.y, 0) : Vec3(0);
    Vec3 F(0);
    double M = 0.0;
    for (size_t b = 0; b < sc.bodies.size(); ++b) {
      const auto& bd = sc.bodies[b];
      if (const auto& f = m.body_fold[b]) {  // turns about its fixed centre of mass
        F += bd.mass_kg * g;
        const auto& jt = sc.joints[f->driven_joint];
        const Vec3 r(jt.parent_point.x, jt.parent_point.y, 0);
        M += (r % (bd.mass_kg * g))[2] - bd.inertia_kgm2 * f->ratio * joint_udot(m, s, f->driver_joint);
        continue;
      }
      const MobilizedBody& mb = m.body_mobod[b];
      const Vec3 com(bd.com_m.x, bd.com_m.y, 0);
      const Vec3 r = mb.findStationLocationInGround(s, com);
      const Vec3 a = mb.findStationAccelerationInGround(s, com);
      const double alpha = mb.getBodyAngularAcceleration(s)[2];
      F += bd.mass_kg * (g - a);
      M += (r % (bd.mass_kg * (g - a)))[2] - bd.inertia_kgm2 * alpha;
    }
    out.push_back(F[0]);
    out.push_back(F[1]);
    out.push_back(M);
  }
}

}  // namespace rdyn::engine
