// The scene's applied loads as one Simbody custom force. Its mode, its rate-gate flags and
// the work of the non-conservative loads live in the State, so kinetostatic calls can
// switch loads off (purely inertial parameters) and forward dynamics can integrate
// W(t) = ∫ P_nc dt next to the motion for the energy balance E(t) − E(0) = W(t).
#include <cmath>

#include "engine/full_model_impl.hpp"

namespace rdyn::engine {

using namespace SimTK;

namespace {

Vec3 v3(models::Vec2 p) { return Vec3(p.x, p.y, 0); }

int load_mode(const FullModel::Impl& m, const State& s) {
  return Value<int>::downcast(m.forces.getDiscreteVariable(s, m.indices->load_mode));
}

// Whether load slot k (joint torques, then point forces) acts now.
bool load_active(const FullModel::Impl& m, const State& s, size_t k, int mode) {
  const models::RateGate* g = load_gate(m.scene, k);
  if (!g) return true;
  if (mode == kLoadsEvents) return m.gate(s, static_cast<int>(k));
  const double rate = m.joint_u(s, m.scene.joint_index(g->joint));
  return models::gate_open(g->sign, rate);
}
bool torque_active(const FullModel::Impl& m, const State& s, int i, int mode) {
  return load_active(m, s, static_cast<size_t>(i), mode);
}

// A point force's tension now [N] and its line. Where the points meet the direction is
// undefined: forward dynamics stops a run whose line passes through zero length
// (engine/forward_dynamics.cpp, checked between steps, since Simbody would only retry a step
// whose force evaluation threw); at exactly zero length e = 0 and the force vanishes.
double point_force_tension(const FullModel::Impl& m, const State& s, const models::PointForce& f,
                           PointForceLine& line, bool with_rate) {
  line = calc_point_force_line(m, s, f, with_rate);
  return models::calc_point_force_tension(f, f.profile ? m.joint_q(s, m.scene.joint_index(f.profile->of)) : 0.0);
}

// A joint torque's load now [N·m or N]: value, or value·τ(θ) of its profile's joint angle.
double torque_value(const FullModel::Impl& m, const State& s, int i) {
  const auto& t = m.scene.joint_torques[i];
  return models::calc_joint_torque(t, t.profile ? m.joint_q(s, m.scene.joint_index(t.profile->of)) : 0.0);
}

// Generalized force on a scene joint's coordinate; a folded joint's load goes to its
// driver by virtual power (τ_driver = r·τ_driven).
void add_joint_force(const FullModel::Impl& m, const State& s, int joint, double tau, Vector& mobility) {
  if (const auto& f = m.joint_fold[joint]) return add_joint_force(m, s, f->driver_joint, f->ratio * tau, mobility);
  m.joint_mobod[joint].applyOneMobilityForce(s, 0, tau, mobility);
}

class SceneLoads : public Force::Custom::Implementation {
 public:
  explicit SceneLoads(const FullModel::Impl& m) : m_(m) {}

  void realizeTopology(State& s) const override {
    auto& idx = *m_.indices;
    idx.load_mode = m_.forces.allocateDiscreteVariable(s, Stage::Dynamics, new Value<int>(kLoadsEvents));
    idx.gate.clear();
    for (size_t i = 0; i < num_load_slots(m_.scene); ++i)
      idx.gate.push_back(m_.forces.allocateDiscreteVariable(s, Stage::Dynamics, new Value<bool>(true)));
    // A statistic: changing it invalidates nothing the dynamics uses (Stage::Report).
    idx.events = m_.forces.allocateDiscreteVariable(s, Stage::Report, new Value<long>(0));
    idx.work = m_.forces.allocateZ(s, Vector(1, 0.0));
  }

  void realizeAcceleration(const State& s) const override {
    // dW/dt = power of the non-conservative loads (forward dynamics' work integral).
    s.updZDot(m_.forces.getMySubsystemIndex())[m_.indices->work] = non_conservative_power(m_, s);
  }

