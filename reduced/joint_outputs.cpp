#include "reduced/joint_outputs.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace rdyn::reduced {

namespace {

constexpr double kTwoPi = 2 * 3.14159265358979323846;

// The body B whose Newton–Euler balance gives loop l's force: body_b, else body_a, when it hangs
// from a revolute joint, its child joints are revolute, and no spring or other loop touches it.
// Returns the body and +1 (B = body_b) or −1 (B = body_a; the force on body_b is the opposite).
std::pair<std::string, int> loop_balance_body(const models::Scene& s, const models::Loop& l) {
  for (const auto& [body, sign] : {std::pair{l.body_b, +1}, std::pair{l.body_a, -1}}) {
    if (body == models::kGround) continue;
    bool ok = true;
    for (const auto& j : s.joints)
      if ((j.child == body || j.parent == body) && j.type != models::JointType::Revolute) ok = false;
    for (const auto& sp : s.springs) ok &= sp.body_a != body && sp.body_b != body;
    for (const auto& pf : s.point_forces) ok &= pf.body_a != body && pf.body_b != body;
    for (const auto& o : s.loops) ok &= &o == &l || (o.body_a != body && o.body_b != body);
    if (ok) return {body, sign};
  }
  throw TableError(fmt::format("{}: the reduced model cannot give the reaction of loop '{}': neither of its bodies "
                               "hangs from revolute joints only, free of springs, point forces and other loops (use "
                               "--model full)",
                               models::where(s, "outputs.reactions"), l.name));
}

// A prismatic joint's reaction by Newton–Euler of its child C: C's other joints are revolute
// children (their reaction lines are known), each loop on C is solved from its other body, and
// no spring, resistance or torque-type load on a child joint acts on C (the moment balance
// about the child point would need them). Throws TableError naming what is missing.
void check_prismatic_balance(const models::Scene& s, const models::Joint& jt) {
  const std::string& c = jt.child;
  auto refuse = [&](const std::string& why) {
    throw TableError(fmt::format("{}: the reduced model cannot give the reaction of prismatic joint '{}': its child "
                                 "'{}' {} (use --model full)",
                                 models::where(s, "outputs.reactions"), jt.name, c, why));
  };
  for (const auto& j : s.joints) {
    if (j.parent != c) continue;
    if (j.type != models::JointType::Revolute) refuse("carries a prismatic joint '" + j.name + "'");
    for (const auto& t : s.joint_torques)
      if (t.joint == j.name) refuse("takes the reaction of the torque on joint '" + j.name + "'");
    for (const auto& m : s.motors)
      if (m.joint == j.name) refuse("takes the reaction of the motor on joint '" + j.name + "'");
  }
  for (const auto& sp : s.springs)
    if (sp.body_a == c || sp.body_b == c) refuse("carries spring '" + sp.name + "'");
  for (const auto& r : s.resistances)
    if (r.body == c) refuse("carries resistance '" + r.name + "'");
  for (const auto& pf : s.point_forces)
    if (pf.body_a == c || pf.body_b == c) refuse("carries point force '" + pf.name + "'");
  for (const auto& l : s.loops)
    if ((l.body_a == c || l.body_b == c) && loop_balance_body(s, l).first == c)
      refuse("is the only body that can balance loop '" + l.name + "'");
}

using Kin = BodyMotion;

// Rigid transfer: the point at offset d (ground frame) from a frame with acceleration a, ω, α.
void transfer(const Kin& k, double dx, double dy, double& ax, double& ay) {
  ax = k.ax - k.al * dy - k.w * k.w * dx;
  ay = k.ay + k.al * dx - k.w * k.w * dy;
}

}  // namespace

