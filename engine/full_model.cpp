// Builds the Simbody system of a scene: one mobilizer per scene joint (pin or slider),
// loop closures as point-on-line constraints (two rows each, no redundancy), gears as
// coordinate couplers or folded onto their driver, constraint actuators as prescribed
// sliders, and the independent coordinate driven by a prescribed law when enabled.
#include "engine/full_model_impl.hpp"
#include "engine/branch_guard.hpp"
#include "engine/branch_rates.hpp"
#include "engine/independent_range.hpp"
#include "engine/inspect.hpp"  // kFarFromGuess_deg
#include "engine/kinetostatic.hpp"

#include <cctype>
#include <cmath>
#include <cstring>

#include <fmt/format.h>

#include "models/scene_yaml.hpp"

namespace rdyn::engine {

using namespace SimTK;
using models::JointType;

Law poly_law(double q, double qdot, double qddot) { return Law(0, q, qdot, qddot, 0, 0); }
Law harmonic_law(double c1, double c2, double c3, double c4, double c5) {
  return Law(1, c1, c2, c3, c4, c5);
}

namespace {

Vec3 v3(models::Vec2 p) { return Vec3(p.x, p.y, 0); }

// Motion::Custom prescribing q(t) from a Law held in the State, so that changing the
// law is a Stage::Time change (no re-realization of the instance).
class LawMotion : public Motion::Custom::Implementation {
 public:
  LawMotion(const FullModel::Impl& impl, int slot) : impl_(impl), slot_(slot) {}
  Motion::Level getLevel(const State&) const override { return Motion::Position; }
  void realizeTopology(State& s) const override {
    auto& idx = impl_.indices->law;
    if (static_cast<int>(idx.size()) <= slot_) idx.resize(slot_ + 1);
    idx[slot_] = impl_.matter.allocateDiscreteVariable(s, Stage::Time, new Value<Law>(Law(0)));
  }
  void calcPrescribedPosition(const State& s, int nq, Real* q) const override { q[0] = eval(s, 0); }
  void calcPrescribedPositionDot(const State& s, int nq, Real* qd) const override { qd[0] = eval(s, 1); }
  void calcPrescribedPositionDotDot(const State& s, int nq, Real* qdd) const override { qdd[0] = eval(s, 2); }