  void calcForce(const State& s, Vector_<SpatialVec>& body_forces, Vector_<Vec3>&,
                 Vector& mobility) const override {
    const int mode = load_mode(m_, s);
    if (mode == kLoadsOff) return;
    const auto& sc = m_.scene;
    if (sc.gravity.enabled) {
      const Vec3 g = v3(sc.gravity.g_m_s2);
      for (size_t b = 0; b < sc.bodies.size(); ++b) {
        if (m_.body_fold[b]) continue;  // folded bodies turn about their centre of mass
        const auto& mb = m_.body_mobod[b];
        mb.applyForceToBodyPoint(s, v3(sc.bodies[b].com_m), sc.bodies[b].mass_kg * g, body_forces);
      }
    }
    for (const auto& sp : sc.springs) {
      const auto& a = m_.mobod_of(sp.body_a);
      const auto& b = m_.mobod_of(sp.body_b);
      const Vec3 pa = a.findStationLocationInGround(s, v3(sp.point_a));
      const Vec3 pb = b.findStationLocationInGround(s, v3(sp.point_b));
      const Vec3 d = pb - pa;
      const double L = d.norm();
      if (L < 1e-15) continue;
      const Vec3 f_on_b = -sp.stiffness_N_per_m * (L - sp.rest_length_m) * (d / L);
      a.applyForceToBodyPoint(s, v3(sp.point_a), -f_on_b, body_forces);
      b.applyForceToBodyPoint(s, v3(sp.point_b), f_on_b, body_forces);
    }
    if (mode == kLoadsConservative) return;
    for (size_t i = 0; i < sc.joint_torques.size(); ++i)
      if (torque_active(m_, s, static_cast<int>(i), mode))
        add_joint_force(m_, s, sc.joint_index(sc.joint_torques[i].joint), torque_value(m_, s, static_cast<int>(i)),
                        mobility);
    for (size_t i = 0; i < sc.point_forces.size(); ++i) {
      if (!load_active(m_, s, sc.joint_torques.size() + i, mode)) continue;
      // Tension T pulls B toward A and A toward B: −T e on B, +T e on A (e from A to B).
      const auto& f = sc.point_forces[i];
      PointForceLine line;
      const double T = point_force_tension(m_, s, f, line, false);
      m_.mobod_of(f.body_a).applyForceToBodyPoint(s, v3(f.point_a), T * line.e_G, body_forces);
      m_.mobod_of(f.body_b).applyForceToBodyPoint(s, v3(f.point_b), -T * line.e_G, body_forces);
    }
    for (const auto& mo : sc.motors) {
      const int j = sc.joint_index(mo.joint);
      add_joint_force(m_, s, j, models::motor_torque(mo.stall_torque, mo.no_load_speed, m_.joint_u(s, j)), mobility);
    }
    for (const auto& r : sc.resistances) {
      const int b = sc.body_index(r.body);
      const double T = models::resistance_torque(r.law, r.coefficient, m_.body_rate(s, b));
      if (const auto& f = m_.body_fold[b]) {
        add_joint_force(m_, s, f->driven_joint, T, mobility);
      } else {
        m_.body_mobod[b].applyBodyTorque(s, Vec3(0, 0, T), body_forces);
      }
    }
  }

  Real calcPotentialEnergy(const State& s) const override {
    if (load_mode(m_, s) == kLoadsOff) return 0.0;
    const auto& sc = m_.scene;
    double V = 0.0;
    if (sc.gravity.enabled) {
      const Vec3 g = v3(sc.gravity.g_m_s2);
      for (size_t b = 0; b < sc.bodies.size(); ++b) {
        if (const auto& f = m_.body_fold[b]) {
          // A folded body turns about its centre of mass, fixed at its ground joint
          // (models/gear_fold.hpp): a constant, kept so that V has the same zero whether the
          // body is folded or built (the leg press's energy columns differed by its m g y,
          // 47.09 J, between the two models).
          V -= sc.bodies[b].mass_kg * dot(g, v3(sc.joints[f->driven_joint].parent_point));
          continue;
        }
        const Vec3 p = m_.body_mobod[b].findStationLocationInGround(s, v3(sc.bodies[b].com_m));
        V -= sc.bodies[b].mass_kg * dot(g, p);  // V = −m g·p
      }
    }
    for (const auto& sp : sc.springs) {
      const Vec3 pa = m_.mobod_of(sp.body_a).findStationLocationInGround(s, v3(sp.point_a));
      const Vec3 pb = m_.mobod_of(sp.body_b).findStationLocationInGround(s, v3(sp.point_b));
      V += 0.5 * sp.stiffness_N_per_m * std::pow((pb - pa).norm() - sp.rest_length_m, 2);
    }
    return V;
  }