void add_joint_position_columns(const models::Scene& scene, const std::vector<double>& q, double h,
                                const std::vector<std::vector<double>>& r, const std::vector<std::vector<double>>& p,
                                Samples& samples) {
  const size_t n = q.size();
  for (size_t j = 0; j < scene.joints.size(); ++j) {
    double k = 0.0;
    if (scene.joints[j].type == models::JointType::Revolute) {
      // After a turn of q the sweep's continued angle has gained 2π k: p(q_first + 2π) is the last
      // sample plus the wrap interval's increment (trapezoid of the ratios, exact to O(h³)).
      const double end = p[j][n - 1] + 0.5 * (r[j][n - 1] + r[j][0]) * h;
      k = std::round((end - p[j][0]) / kTwoPi);
    }
    std::vector<double> col(n);
    for (size_t i = 0; i < n; ++i) col[i] = p[j][i] - k * q[i];
    samples.add("p_" + scene.joints[j].name, col);
    samples.add("k_" + scene.joints[j].name, std::vector<double>(n, k));
  }
}

void turn_reaction_lines_to_ground(const models::Scene& scene, Samples& s) {
  const size_t n = s.q.size();
  for (const auto& jt : scene.joints) {
    const std::string fx = internal_request_name(jt.name, 'x'), fy = internal_request_name(jt.name, 'y');
    if (s.column("me1_" + fx) < 0 || s.column("me1_" + fy) < 0) continue;
    // The child's angle in ground: the sum over the revolute joints from ground to it.
    std::vector<double> th(n, 0.0);
    std::string body = jt.child;
    for (size_t hops = 0; body != models::kGround && hops <= scene.joints.size(); ++hops) {
      const auto it = std::find_if(scene.joints.begin(), scene.joints.end(),
                                   [&](const models::Joint& x) { return x.child == body; });
      if (it == scene.joints.end()) break;
      if (it->type == models::JointType::Revolute) {
        const auto& p = s.columns[s.require("p_" + it->name)];
        const auto& k = s.columns[s.require("k_" + it->name)];
        for (size_t i = 0; i < n; ++i) th[i] += it->offset_rad + p[i] + k[i] * s.q[i];
      }
      body = it->parent;
    }
    std::vector<std::string> parts{"me1_", "me2_", "Qx_cons_"};  // prefix + force (+ "_" + other)
    std::vector<std::pair<std::string, std::string>> cols;
    for (const auto& pre : parts) cols.emplace_back(pre + fx, pre + fy);
    for (const auto& o : scene.joints) cols.emplace_back("rx_" + fx + "_" + o.name, "rx_" + fy + "_" + o.name);
    for (const auto& r : scene.resistances) cols.emplace_back("wx_" + fx + "_" + r.body, "wx_" + fy + "_" + r.body);
    for (const auto& pf : scene.point_forces)
      cols.emplace_back("Qxpf_" + fx + "_" + pf.name, "Qxpf_" + fy + "_" + pf.name);
    for (const auto& [nx, ny] : cols) {
      const int cx = s.column(nx), cy = s.column(ny);
      if (cx < 0 || cy < 0) continue;
      auto& X = s.columns[cx];
      auto& Y = s.columns[cy];
      for (size_t i = 0; i < n; ++i) {
        const double c = std::cos(th[i]), sn = std::sin(th[i]), x = X[i], y = Y[i];
        X[i] = c * x - sn * y, Y[i] = sn * x + c * y;
      }
    }
    // A pole of either child-frame line is in both ground-frame lines.
    std::vector<double> poles;
    for (const auto& [name, q] : s.poles)
      if (name == fx || name == fy) poles.insert(poles.end(), q.begin(), q.end());
    if (poles.empty()) continue;
    std::sort(poles.begin(), poles.end());
    poles.erase(std::unique(poles.begin(), poles.end()), poles.end());
    s.poles.erase(std::remove_if(s.poles.begin(), s.poles.end(),
                                 [&](const auto& pr) { return pr.first == fx || pr.first == fy; }),
                  s.poles.end());
    s.poles.emplace_back(fx, poles);
    s.poles.emplace_back(fy, poles);
  }
}

