// Where everything is: every body's frame, every joint and every body point in the ground frame
// for one set of joint coordinates (planar tree kinematics, the scene's own joint definitions).
// The drawings and animations (`rdyn inspect --svg`, `rdyn animate`) take their geometry from
// here and nowhere else: the joint coordinates come from the models (the full model's or the
// reduced model's q_<joint> output columns), this turns them into positions. Plain data.
#pragma once

#include <string>
#include <vector>

#include "models/scene.hpp"

namespace rdyn::models {

struct BodyPose {
  double x_m = 0.0, y_m = 0.0;  // body frame origin in the ground frame [m]
  double angle_rad = 0.0;       // body frame rotation about z [rad]
};

struct Pose {
  std::vector<BodyPose> bodies;  // scene.bodies order
  std::vector<Vec2> joints;      // scene.joints order: the joint's point on its child, ground frame [m]
};

// The pose for joint coordinates q_joint (scene.joints order; [rad] revolute, [m] prismatic,
// as both models output them). Revolute: child angle = parent angle + offset + q; prismatic:
// the child point sits at the parent point + q·axis (parent frame), the child keeps the parent's
// angle (models/scene.hpp, Joint). Throws std::invalid_argument when the sizes differ, a value
// is not finite or the joints do not form a tree rooted at ground.
Pose calc_pose(const Scene& scene, const std::vector<double>& q_joint);

// Point p_B (in body `body`'s frame; ground: ground frame) in the ground frame.
Vec2 calc_ground_point(const Scene& scene, const Pose& pose, const std::string& body, Vec2 p_B);

// Two attachments of one body closer than this are one point [m].
inline constexpr double kSamePoint_m = 1e-12;

// The points body `body` carries, in its own frame (ground: the ground frame): its named points
// (name order), then the attachments of joints (parent point, child point), loops, springs and
// point forces in scene order, each once (kSamePoint_m). Ground has no named points here.
std::vector<Vec2> calc_body_points(const Scene& scene, const std::string& body);

// Those points in outline order — by angle about their centroid in the body frame, hence the
// same in every pose — so that the polygon through them does not cross itself (a bar for two
// points). What the drawings (validate/report/mechanism_drawing.cpp) and the MJCF export's
// visual capsules (models/mjcf_export.cpp) draw a body as.
std::vector<Vec2> calc_body_outline(const Scene& scene, const std::string& body);

}  // namespace rdyn::models