 private:
  double eval(const State& s, int order) const {
    const Law& c = Value<Law>::downcast(impl_.matter.getDiscreteVariable(s, impl_.indices->law[slot_]));
    const double t = s.getTime();
    if (c[0] == 0) {  // c1 + c2 t + ½ c3 t²
      return order == 0 ? c[1] + c[2] * t + 0.5 * c[3] * t * t : order == 1 ? c[2] + c[3] * t : c[3];
    }
    const double ph = c[4] * t + c[5];  // c1 + c2 t + c3 cos(c4 t + c5)
    return order == 0   ? c[1] + c[2] * t + c[3] * std::cos(ph)
           : order == 1 ? c[2] - c[3] * c[4] * std::sin(ph)
                        : -c[3] * c[4] * c[4] * std::cos(ph);
  }
  const FullModel::Impl& impl_;
  int slot_;
};

// Planar rigid body: mass, centre of mass and centroidal z inertia; the out-of-plane
// moments are set equal to Izz (any valid value works: rotation stays about z).
MassProperties planar_mass(double m, models::Vec2 com, double Izz_c, double extra_Izz) {
  Inertia about_origin = Inertia(Izz_c).shiftFromMassCenter(v3(com), m);
  if (extra_Izz > 0) about_origin += Inertia(extra_Izz);  // massless: same about any point
  return MassProperties(m, v3(com), about_origin);
}

// Each loop that names its branch must have closed on it: the named joint's coordinate (a
// revolute angle wrapped to (−180°, 180°]) has the sign asked for. Zero (the boundary between
// the branches, a singular position) is neither.
void check_branches(const FullModel::Impl& m, const State& s) {
  for (const auto& l : m.scene.loops) {
    if (!l.branch) continue;
    const int j = m.scene.joint_index(l.branch->joint);
    if (j < 0) throw EngineError(fmt::format("{}: loop '{}' names its branch by an unknown joint '{}'",
                                             m.scene.source_file, l.name, l.branch->joint));
    const auto& jt = m.scene.joints[j];
    const bool rev = jt.type == JointType::Revolute;
    const double q = m.joint_q(s, j);
    const double v = rev ? std::remainder(q, 2 * Pi) : q;
    if (l.branch->sign * v > 0) continue;
    const double shown = rev ? v * 180 / Pi : v;
    throw EngineError(fmt::format(
        "{}: loop '{}' assembled on the other branch: joint '{}' is at {:.6g}{} but the "
        "branch asks for a {} value{}; move the guesses toward that branch (e.g. {} of '{}')",
        models::where(m.scene, "loops." + l.name + ".branch"), l.name, jt.name, shown, rev ? "° (wrapped to (−180°, 180°])" : " m",
        l.branch->sign > 0 ? "positive" : "negative", v == 0 ? " (0 is the boundary between the branches)" : "",
        rev ? "guess_deg" : "guess_m", jt.name));
  }
}

// Every point force and spring has a direction where the mechanism assembles: its points are apart.
void check_point_forces(const FullModel::Impl& m, const State& s) {
  // One refusal for both kinds: a load whose two points (nearly) coincide has no line of action.
  auto refuse_if_close = [&](const char* kind, const std::string& name, const std::string& body_a,
                             const std::string& body_b, double L) {
    if (L >= models::limits::kMinPointForceLength_m) return;
    const std::string field = "loads." + name + ".point_b";
    throw models::SceneError(
        m.scene.source_file, m.scene.line_of(field), field,
        fmt::format("{} '{}': point_b on '{}' lies {:.3g} m from point_a on '{}' in the assembled configuration "
                    "(at {} = {:.6g}), closer than {:g} m: the line of action has no direction",
                    kind, name, body_b, L, body_a, m.scene.independent, m.scene.initial.q,
                    models::limits::kMinPointForceLength_m));
  };
  for (const auto& f : m.scene.point_forces)
    refuse_if_close("point force", f.name, f.body_a, f.body_b, calc_point_force_line(m, s, f, false).length);
  // A spring too: its force k (L − L0) acts along a line that has no direction at L = 0 (the full
  // model skipped it there, the reduced model's potential did not: the two then disagree).
  for (const auto& sp : m.scene.springs) {
    const Vec3 p_GA = m.mobod_of(sp.body_a).findStationLocationInGround(s, v3(sp.point_a));
    const Vec3 p_GB = m.mobod_of(sp.body_b).findStationLocationInGround(s, v3(sp.point_b));
    refuse_if_close("spring", sp.name, sp.body_a, sp.body_b, (p_GB - p_GA).norm());
  }
}

}  // namespace

namespace {

// Requests the builder can honour (check_scene refuses the others with a line number; this keeps
// a scene built in code from reaching Simbody with a dangling handle). The independent joint is
// accepted (its pin is prescribed, the sliders after it carry the child): the reduced model's
// reaction lines (reduced/joint_outputs.hpp) use it.
void check_constraint_force_requests(const models::Scene& scene) {
  for (const auto& c : scene.outputs.constraint_forces) {
    const int j = scene.joint_index(c.joint);
    if (j < 0 || scene.joints[j].type != JointType::Revolute || !(std::hypot(c.direction.x, c.direction.y) > 0))
      throw EngineError(fmt::format("{}: constraint force '{}' needs a revolute joint and a non-zero direction",
                                    scene.source_file, c.name));
  }
}

// Stage 1: which geared bodies can be folded onto their driver (models/gear_fold.hpp): a leaf
// turning about a fixed axis through its centre of mass, touched by nothing else, whose motion
// is not requested. Its kinetic energy ½ I (r u)² becomes ½ (r² I) u² on the driver.
struct GearFolding {
  std::vector<double> extra_inertia;  // [body] kg·m² moved onto it
  std::vector<bool> folded;           // [gear]
};
GearFolding fold_geared_bodies(FullModel::Impl& m) {
  GearFolding out{std::vector<double>(m.scene.bodies.size(), 0.0), std::vector<bool>(m.scene.gears.size(), false)};
  if (!m.options.fold_geared_bodies) return out;
  for (const auto& f : models::calc_gear_folds(m.scene)) {
    m.joint_fold[f.driven_joint] = f;
    m.body_fold[f.body] = f;
    out.folded[f.gear] = true;
    out.extra_inertia[f.driver_body] += f.moved_inertia_kgm2;
  }
  return out;
}

// A revolute joint with requested constraint forces (the Actuator route): a pin to a massless
// frame C turned like the child (rotation offset + q), then one slider per requested direction
// d_k (child frame), in series, the last carrying the child. Each slider's F and M frames are
// Rz(a_k) so it slides along d_k and leaves the orientation alone: R_PB = Rz(offset) Rz(q). In
// series every slider carries the whole joint force, so its multiplier is that force projected
// on its own d_k (virtual power: ẋ_k moves the child along d_k), whatever the other directions
// are — the Reaction route's quantity.
void add_actuated_pin(FullModel::Impl& m, int j, MobilizedBody& parent, const Body::Rigid& info,
                      const std::vector<int>& requests) {
  const auto& jt = m.scene.joints[j];
  MobilizedBody::Pin pin(parent, Transform(Rotation(jt.offset_rad, ZAxis), v3(jt.parent_point)), Body::Massless(),
                         Transform());
  MobilizedBody carrier = pin;
  for (size_t i = 0; i < requests.size(); ++i) {
    const auto& d = m.scene.outputs.constraint_forces[requests[i]].direction;
    const Rotation R_d(std::atan2(d.y, d.x), ZAxis);
    const bool last = i + 1 == requests.size();
    MobilizedBody::Slider slider(carrier, Transform(R_d), last ? Body(info) : Body(Body::Massless()),
                                 Transform(R_d, last ? v3(jt.child_point) : Vec3(0)));
    m.actuator_slider[requests[i]] = slider;
    carrier = slider;
  }
  m.joint_mobod[j] = pin;
  m.body_mobod[m.scene.body_index(jt.child)] = carrier;
}

// The mobilizer of joint j (its parent already built): a slider, a pin, or a pin with constraint
// actuators.
void add_joint_mobilizer(FullModel::Impl& m, int j, const std::vector<double>& extra_inertia) {
  const auto& scene = m.scene;
  const auto& jt = scene.joints[j];
  MobilizedBody parent = jt.parent == models::kGround ? MobilizedBody(m.matter.updGround())
                                                      : m.body_mobod[scene.body_index(jt.parent)];
  const int b = scene.body_index(jt.child);
  const auto& bd = scene.bodies[b];
  const Body::Rigid info(planar_mass(bd.mass_kg, bd.com_m, bd.inertia_kgm2, extra_inertia[b]));
  std::vector<int> requests;  // constraint forces asked of this joint
  for (size_t k = 0; k < scene.outputs.constraint_forces.size(); ++k)
    if (scene.outputs.constraint_forces[k].joint == jt.name) requests.push_back(static_cast<int>(k));
  if (jt.type == JointType::Prismatic) {
    const Rotation R(std::atan2(jt.axis.y, jt.axis.x), ZAxis);
    MobilizedBody::Slider mb(parent, Transform(R, v3(jt.parent_point)), info, Transform(R, v3(jt.child_point)));
    m.joint_mobod[j] = m.body_mobod[b] = mb;
  } else if (!requests.empty() && m.options.route == ConstraintForceRoute::Actuator) {
    add_actuated_pin(m, j, parent, info, requests);
  } else {
    MobilizedBody::Pin mb(parent, Transform(Rotation(jt.offset_rad, ZAxis), v3(jt.parent_point)), info,
                          Transform(v3(jt.child_point)));
    m.joint_mobod[j] = m.body_mobod[b] = mb;
  }
}

// Stage 2: mobilizers in tree order (parents first); a folded joint gets none.
void add_mobilizers(FullModel::Impl& m, const std::vector<double>& extra_inertia) {
  const auto& scene = m.scene;
  const size_t nj = scene.joints.size();
  std::vector<bool> built(nj, false);
  for (size_t pass = 0, done = 0; done < nj && pass <= nj; ++pass) {
    for (size_t j = 0; j < nj; ++j) {
      const auto& jt = scene.joints[j];
      if (built[j]) continue;
      if (!m.joint_fold[j]) {
        if (jt.parent != models::kGround && !m.body_mobod[scene.body_index(jt.parent)].isInSubsystem()) continue;
        add_joint_mobilizer(m, static_cast<int>(j), extra_inertia);
      }
      built[j] = true;
      ++done;
    }
  }
  for (size_t j = 0; j < nj; ++j)
    if (!built[j])
      throw EngineError(fmt::format("{}: joint '{}' hangs from no body reachable from ground (the joints must "
                                    "form a tree)",
                                    scene.source_file, scene.joints[j].name));
}

// Stage 3: loop closures: a point of body_b stays on the z line through a point of body_a: the
// two in-plane rows of a planar revolute, without Ball's redundant third row.
void add_loop_closures(FullModel::Impl& m) {
  for (const auto& l : m.scene.loops) {
    MobilizedBody a = l.body_a == models::kGround ? MobilizedBody(m.matter.updGround())
                                                   : m.body_mobod[m.scene.body_index(l.body_a)];
    MobilizedBody b = l.body_b == models::kGround ? MobilizedBody(m.matter.updGround())
                                                   : m.body_mobod[m.scene.body_index(l.body_b)];
    m.constraints.emplace_back("loop '" + l.name + "'",
                               Constraint::PointOnLine(a, UnitVec3(ZAxis), v3(l.point_a), b, v3(l.point_b)));
  }
}

// Stage 4: gears that were not folded: q_driven − r·q_driver − c = 0.
void add_gear_couplers(FullModel::Impl& m, const std::vector<bool>& folded) {
  m.gear_coupled.assign(m.scene.joints.size(), false);
  for (size_t g = 0; g < m.scene.gears.size(); ++g) {
    if (folded[g]) continue;
    const auto& gear = m.scene.gears[g];
    const int jr = m.scene.joint_index(gear.driver), jd = m.scene.joint_index(gear.driven);
    Vector coeff(3);
    coeff[0] = -gear.ratio;
    coeff[1] = 1.0;
    coeff[2] = -models::calc_gear_offset(m.scene, gear);
    std::vector<MobilizedBodyIndex> mbs{m.joint_mobod[jr].getMobilizedBodyIndex(),
                                        m.joint_mobod[jd].getMobilizedBodyIndex()};
    std::vector<MobilizerQIndex> qs{MobilizerQIndex(0), MobilizerQIndex(0)};
    m.coupled_gears.push_back(static_cast<int>(g));
    m.gear_coupled[jr] = m.gear_coupled[jd] = true;
    m.constraints.emplace_back("gear '" + gear.name + "'",
                               Constraint::CoordinateCoupler(m.matter, new Function::Linear(coeff), mbs, qs));
  }
}

}  // namespace

FullModel::Impl::Impl(const models::Scene& s, FullModelOptions o)
    : scene(s), options(o), matter(system), forces(system) {
  const size_t nj = scene.joints.size(), nb = scene.bodies.size();
  joint_mobod.resize(nj);
  body_mobod.resize(nb);
  joint_fold.resize(nj);
  body_fold.resize(nb);
  independent = scene.joint_index(scene.independent);
  if (independent < 0) throw EngineError(scene.source_file + ": unknown independent joint '" + scene.independent + "'");
  check_constraint_force_requests(scene);
  actuator_slider.resize(options.route == ConstraintForceRoute::Actuator ? scene.outputs.constraint_forces.size()
                                                                          : 0);
  const GearFolding folding = fold_geared_bodies(*this);
  add_mobilizers(*this, folding.extra_inertia);
  add_loop_closures(*this);
  add_gear_couplers(*this, folding.folded);
  // Stage 5: prescribed laws: the independent coordinate (enabled for kinetostatic calls,
  // disabled for forward dynamics) and each constraint actuator (always x = 0).
  independent_motion = Motion::Custom(joint_mobod[independent], new LawMotion(*this, 0));
  for (size_t k = 0; k < actuator_slider.size(); ++k)
    actuator_motion.push_back(Motion::Custom(actuator_slider[k], new LawMotion(*this, 1 + static_cast<int>(k))));
  add_scene_loads(*this);
  try {
    system.realizeTopology();  // its default State is realized through Model (Simbody's System.h)
    jacobian_plan = make_constraint_jacobian_plan(*this);
  } catch (const std::exception& e) {
    throw EngineError(std::string("Simbody could not build the system: ") + describe_simbody_exception(e));
  }
}

const MobilizedBody& FullModel::Impl::mobod_of(const std::string& body) const {
  if (body == models::kGround) return matter.getGround();
  return body_mobod[scene.body_index(body)];
}

double FullModel::Impl::joint_q(const State& s, int j) const {
  if (const auto& f = joint_fold[j]) return f->ratio * joint_q(s, f->driver_joint) + f->q_offset;
  return joint_mobod[j].getOneQ(s, MobilizerQIndex(0));
}

double FullModel::Impl::joint_u(const State& s, int j) const {
  if (const auto& f = joint_fold[j]) return f->ratio * joint_u(s, f->driver_joint);
  return joint_mobod[j].getOneU(s, MobilizerUIndex(0));
}

double FullModel::Impl::body_rate(const State& s, int b) const {
  if (const auto& f = body_fold[b]) return f->ratio * joint_u(s, f->driver_joint);
  return body_mobod[b].getBodyAngularVelocity(s)[2];
}

void FullModel::Impl::set_law(State& s, int which, const Law& law) const {
  Value<Law>::updDowncast(matter.updDiscreteVariable(s, indices->law[which])) = law;
}

void FullModel::Impl::set_load_mode(State& s, LoadMode mode) const {
  Value<int>::updDowncast(forces.updDiscreteVariable(s, indices->load_mode)) = mode;
}

void FullModel::Impl::set_gate(State& s, int torque, bool on) const {
  Value<bool>::updDowncast(forces.updDiscreteVariable(s, indices->gate[torque])) = on;
}

bool FullModel::Impl::gate(const State& s, int torque) const {
  return Value<bool>::downcast(forces.getDiscreteVariable(s, indices->gate[torque]));
}

double FullModel::Impl::work(const State& s) const { return forces.getZ(s)[indices->work]; }
void FullModel::Impl::set_work(State& s, double work_J) const { forces.updZ(s)[indices->work] = work_J; }
long FullModel::Impl::events(const State& s) const {
  return Value<long>::downcast(forces.getDiscreteVariable(s, indices->events));
}

std::vector<double> FullModel::Impl::constraint_forces(const State& s) const {
  const auto& req = scene.outputs.constraint_forces;
  std::vector<double> out(req.size());
  if (options.route == ConstraintForceRoute::Actuator) {
    // Simbody's multipliers sit on the left (M u̇ + Gᵀλ + τ = f): actuator force = −τ.
    for (size_t k = 0; k < req.size(); ++k) out[k] = -actuator_slider[k].getOneTau(s, MobilizerUIndex(0));
    return out;
  }
  Vector_<SpatialVec> reactions;
  matter.calcMobilizerReactionForces(s, reactions);
  for (size_t k = 0; k < req.size(); ++k) {
    const auto& jt = scene.joints[scene.joint_index(req[k].joint)];
    const MobilizedBody& child = body_mobod[scene.body_index(jt.child)];
    const Vec3 d_G = child.getBodyRotation(s) * UnitVec3(v3(req[k].direction));
    out[k] = dot(reactions[child.getMobilizedBodyIndex()][1], d_G);  // force on child at M, in G
  }
  return out;
}

std::pair<double, std::string> FullModel::Impl::worst_loop_gap(const State& s) const {
  std::pair<double, std::string> worst{0.0, ""};
  for (const auto& l : scene.loops) {
    const Vec3 pa = mobod_of(l.body_a).findStationLocationInGround(s, v3(l.point_a));
    const Vec3 pb = mobod_of(l.body_b).findStationLocationInGround(s, v3(l.point_b));
    const double gap = (pa - pb).norm();
    if (gap >= worst.first) worst = {gap, l.name};
  }
  return worst;
}

std::pair<double, std::string> FullModel::Impl::worst_gear_error(const State& s) const {
  std::pair<double, std::string> worst{0.0, ""};
  for (int g : coupled_gears) {
    const auto& gear = scene.gears[g];
    const double q_driver = joint_q(s, scene.joint_index(gear.driver));
    const double q_driven = joint_q(s, scene.joint_index(gear.driven));
    const double error = std::abs(q_driven - gear.ratio * q_driver - models::calc_gear_offset(scene, gear));
    if (!(error < worst.first)) worst = {error, gear.name};  // NaN too
  }
  return worst;
}

FullModel::FullModel(const models::Scene& scene, FullModelOptions options)
    : impl_(std::make_unique<Impl>(scene, options)) {}
FullModel::~FullModel() = default;
const models::Scene& FullModel::scene() const { return impl_->scene; }
const FullModelOptions& FullModel::options() const { return impl_->options; }
int FullModel::num_simbody_bodies() const { return impl_->matter.getNumBodies() - 1; }
bool FullModel::is_folded(const std::string& body) const {
  const int b = impl_->scene.body_index(body);
  return b >= 0 && impl_->body_fold[b].has_value();
}

namespace {

// Simbody's assembler from the state's coordinates, the constraint actuators locked at x = 0 and
// the independent coordinate locked when `lock_independent`; the worst closure error after it:
// the loops' gap [m] or a gear's residual [rad or m] (the Assembler gives up silently).
double assemble(const FullModel::Impl& m, State& s, bool lock_independent) {
  Assembler assembler(m.system);
  assembler.setAccuracy(1e-12);
  if (lock_independent) assembler.lockMobilizer(m.joint_mobod[m.independent].getMobilizedBodyIndex());
  for (const auto& sl : m.actuator_slider) assembler.lockMobilizer(sl.getMobilizedBodyIndex());
  try {
    assembler.initialize(s);
    assembler.assemble();
  } catch (const std::exception&) {
    // Fall through: the gap check reports which loop fails and by how much.
  }
  assembler.updateFromInternalState(s);
  m.system.realize(s, Stage::Position);
  return std::max(m.worst_loop_gap(s).first, m.worst_gear_error(s).first);
}

// Direct assembly at the initial q failed from the scene's guesses: they are too far from the
// configuration there for the assembler's Newton steps (a parallelogram chain started 0.01° from
// flat with its 90°/−90° guesses left a gap of 2 m). Assemble where the guesses fit — every
// joint at its guess, the independent coordinate too, and free — then walk the independent to
// the initial q in moves of at most 2°, each assembled from the last. The state is left at the
// last move that closed; true when it reached the initial q.
// How a continuation from the guesses' configuration to the initial q ended.
enum class Walk {
  Reached,               // s holds the start, on the guesses' branch
  GuessesDoNotAssemble,  // the guesses describe no configuration (s unchanged)
  SingularBetween,       // a configuration where the loop Jacobian loses rank lies between
  NoProgress,            // moves stopped closing
};

Walk assemble_by_continuation(const FullModel::Impl& m, State& s) {
  const State start = s;
  // A gearless mechanism repeats each turn: the walk starts whole turns on, toward q, and walks
  // the last part of a turn (from 30° to 1e6° it gave up at once, blaming a singular configuration).
  const double guess = m.scene.joints[m.independent].guess, q_to = m.scene.initial.q;
  const bool rev = m.scene.joints[m.independent].type == models::JointType::Revolute;
  const double g0 = rev && m.scene.gears.empty() ? guess + 2 * M_PI * std::trunc((q_to - guess) / (2 * M_PI)) : guess;
  m.joint_mobod[m.independent].setOneQ(s, MobilizerQIndex(0), g0);
  m.set_law(s, 0, poly_law(g0, 0.0, 0.0));
  if (!(assemble(m, s, false) <= 1e-8)) {
    s = start;
    return Walk::GuessesDoNotAssemble;
  }
  const double q_from = m.joint_mobod[m.independent].getOneQ(s, MobilizerQIndex(0));
  const double max_move = rev ? 2 * M_PI / 180 : 0.02 * std::max(1e-3, std::abs(q_to - q_from));
  // A move that does not close is halved (near a flat configuration Newton's basin shrinks),
  // down to 1e-6 of the largest move; at most 4000 assemblies.
  // The walk must not pass a configuration where the loop Jacobian loses rank: branches cross
  // there, and which one it leaves on is an accident (a chain walked from 90° to 270° through its
  // flat configuration came out folded). A minimum of the conditioning below kSingularWindow with
  // a rise after it is such a passage: the walk gives up. An approach to the target is not.
  constexpr double kSingularWindow = 1e-2;
  // Toward a singular configuration the other branch comes within ~2× the distance to it: a
  // move longer than about a third of that distance may land there (a chain walked from 2° to
  // 0.003° in one move came out folded). The conditioning falls like the distance, so moves are
  // kept below max_move·κ/kFarConditioning.
  constexpr double kFarConditioning = 0.05;
  double q = q_from, move = max_move, lowest = calc_loop_conditioning(m, s);
  for (int it = 0; it < 4000 && q != q_to && move >= 1e-6 * max_move; ++it) {
    const double step = std::min(move, max_move * std::max(1e-6, std::min(1.0, lowest / kFarConditioning)));
    // Steps shrinking far from the target: a singular configuration lies between (a walk from
    // 90° to 270° through a chain's flat position at 180°); do not creep up to it.
    if (step < 1e-3 * std::abs(q_to - q)) return Walk::SingularBetween;
    const double q_next = std::abs(q_to - q) <= step ? q_to : q + std::copysign(step, q_to - q);
    State next = s;
    m.joint_mobod[m.independent].setOneQ(next, MobilizerQIndex(0), q_next);
    m.set_law(next, 0, poly_law(q_next, 0.0, 0.0));  // the prescribed position the assembly keeps
    if (assemble(m, next, true) <= 1e-8) {
      const double k = calc_loop_conditioning(m, next);
      if (lowest < kSingularWindow && k > 2 * lowest) return Walk::SingularBetween;
      lowest = std::min(lowest, k);
      s = next, q = q_next;
      move = std::min(max_move, 2 * move);
    } else {
      move *= 0.5;
    }
  }
  return q == q_to ? Walk::Reached : Walk::NoProgress;
}

bool far_from_guesses(const FullModel::Impl& m, const State& s) {
  for (size_t j = 0; j < m.scene.joints.size(); ++j) {
    if (m.joint_fold[j] || static_cast<int>(j) == m.independent) continue;
    if (m.scene.joints[j].type != models::JointType::Revolute) continue;
    const double q = m.joint_mobod[j].getOneQ(s, MobilizerQIndex(0)), g = m.scene.joints[j].guess;
    if (std::abs(std::remainder(q - g, 2 * M_PI)) > kFarFromGuess_deg * M_PI / 180) return true;
  }
  return false;
}

// The direct assembly by the chord Newton projection from the guesses (engine/branch_rates), kept
// only when it closes every loop to 1e-13 within kFarFromGuess_deg of every guess; else the
// guesses are restored for Simbody's Assembler. With the independent coordinate and the
// actuators prescribed the configuration is isolated, so both land on the same one, to their
// accuracies (1e-13, 1e-12); the Assembler's set-up (its own state copies, quaternion
// conversions) was 5 % of a sweep case (issue #28).
bool newton_assemble(const FullModel::Impl& m, State& s) {
  const Vector guesses = s.getQ();
  m.system.realize(s, Stage::Time);
  m.system.prescribeQ(s);
  if (newton_project(m, s) && !far_from_guesses(m, s)) {
    // To rounding, as the Assembler closes: a forward run's first projection (the independent
    // coordinate free) would otherwise move the start by the 1e-13 left (the cycle rerun of
    // validate/analysis/cycle_run starts exactly at its q).
    polish_projection(m, s);
    return true;
  }
  s.updQ() = guesses;
  return false;
}

// Each revolute joint's angle within half a turn of its guess: the assembler may land whole
// turns away (8224 turns for a chain started 0.5° from flat), which is the same configuration
// but not the coordinate a user reads or a branch check compares. Not a joint of a gear coupler:
// q_driven = r·q_driver + c holds absolute angles, so a turn taken off one side is a residual of
// 2π (r·2π) that the next projection cannot undo (a five-bar geared 6:1 started at 430.2° had its
// fast crank turned back 6 turns: 37.7 rad off, projectQ stalled). Its angle stays as assembled.
void wrap_to_guesses(const FullModel::Impl& m, State& s) {
  for (size_t j = 0; j < m.scene.joints.size(); ++j) {
    if (m.joint_fold[j] || static_cast<int>(j) == m.independent || m.gear_coupled[j]) continue;
    if (m.scene.joints[j].type != models::JointType::Revolute) continue;
    const double q = m.joint_mobod[j].getOneQ(s, MobilizerQIndex(0)), g = m.scene.joints[j].guess;
    const double wrapped = g + std::remainder(q - g, 2 * M_PI);
    if (wrapped != q) m.joint_mobod[j].setOneQ(s, MobilizerQIndex(0), wrapped);
  }
  m.system.realize(s, Stage::Position);
}

// The direct assembly landed far from the guesses and the walk from the guesses' configuration
// stopped at a configuration where the loop Jacobian loses rank (`walked`: where it stopped):
// branches cross there, so the guesses do not say which branch the start is on, and the one the
// assembler landed on is an accident (a parallelogram chain started at −30° with its 90° guesses
// came out folded: its cranks no longer turn alike). Unless a loop names its branch (checked
// after assembly), that is a scene error naming `initial`.
void refuse_branch_across_singularity(const FullModel::Impl& m, const State& s, const State& walked) {
  for (const auto& l : m.scene.loops)
    if (l.branch) return;
  const bool rev = m.scene.joints[m.independent].type == models::JointType::Revolute;
  std::string far;
  for (size_t j = 0; j < m.scene.joints.size() && far.empty(); ++j) {
    if (m.joint_fold[j] || static_cast<int>(j) == m.independent) continue;
    if (m.scene.joints[j].type != models::JointType::Revolute) continue;
    const double q = m.joint_mobod[j].getOneQ(s, MobilizerQIndex(0)), g = m.scene.joints[j].guess;
    if (std::abs(std::remainder(q - g, 2 * M_PI)) > kFarFromGuess_deg * M_PI / 180)
      far = fmt::format("joint '{}' at {:.4g}° against its guess {:.4g}°", m.scene.joints[j].name, q * 180 / M_PI,
                        g * 180 / M_PI);
  }
  throw models::SceneError(
      m.scene.source_file, m.scene.line_of("initial"), "initial",
      fmt::format("the start of '{}' ({}) lies across a singular configuration (near {}) from the configuration "
                  "the joints' guesses describe ({}): assembly branches cross there, so the guesses do not say which "
                  "branch the start is on, and the assembly landed elsewhere ({}); give guesses that describe the "
                  "configuration at this start, or name the branch with a loop's `branch`",
                  m.scene.independent, format_coordinate(m.scene.initial.q, rev),
                  format_coordinate(m.joint_q(walked, m.independent), rev),
                  format_coordinate(m.scene.joints[m.independent].guess, rev), far));
}

// The guesses' configuration (assembled at the guessed independent coordinate) followed to the
// initial q by follow_branch, with the branch guard's moves; the workspace's continuation history
// is left empty. False when a move cannot be made.
bool continue_through_singularity(const FullModel& model, FullWorkspace& ws, const State& guesses) {
  const auto& m = model.impl();
  auto& w = ws.impl();
  State& s = w.state;
  s = guesses;
  const double guess = m.scene.joints[m.independent].guess;
  m.joint_mobod[m.independent].setOneQ(s, MobilizerQIndex(0), guess);
  m.set_law(s, 0, poly_law(guess, 0.0, 0.0));
  bool ok = assemble(m, s, false) <= 1e-8;
  if (ok) {
    const bool rev = m.scene.joints[m.independent].type == models::JointType::Revolute;
    const double scale = calc_length_scale(m.scene);
    double tolerance = kBranchTolerance_rad;
    for (const auto& j : m.scene.joints)
      if (j.type == models::JointType::Prismatic) tolerance = std::min(tolerance, kBranchTolerance_rel * scale);
    try {
      follow_branch(model, ws, m.scene.initial.q, rev ? kBranchMaxMove_rad : kBranchMaxMove_rel * scale,
                    kBranchCorrectionFraction * tolerance);
    } catch (const std::exception&) {
      ok = false;
    }
  }
  w.hist_n = 0;
  w.anchor_set = false;
  m.set_law(s, 0, poly_law(m.scene.initial.q, 0.0, 0.0));
  return ok && assemble(m, s, true) <= 1e-8;
}

}  // namespace

FullWorkspace::FullWorkspace(const FullModel& model)
    : impl_(std::make_unique<Impl>(model.impl())) {
  const auto& m = model.impl();
  State& s = impl_->state;
  // Start from the scene's guesses (they pick the branch, e.g. knee in front), with the
  // independent coordinate at its initial value and every constraint actuator at x = 0.
  for (size_t j = 0; j < m.scene.joints.size(); ++j)
    if (!m.joint_fold[j]) m.joint_mobod[j].setOneQ(s, MobilizerQIndex(0), m.scene.joints[j].guess);
  m.joint_mobod[m.independent].setOneQ(s, MobilizerQIndex(0), m.scene.initial.q);
  m.set_law(s, 0, poly_law(m.scene.initial.q, 0.0, 0.0));
  const Vector q_guesses = s.getQ();  // only q changes below (a State copy: ~0.3 M instructions)
  // Directly at the initial q; where that fails, or lands a revolute joint more than
  // kFarFromGuess_deg from its guess (on another branch: a parallelogram chain started 0.1° from
  // flat with its 90° guesses folded into the antiparallelogram), by continuation from the
  // configuration the guesses describe, when that reaches the initial q.
  const bool direct = newton_assemble(m, s) || assemble(m, s, true) <= 1e-8;
  if (!direct || far_from_guesses(m, s)) {
    State guesses = s;
    guesses.updQ() = q_guesses;
    State walked = guesses;
    const Walk walk = assemble_by_continuation(m, walked);
    // Through a singular configuration along the guesses' branch, as the extraction and the
    // dynamics continue (follow_branch: the chord of the last move there, the smooth
    // continuation, not the branch that crosses); where that fails, the start's branch is not
    // determined by the guesses: refused unless a loop names it.
    const State direct_state = s;
    if (walk == Walk::Reached) {
      s = walked;
    } else if (walk == Walk::SingularBetween && continue_through_singularity(model, *this, guesses)) {
      // s holds the start on the guesses' branch
    } else if (!direct) {
      s = guesses;  // report the direct attempt's gap
      assemble(m, s, true);
    } else if (walk == Walk::SingularBetween) {
      s = direct_state;
      wrap_to_guesses(m, s);
      refuse_branch_across_singularity(m, s, walked);
    }
  }
  wrap_to_guesses(m, s);
  const bool rev = m.scene.joints[m.independent].type == models::JointType::Revolute;
  const std::string at =
      rev ? fmt::format("{:.6g}°", m.scene.initial.q * 180 / Pi) : fmt::format("{:.6g} m", m.scene.initial.q);
  const auto [gap, loop] = m.worst_loop_gap(s);
  if (gap > 1e-8)
    throw EngineError(fmt::format("{}: loop '{}' cannot close at {} = {}: the best assembly attempt "
                                  "leaves a gap of {:.6g} m (check lengths and ground points, and that the joints' "
                                  "guesses describe the configuration at this q: assembly walks from them to q, but "
                                  "not across a singular configuration)",
                                  models::where(m.scene, "loops." + loop), loop, m.scene.independent, at, gap));
  // The state must be on the manifold every later projection starts from: the gears too.
  const auto [residual, gear] = m.worst_gear_error(s);
  if (!(residual <= 1e-8))
    throw EngineError(fmt::format("{}: gear '{}' does not hold at {} = {}: the best assembly attempt leaves "
                                  "q_driven − ratio·q_driver − c = {:.6g} (rad or m of the driven joint; c from the "
                                  "joints' guesses)",
                                  m.scene.source_file, gear, m.scene.independent, at, residual));
  check_one_dof(m, s);
  // A start where the loops' Jacobian (less the prescribed columns) is singular by the measure
  // the extraction marks singular grid points with: refused (issue #22 item 5).
  if (calc_loop_conditioning(m, s) < kSingularConditioning) throw_singular_start(m, s);
  check_branches(m, s);
  check_point_forces(m, s);
}

FullWorkspace::Impl::Impl(const FullModel::Impl& m) : model(m), state(m.default_state()) {}
FullWorkspace::Impl::~Impl() = default;
FullWorkspace::~FullWorkspace() = default;
FullWorkspace::FullWorkspace(FullWorkspace&&) noexcept = default;

std::string describe_simbody_error(const std::string& what) {
  std::string text = what;
  const std::string thrown = "SimTK Exception thrown at ";  // then "<file>:<line>:\n  "
  if (text.rfind(thrown, 0) == 0) {
    const auto nl = text.find('\n');
    text.erase(0, nl == std::string::npos ? text.size() : nl + 1);
  }
  // The condition Simbody checked, then its words without the "(Required condition …)" line.
  std::string condition;
  for (const char* tag : {"(Required condition '", "(Assertion '"}) {
    const auto at = text.find(tag);
    if (at == std::string::npos) continue;
    const auto start = at + std::strlen(tag), end = text.find('\'', start);
    condition = text.substr(start, end == std::string::npos ? std::string::npos : end - start);
    text.erase(at);
  }
  std::string line;  // whitespace (newlines included) collapsed
  for (char c : text) {
    if (std::isspace(static_cast<unsigned char>(c))) {
      if (!line.empty() && line.back() != ' ') line += ' ';
    } else {
      line += c;
    }
  }
  const std::string prefix = "Error detected by Simbody method ";
  if (line.rfind(prefix, 0) == 0) line.erase(0, prefix.size());
  while (!line.empty() && (line.back() == ' ' || line.back() == ':' || line.back() == '.')) line.pop_back();
  // Conditions a run on valid input meets, in words.
  if (condition == "t1 > t0")
    return "the integrator's step shrank to zero length while it located a load switch (switches closer together "
           "than the time can resolve at this t: a gate that switches back at once, or a run too long for its "
           "tolerance; Simbody found an event interval of zero length)";
  if (condition.empty()) return line;
  return line + " [Simbody's condition: " + condition + "]";
}

}  // namespace rdyn::engine