std::vector<std::string> reaction_line_joints(const models::Scene& scene) {
  std::vector<std::string> joints;  // revolute joints whose reaction lines are needed
  auto need = [&](const std::string& j) {
    if (std::find(joints.begin(), joints.end(), j) == joints.end()) joints.push_back(j);
  };
  for (const auto& name : scene.outputs.reactions) {
    auto need_loop = [&](const models::Loop& l) {
      const auto body = loop_balance_body(scene, l).first;
      for (const auto& j : scene.joints)
        if (j.child == body || j.parent == body) need(j.name);
    };
    if (const auto* j = scene.find_joint(name)) {
      if (j->type == models::JointType::Revolute) {
        need(name);
        continue;
      }
      check_prismatic_balance(scene, *j);
      for (const auto& k : scene.joints)
        if (k.parent == j->child) need(k.name);
      for (const auto& l : scene.loops)
        if (l.body_a == j->child || l.body_b == j->child) need_loop(l);
      continue;
    }
    for (const auto& l : scene.loops)
      if (l.name == name) need_loop(l);
  }
  return joints;
}

models::Scene with_reaction_requests(const models::Scene& scene) {
  models::Scene out = scene;
  for (const auto& j : reaction_line_joints(scene)) {
    for (char axis : {'x', 'y'}) {
      const std::string name = internal_request_name(j, axis);
      for (const auto& c : scene.outputs.constraint_forces)
        if (c.name == name)
          throw TableError("constraint force name '" + name + "' is reserved for the reduced model's reaction lines");
      out.outputs.constraint_forces.push_back({name, j, axis == 'x' ? models::Vec2{1, 0} : models::Vec2{0, 1}});
    }
  }
  return out;
}

ReducedReactions split_reduced_reactions(const models::Scene& scene) {
  ReducedReactions out{scene, {}};
  out.scene.outputs.reactions.clear();
  for (const auto& name : scene.outputs.reactions) {
    models::Scene one = scene;
    one.outputs.reactions = {name};
    try {
      with_reaction_requests(one);
      out.scene.outputs.reactions.push_back(name);
    } catch (const TableError& e) {
      out.not_given.emplace_back(name, e.what());
    }
  }
  return out;
}

namespace {

// Planar tree kinematics: the child's frame from its parent's and its joint's motion.
void place_child(const JointOutputModel& m, JointOutputWorkspace& ws, int j) {
  const auto& jt = m.scene.joints[j];
  const Kin P = m.parent[j] < 0 ? Kin{} : ws.body[m.parent[j]];
  const double cP = std::cos(P.th), sP = std::sin(P.th);
  double px = jt.parent_point.x, py = jt.parent_point.y, arx = 0, ary = 0;
  Kin C = P;
  if (jt.type == models::JointType::Revolute) {
    C.th = P.th + jt.offset_rad + ws.qj[j];
    C.w = P.w + ws.uj[j];
    C.al = P.al + ws.aj[j];
  } else {  // slides along the axis (parent frame) by q_j
    px += jt.axis.x * ws.qj[j];
    py += jt.axis.y * ws.qj[j];
    const double ux = cP * jt.axis.x - sP * jt.axis.y, uy = sP * jt.axis.x + cP * jt.axis.y;
    // relative acceleration u q̈ plus Coriolis 2 ω k × (u q̇)
    arx = ux * ws.aj[j] - 2 * P.w * uy * ws.uj[j];
    ary = uy * ws.aj[j] + 2 * P.w * ux * ws.uj[j];
  }
  const double dx = cP * px - sP * py, dy = sP * px + cP * py;  // parent origin → joint point
  double Jax, Jay;
  transfer(P, dx, dy, Jax, Jay);
  Jax += arx, Jay += ary;
  const double cC = std::cos(C.th), sC = std::sin(C.th);
  const double ex = -(cC * jt.child_point.x - sC * jt.child_point.y);  // joint point → child origin
  const double ey = -(sC * jt.child_point.x + cC * jt.child_point.y);
  C.x = P.x + dx + ex;
  C.y = P.y + dy + ey;
  Kin Jk = C;
  Jk.ax = Jax, Jk.ay = Jay;
  transfer(Jk, ex, ey, C.ax, C.ay);
  const int b = m.child[j];
  ws.body[b] = C;
  const auto& bd = m.scene.bodies[b];
  const double fx = cC * bd.com_m.x - sC * bd.com_m.y, fy = sC * bd.com_m.x + cC * bd.com_m.y;
  ws.cx[b] = C.x + fx, ws.cy[b] = C.y + fy;
  transfer(C, fx, fy, ws.cax[b], ws.cay[b]);
}

// Joint motion at (q, q̇, q̈), then every body's by planar tree kinematics, into ws.
void calc_kinematics(const JointOutputModel& m, const Table& T, JointOutputWorkspace& ws, double q, double qd,
                     double qdd) {
  // Joint motion: q_j = p_j + k_j q; q̇_j = r_j q̇; q̈_j = r_j q̈ + (dr_j/dq) q̇².
  for (size_t j = 0; j < m.c_p.size(); ++j) {
    const double rj = T.eval(m.c_r[j], q);
    ws.qj[j] = T.eval(m.c_p[j], q) + T.eval(m.c_k[j], q) * q;
    ws.uj[j] = rj * qd;
    ws.aj[j] = rj * qdd + T.eval_deriv(m.c_r[j], q) * qd * qd;
  }
  for (int j : m.order) place_child(m, ws, j);
}

// The reactions of one state from its reaction lines (the run's constraint forces) and motion.
struct StateReactions {
  const JointOutputModel& m;
  const JointOutputWorkspace& k;
  const double* forces;  // the run's constraint forces, in the order make_joint_output_model was given

