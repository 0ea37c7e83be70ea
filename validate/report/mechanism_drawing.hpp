// The mechanism drawn (`rdyn inspect --svg`, `rdyn animate`, the validate report): bodies as the
// bar or polygon through their points, joints, ground pivots, loops, gears, springs and point
// forces as lines, force arrows and point traces. Every position comes from models::calc_pose
// on the joint coordinates the models output; the page's script only moves elements to the
// positions the frames hold (no kinematics in JavaScript).
#pragma once

#include <string>
#include <vector>

#include "models/pose.hpp"
#include "models/scene.hpp"
#include "models/timeseries.hpp"

namespace rdyn::validate {

// A force drawn as an arrow at a point: its ground-frame components per frame [N].
struct ForceArrow {
  std::string name;  // label (the request's or reaction's name)
  std::string body;  // the point it acts at: body (or ground) and the point in its frame
  models::Vec2 point;
  std::vector<double> fx_N, fy_N;  // per frame, ground frame [N]
};

// What is drawn and where, frame by frame.
struct MechanismFrames {
  std::vector<double> t_s;                  // frame times [s]
  std::vector<double> q;                    // the independent coordinate per frame [rad or m]
  std::vector<std::vector<double>> q_joint;  // [frame][joint]: every joint's coordinate [rad or m]
  std::vector<ForceArrow> arrows;
  std::vector<std::string> traces;  // "body.point" whose path is drawn over the whole run
};

// One scene point: a body (or ground) and the point in its frame.
struct DrawPoint {
  std::string body;
  models::Vec2 p;
};
// Every point drawn, in a fixed order: each body's points (named points, joint, loop, spring and
// point-force attachments, deduplicated), then ground's. Scene order within each.
std::vector<DrawPoint> collect_draw_points(const models::Scene& scene);

// Arrows for the scene's requested constraint forces (outputs.constraint_forces: along the
// request's direction in the child frame) and reactions (outputs.reactions: R_<n>_x, R_<n>_y
// columns) from a run's time series, sampled at `rows` (its row indices of the frames).
std::vector<ForceArrow> force_arrows(const models::Scene& scene, const models::TimeSeries& ts,
                                     const std::vector<size_t>& rows);

// Frames from a run that outputs every joint's coordinate (analysis/mechanism_run.hpp): at most
// max_frames rows, evenly strided, the first and the last always; arrows for the scene's requested
// forces; `traces` as given (empty: the named points where the scene's loops close).
inline constexpr size_t kMaxFrames = 2000;
MechanismFrames frames_from_run(const models::Scene& scene, const models::TimeSeries& ts,
                                std::vector<std::string> traces, size_t max_frames = kMaxFrames);

// A standalone SVG of frame `frame`; `note` (escaped) is written under the drawing, e.g. the
// independent coordinate's range and dead points. Throws std::invalid_argument for a frame out
// of range or a trace naming an unknown point.
std::string mechanism_svg(const models::Scene& scene, const MechanismFrames& frames, size_t frame,
                          const std::string& note);

// One animation as a block of HTML that a page may hold several of (the validate report, the
// optimize report's two strategies): a <div class="animation"> with its controls (play/pause,
// a time slider, speed), the drawing, the frames as inline JSON and a script scoped to the div
// (no network). `#t=T` in the page's address shows the frame nearest T (clamped to the run) in
// every animation of the page; each div and its svg carry data-t and data-frame, and every
// joint element's data-x/data-y are that frame's positions. `title` (escaped) heads the block
// when not empty. Needs animation_css() in the page's style.
std::string animation_section(const models::Scene& scene, const MechanismFrames& frames, const std::string& title);
std::string animation_css();

// The self-contained page of one animation (`rdyn animate`): the section above under a heading;
// <body> carries data-t and data-frame too.
std::string animation_html(const models::Scene& scene, const MechanismFrames& frames, const std::string& title);

}  // namespace rdyn::validate