 private:
  const FullModel::Impl& m_;
};

// Switches a gated torque when its joint rate changes sign (localized by the integrator,
// so the discontinuous torque never sits inside a step).
class GateSwitch : public TriggeredEventHandler {
 public:
  GateSwitch(const FullModel::Impl& m, int torque)  // torque: the load slot
      : TriggeredEventHandler(Stage::Velocity), m_(m), torque_(torque) {
    getTriggerInfo().setTriggerOnRisingSignTransition(true);
    getTriggerInfo().setTriggerOnFallingSignTransition(true);
    // Locate the switch to a nanosecond: the knee force jumps by hundreds of newtons there.
    getTriggerInfo().setRequiredLocalizationTimeWindow(1e-9);
  }
  Real getValue(const State& s) const override {
    const auto& gate = *load_gate(m_.scene, static_cast<size_t>(torque_));
    return m_.joint_u(s, m_.scene.joint_index(gate.joint));
  }
  void handleEvent(State& s, Real, bool&) const override {
    const auto& gate = *load_gate(m_.scene, static_cast<size_t>(torque_));
    const double rate = getValue(s);
    // The state handed over is just past the crossing; at an exact zero keep toggling.
    const bool on = rate != 0.0 ? models::gate_open(gate.sign, rate) : !m_.gate(s, torque_);
    m_.set_gate(s, torque_, on);
    ++Value<long>::updDowncast(m_.forces.updDiscreteVariable(s, m_.indices->events));
  }

 private:
  const FullModel::Impl& m_;
  int torque_;
};

}  // namespace

double non_conservative_power(const FullModel::Impl& m, const State& s) {
  const int mode = load_mode(m, s);
  if (mode == kLoadsOff || mode == kLoadsConservative) return 0.0;
  const auto& sc = m.scene;
  double P = 0.0;
  for (size_t i = 0; i < sc.joint_torques.size(); ++i) {
    const int j = sc.joint_index(sc.joint_torques[i].joint);
    if (torque_active(m, s, static_cast<int>(i), mode)) P += torque_value(m, s, static_cast<int>(i)) * m.joint_u(s, j);
  }
  for (size_t i = 0; i < sc.point_forces.size(); ++i) {
    if (!load_active(m, s, sc.joint_torques.size() + i, mode)) continue;
    PointForceLine line;
    P -= point_force_tension(m, s, sc.point_forces[i], line, true) * line.rate;  // tension works against L̇
  }
  for (const auto& mo : sc.motors) {
    const double u = m.joint_u(s, sc.joint_index(mo.joint));
    P += models::motor_torque(mo.stall_torque, mo.no_load_speed, u) * u;
  }
  for (const auto& r : sc.resistances) {
    const double w = m.body_rate(s, sc.body_index(r.body));
    P += models::resistance_torque(r.law, r.coefficient, w) * w;
  }
  return P;
}

const models::RateGate* load_gate(const models::Scene& s, size_t k) {
  const auto& g = k < s.joint_torques.size() ? s.joint_torques[k].active_when
                                             : s.point_forces.at(k - s.joint_torques.size()).active_when;
  return g ? &*g : nullptr;
}

PointForceLine calc_point_force_line(const FullModel::Impl& m, const State& s, const models::PointForce& f,
                                     bool with_rate) {
  const auto& a = m.mobod_of(f.body_a);
  const auto& b = m.mobod_of(f.body_b);
  PointForceLine line;
  line.p_GA = a.findStationLocationInGround(s, v3(f.point_a));
  line.p_GB = b.findStationLocationInGround(s, v3(f.point_b));
  const Vec3 d = line.p_GB - line.p_GA;
  line.length = d.norm();
  line.e_G = line.length > 0 ? d / line.length : Vec3(0);
  if (with_rate)
    line.rate = dot(line.e_G, b.findStationVelocityInGround(s, v3(f.point_b)) -
                                  a.findStationVelocityInGround(s, v3(f.point_a)));  // L̇ = e·(v_B − v_A)
  return line;
}

void add_scene_loads(FullModel::Impl& impl) {
  Force::Custom(impl.forces, new SceneLoads(impl));
  for (size_t k = 0; k < num_load_slots(impl.scene); ++k)
    if (load_gate(impl.scene, k)) impl.system.addEventHandler(new GateSwitch(impl, static_cast<int>(k)));
}

}  // namespace rdyn::engine