  // A revolute joint's reaction: its two ground-frame reaction lines (turned at extraction).
  void revolute(int j, double& Rx, double& Ry) const {
    Rx = forces[m.line_x[j]], Ry = forces[m.line_y[j]];
  }
  // Force of loop l's body_a on its body_b: Newton–Euler of the body B that balances it,
  // R_parent + Σ(−R_children) + F_loop + m g = m a_c.
  void loop(int l, double& Rx, double& Ry) const {
    const int b = m.loop_body[l];
    const double m_b = m.scene.bodies[b].mass_kg;
    double Fx = m_b * (k.cax[b] - m.gx), Fy = m_b * (k.cay[b] - m.gy);
    for (size_t j = 0; j < m.child.size(); ++j) {
      double jx, jy;
      if (m.child[j] == b) revolute(static_cast<int>(j), jx, jy), Fx -= jx, Fy -= jy;
      if (m.parent[j] == b) revolute(static_cast<int>(j), jx, jy), Fx += jx, Fy += jy;
    }
    Rx = m.loop_sign[l] * Fx, Ry = m.loop_sign[l] * Fy;
  }
  // Prismatic: Newton–Euler of the child C about the joint's child point P:
  // R = m (a_c − g) − Σ F_loops on C + Σ R_children; M = I α + (r_c − P) × m (a_c − g)
  // − Σ (r_k − P) × F_k over the other forces on C. Writes x, y, normal and moment.
  void prismatic(int j, double out[4]) const {
    const auto& jt = m.scene.joints[j];
    const int b = m.child[j];
    const auto& bd = m.scene.bodies[b];
    const Kin& C = k.body[b];
    const double cC = std::cos(C.th), sC = std::sin(C.th);
    auto at = [&](models::Vec2 p, double& x, double& y) {
      x = C.x + cC * p.x - sC * p.y, y = C.y + sC * p.x + cC * p.y;
    };
    double Px, Py;
    at(jt.child_point, Px, Py);
    const double mx = bd.mass_kg * (k.cax[b] - m.gx), my = bd.mass_kg * (k.cay[b] - m.gy);
    double Rx = mx, Ry = my;
    double M = bd.inertia_kgm2 * C.al + (k.cx[b] - Px) * my - (k.cy[b] - Py) * mx;
    auto other = [&](double x, double y, double fx, double fy) {  // another force on C at (x, y)
      Rx -= fx, Ry -= fy;
      M -= (x - Px) * fy - (y - Py) * fx;
    };
    for (size_t kj = 0; kj < m.parent.size(); ++kj)
      if (m.parent[kj] == b) {
        double kx, ky, x, y;
        revolute(static_cast<int>(kj), kx, ky);
        at(m.scene.joints[kj].parent_point, x, y);
        other(x, y, -kx, -ky);
      }
    for (size_t li = 0; li < m.scene.loops.size(); ++li) {
      const auto& l = m.scene.loops[li];
      if (l.body_a != jt.child && l.body_b != jt.child) continue;
      double fx, fy, x, y;
      loop(static_cast<int>(li), fx, fy);
      const bool on_b = l.body_b == jt.child;
      at(on_b ? l.point_b : l.point_a, x, y);
      other(x, y, on_b ? fx : -fx, on_b ? fy : -fy);
    }
    const Kin P = m.parent[j] < 0 ? Kin{} : k.body[m.parent[j]];
    const double ux = std::cos(P.th) * jt.axis.x - std::sin(P.th) * jt.axis.y;
    const double uy = std::sin(P.th) * jt.axis.x + std::cos(P.th) * jt.axis.y;
    out[0] = Rx, out[1] = Ry, out[2] = -uy * Rx + ux * Ry, out[3] = M;
  }
  // The mechanism's load on the ground: −(Σ m a_c − Σ m g), moment about O likewise.
  void shaking(double out[3]) const {
    double Fx = 0, Fy = 0, M = 0;
    for (size_t b = 0; b < m.scene.bodies.size(); ++b) {
      const auto& bd = m.scene.bodies[b];
      const double fx = bd.mass_kg * (m.gx - k.cax[b]), fy = bd.mass_kg * (m.gy - k.cay[b]);
      Fx += fx, Fy += fy;
      M += k.cx[b] * fy - k.cy[b] * fx - bd.inertia_kgm2 * k.body[b].al;
    }
    out[0] = Fx, out[1] = Fy, out[2] = M;
  }
};

// The internal reaction lines are not outputs of their own.
void drop_internal_lines(const models::Scene& s, models::TimeSeries& ts) {
  for (size_t k = ts.force_names.size(); k-- > 0;) {
    const bool user = std::any_of(s.outputs.constraint_forces.begin(), s.outputs.constraint_forces.end(),
                                  [&](const models::ConstraintForceRequest& c) { return c.name == ts.force_names[k]; });
    if (user) continue;
    ts.force_names.erase(ts.force_names.begin() + static_cast<long>(k));
    ts.forces.erase(ts.forces.begin() + static_cast<long>(k));
  }
}

}  // namespace

