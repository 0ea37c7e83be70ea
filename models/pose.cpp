#include "models/pose.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace rdyn::models {

Pose calc_pose(const Scene& s, const std::vector<double>& q_joint) {
  const size_t nj = s.joints.size();
  if (q_joint.size() != nj) throw std::invalid_argument("calc_pose: one coordinate per joint expected");
  for (double v : q_joint)
    if (!std::isfinite(v)) throw std::invalid_argument("calc_pose: a joint coordinate is not finite");
  Pose pose;
  pose.bodies.assign(s.bodies.size(), BodyPose{});
  pose.joints.assign(nj, Vec2{});
  std::vector<char> placed(s.bodies.size(), 0), done(nj, 0);
  // Parents before children: at most nj passes over the joints, each placing at least one child
  // of a placed body, else the tree is broken.
  size_t n_done = 0;
  for (size_t pass = 0; pass < nj && n_done < nj; ++pass) {
    for (size_t j = 0; j < nj; ++j) {
      if (done[j]) continue;
      const Joint& jt = s.joints[j];
      const bool from_ground = jt.parent == kGround;
      const int pb = from_ground ? -1 : s.body_index(jt.parent);
      const int cb = s.body_index(jt.child);
      if (cb < 0 || (!from_ground && pb < 0)) throw std::invalid_argument("calc_pose: joint '" + jt.name + "' names an unknown body");
      if (!from_ground && !placed[pb]) continue;
      const BodyPose P = from_ground ? BodyPose{} : pose.bodies[pb];
      const double cP = std::cos(P.angle_rad), sP = std::sin(P.angle_rad);
      double px = jt.parent_point.x, py = jt.parent_point.y;
      BodyPose C = P;
      if (jt.type == JointType::Revolute) {
        C.angle_rad = P.angle_rad + jt.offset_rad + q_joint[j];
      } else {  // slides along the axis (parent frame) by q
        px += jt.axis.x * q_joint[j];
        py += jt.axis.y * q_joint[j];
      }
      // p_GJ: the joint point in ground; the child origin is then p_GJ − R_C·child_point.
      const double jx = P.x_m + cP * px - sP * py, jy = P.y_m + sP * px + cP * py;
      const double cC = std::cos(C.angle_rad), sC = std::sin(C.angle_rad);
      C.x_m = jx - (cC * jt.child_point.x - sC * jt.child_point.y);
      C.y_m = jy - (sC * jt.child_point.x + cC * jt.child_point.y);
      pose.bodies[cb] = C;
      pose.joints[j] = Vec2{jx, jy};
      placed[cb] = 1;
      done[j] = 1;
      ++n_done;
    }
  }
  if (n_done < nj) throw std::invalid_argument("calc_pose: the joints do not form a tree rooted at ground");
  return pose;
}

Vec2 calc_ground_point(const Scene& s, const Pose& pose, const std::string& body, Vec2 p) {
  if (body == kGround) return p;
  const int b = s.body_index(body);
  if (b < 0 || static_cast<size_t>(b) >= pose.bodies.size())
    throw std::invalid_argument("calc_ground_point: unknown body '" + body + "'");
  const BodyPose& B = pose.bodies[b];
  const double c = std::cos(B.angle_rad), si = std::sin(B.angle_rad);
  return Vec2{B.x_m + c * p.x - si * p.y, B.y_m + si * p.x + c * p.y};
}

std::vector<Vec2> calc_body_points(const Scene& s, const std::string& body) {
  std::vector<Vec2> pts;
  auto add = [&](const std::string& b, Vec2 p) {
    if (b != body) return;
    for (const auto& q : pts)
      if (std::abs(q.x - p.x) < kSamePoint_m && std::abs(q.y - p.y) < kSamePoint_m) return;
    pts.push_back(p);
  };
  if (const Body* b = s.find_body(body))
    for (const auto& [name, p] : b->points) add(body, p);
  for (const auto& j : s.joints) add(j.parent, j.parent_point), add(j.child, j.child_point);
  for (const auto& l : s.loops) add(l.body_a, l.point_a), add(l.body_b, l.point_b);
  for (const auto& sp : s.springs) add(sp.body_a, sp.point_a), add(sp.body_b, sp.point_b);
  for (const auto& pf : s.point_forces) add(pf.body_a, pf.point_a), add(pf.body_b, pf.point_b);
  return pts;
}

std::vector<Vec2> calc_body_outline(const Scene& s, const std::string& body) {
  std::vector<Vec2> pts = calc_body_points(s, body);
  if (pts.empty()) return pts;
  double cx = 0, cy = 0;
  for (const auto& p : pts) cx += p.x, cy += p.y;
  cx /= static_cast<double>(pts.size()), cy /= static_cast<double>(pts.size());
  std::stable_sort(pts.begin(), pts.end(), [&](const Vec2& a, const Vec2& b) {
    return std::atan2(a.y - cy, a.x - cx) < std::atan2(b.y - cy, b.x - cx);
  });
  return pts;
}

}  // namespace rdyn::models
