// A scene as MJCF, MuJoCo's XML model format: the same planar mechanism for a peer engine.
// Pure text generation from the scene (no MuJoCo here): bodies with mass, centre of mass and
// inertia, visual capsules along their outlines, hinges (axis z) and slides for the tree joints, loop closures as `connect`
// equalities, gears as `joint` equalities, gravity. MJCF cannot express rdyn's loads (rate-
// gated joint torques, resistance laws, motor lines, point-to-point springs): a comment lists
// them, and engine/mujoco_peer.cpp applies them at every evaluation.
#pragma once

#include <string>
#include <vector>

#include "models/gear_fold.hpp"
#include "models/scene.hpp"

namespace rdyn::models {

struct MjcfOptions {
  // Joint coordinates [rad or m] at which the bodies are placed, one per scene joint (scene
  // order); empty: the joints' guesses. MuJoCo infers a `connect` equality's second anchor
  // from the configuration the model is written in (MJCF reference, "connect"), so the loops
  // must be closed there: pass an assembled configuration (validate/cli/commands.cpp does).
  std::vector<double> reference_q;
  // Fold every geared body calc_foldable_gears allows into its driver (inertia r²·I added to
  // the driver's Izz, no body and no gear equality), as the full model does by default.
  bool fold_geared_bodies = false;
  double timestep_s = 1e-3;        // <option timestep> [s], > 0
  std::string integrator = "Euler";  // Euler | RK4
  // Softness of the loop and gear equalities (MuJoCo's solref = [timeconst, dampratio] and
  // solimp = [dmin, dmax, width]). timeconst 0: twice the time step, the smallest MuJoCo
  // accepts with its `refsafe` default; solimp near 1 makes the constraint nearly rigid.
  double timeconst_s = 0.0;
  double dampratio = 1.0;
  double impedance = 0.9999;  // dmin = dmax, in (0, 1)
  // What MuJoCo's viewer shows: capsules along every body's outline (models::calc_body_outline,
  // the drawing's bars and polygons; a sphere for a body with one point) and a sphere at every
  // ground attachment. Visual only: contype = conaffinity = 0 and the inertia is the <inertial>
  // (inertiafromgeom="false"), so the dynamics are the same without them. The MuJoCo peer
  // leaves them out (no geometry to update in its timed runs).
  bool visual_geoms = true;
};

// The MJCF document. Throws SceneError for a body named "world" (MJCF's ground) and for options
// out of range (reference_q of the wrong size or not finite, a time step ≤ 0, an unknown
// integrator).
std::string export_mjcf(const Scene& scene, const MjcfOptions& options = {});

// Text for an XML attribute value or element content: & < > " ' as character references,
// control characters other than tab, CR and LF dropped (XML 1.0 cannot hold them).
std::string xml_escape(const std::string& text);
// Text for an XML comment: as xml_escape's characters, with "--" (which would end or
// invalidate the comment) broken up.
std::string xml_comment_text(const std::string& text);

}  // namespace rdyn::models