std::vector<std::string> joint_output_columns(const models::Scene& scene) {
  std::vector<std::string> names;
  for (const auto& jt : scene.joints) names.insert(names.end(), {"p_" + jt.name, "k_" + jt.name, "r_" + jt.name});
  return names;
}

JointOutputModel make_joint_output_model(const models::Scene& scene, const Table& table,
                                         const std::vector<std::string>& force_names) {
  JointOutputModel m;
  m.scene = scene;
  m.names = joint_output_names(scene);
  const auto& s = m.scene;
  const size_t nj = s.joints.size();
  auto col = [&](const std::string& name) {
    const int c = table.column(name);
    if (c < 0)
      throw TableError("the reduced table has no column '" + name +
                       "': extract it from a scene that asks for outputs.joints, reactions or shaking");
    return c;
  };
  const auto columns = joint_output_columns(s);
  for (size_t j = 0; j < nj; ++j) {
    const auto& jt = s.joints[j];
    m.c_p.push_back(col(columns[3 * j]));
    m.c_k.push_back(col(columns[3 * j + 1]));
    m.c_r.push_back(col(columns[3 * j + 2]));
    m.parent.push_back(jt.parent == models::kGround ? -1 : s.body_index(jt.parent));
    m.child.push_back(s.body_index(jt.child));
  }
  // Joints with parents before children (a tree rooted at ground).
  std::vector<char> done(nj, 0);
  for (size_t pass = 0; pass <= nj && m.order.size() < nj; ++pass)
    for (size_t j = 0; j < nj; ++j) {
      if (done[j]) continue;
      bool ready = m.parent[j] < 0;
      for (int o : m.order) ready |= m.child[o] == m.parent[j];
      if (ready) m.order.push_back(static_cast<int>(j)), done[j] = 1;
    }
  m.gx = s.gravity.enabled ? s.gravity.g_m_s2.x : 0.0, m.gy = s.gravity.enabled ? s.gravity.g_m_s2.y : 0.0;
  // The reaction lines the requested reactions read (with_reaction_requests asked for them).
  m.line_x.assign(nj, -1), m.line_y.assign(nj, -1);
  auto line = [&](const std::string& name) {
    const auto it = std::find(force_names.begin(), force_names.end(), name);
    if (it == force_names.end()) throw TableError("the reduced run has no constraint line '" + name + "'");
    return static_cast<int>(it - force_names.begin());
  };
  for (const auto& j : reaction_line_joints(s)) {
    const int ji = s.joint_index(j);
    m.line_x[ji] = line(internal_request_name(j, 'x'));
    m.line_y[ji] = line(internal_request_name(j, 'y'));
  }
  // Every loop a requested reaction balances: its body (reaction_line_joints has checked it can).
  m.loop_body.assign(s.loops.size(), -1), m.loop_sign.assign(s.loops.size(), 0);
  for (size_t l = 0; l < s.loops.size(); ++l) {
    const auto& lp = s.loops[l];
    bool needed = std::find(s.outputs.reactions.begin(), s.outputs.reactions.end(), lp.name) != s.outputs.reactions.end();
    for (const auto& r : s.outputs.reactions)
      if (const auto* j = s.find_joint(r); j && j->type != models::JointType::Revolute)
        needed |= lp.body_a == j->child || lp.body_b == j->child;
    if (!needed) continue;
    const auto [body, sign] = loop_balance_body(s, lp);
    m.loop_body[l] = s.body_index(body), m.loop_sign[l] = sign;
  }
  return m;
}

JointOutputWorkspace::JointOutputWorkspace(const JointOutputModel& m)
    : qj(m.scene.joints.size()),
      uj(m.scene.joints.size()),
      aj(m.scene.joints.size()),
      body(m.scene.bodies.size()),
      cax(m.scene.bodies.size()),
      cay(m.scene.bodies.size()),
      cx(m.scene.bodies.size()),
      cy(m.scene.bodies.size()) {}

void calc_joint_outputs(const JointOutputModel& m, const Table& table, JointOutputWorkspace& ws, double q,
                        double qdot, double qddot, const double* forces, double* out) {
  calc_kinematics(m, table, ws, q, qdot, qddot);
  const StateReactions R{m, ws, forces};
  const auto& s = m.scene;
  size_t c = 0;
  for (const auto& name : s.outputs.joints) {
    const int j = s.joint_index(name);
    out[c++] = ws.qj[j];
    out[c++] = ws.uj[j];
    out[c++] = ws.aj[j];
  }
  for (const auto& name : s.outputs.reactions) {
    double v[4] = {0, 0, 0, 0};
    const int j = s.joint_index(name);
    const bool prismatic = j >= 0 && s.joints[j].type != models::JointType::Revolute;
    if (j >= 0 && !prismatic) R.revolute(j, v[0], v[1]);
    else if (prismatic) R.prismatic(j, v);
    else
      for (size_t l = 0; l < s.loops.size(); ++l)
        if (s.loops[l].name == name) R.loop(static_cast<int>(l), v[0], v[1]);
    for (int n = 0; n < (prismatic ? 4 : 2); ++n) out[c++] = v[n];
  }
  if (s.outputs.shaking) R.shaking(out + c);
}

void add_joint_outputs(const models::Scene& s, const ReducedModel& m, models::TimeSeries& ts) {
  const JointOutputModel jm = make_joint_output_model(s, m.table, ts.force_names);
  JointOutputWorkspace ws(jm);
  const size_t ns = ts.t.size();
  ts.column_names = jm.names;
  ts.columns.assign(jm.names.size(), std::vector<double>(ns));
  std::vector<double> forces(ts.forces.size()), out(jm.names.size());
  for (size_t i = 0; i < ns; ++i) {
    for (size_t f = 0; f < forces.size(); ++f) forces[f] = ts.forces[f][i];
    calc_joint_outputs(jm, m.table, ws, ts.q[i], ts.qdot[i], ts.qddot[i], forces.data(), out.data());
    for (size_t c = 0; c < out.size(); ++c) ts.columns[c][i] = out[c];
  }
  drop_internal_lines(s, ts);
}

}  // namespace rdyn::reduced
