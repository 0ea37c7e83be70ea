// MJCF export: well-formed XML (expat) for every shipped scene, names and free text escaped,
// and the bodies placed so that every joint's two points coincide — composed here from the
// written poses, against a four-bar closed in closed form.
#include "models/mjcf_export.hpp"

#include <expat.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <fstream>
#include <sstream>

#include "models/pose.hpp"
#include "models/scene_yaml.hpp"

#ifdef RDYN_HAVE_MUJOCO
#include <mujoco/mujoco.h>
#endif

namespace rdyn::models {
namespace {

struct Element {
  std::string tag;
  std::map<std::string, std::string> attr;
  int parent = -1;  // index of the enclosing element
};

struct Parsed {
  bool ok = false;
  std::string error;
  std::vector<Element> elements;
  std::string comments;
};

// Parses `xml` with expat (a conforming XML 1.0 parser): elements, attributes, comments.
Parsed parse(const std::string& xml) {
  struct Ctx {
    Parsed p;
    std::vector<int> open;
  } ctx;
  XML_Parser parser = XML_ParserCreate("UTF-8");
  XML_SetUserData(parser, &ctx);
  XML_SetElementHandler(
      parser,
      [](void* data, const XML_Char* name, const XML_Char** atts) {
        auto& c = *static_cast<Ctx*>(data);
        Element e{name, {}, c.open.empty() ? -1 : c.open.back()};
        for (int i = 0; atts[i]; i += 2) e.attr[atts[i]] = atts[i + 1];
        c.p.elements.push_back(e);
        c.open.push_back(static_cast<int>(c.p.elements.size()) - 1);
      },
      [](void* data, const XML_Char*) { static_cast<Ctx*>(data)->open.pop_back(); });
  XML_SetCommentHandler(parser, [](void* data, const XML_Char* text) { static_cast<Ctx*>(data)->p.comments += text; });
  ctx.p.ok = XML_Parse(parser, xml.data(), static_cast<int>(xml.size()), 1) == XML_STATUS_OK;
  if (!ctx.p.ok)
    ctx.p.error = std::string(XML_ErrorString(XML_GetErrorCode(parser))) + " at line " +
                  std::to_string(XML_GetCurrentLineNumber(parser));
  XML_ParserFree(parser);
  return ctx.p;
}

int count(const Parsed& p, const std::string& tag) {
  int n = 0;
  for (const auto& e : p.elements) n += e.tag == tag;
  return n;
}

std::vector<double> numbers(const std::string& s) {
  std::vector<double> v;
  std::istringstream in(s);
  for (double x; in >> x;) v.push_back(x);
  return v;
}

// World pose (x, y, angle) of each <body> element, composed from the nested pos/quat.
struct Pose {
  double x = 0, y = 0, a = 0;
  Vec2 apply(Vec2 p) const {
    return {x + std::cos(a) * p.x - std::sin(a) * p.y, y + std::sin(a) * p.x + std::cos(a) * p.y};
  }
};
std::map<std::string, Pose> world_poses(const Parsed& p) {
  std::map<int, Pose> by_index;
  std::map<std::string, Pose> by_name{{"world", {}}};
  for (size_t i = 0; i < p.elements.size(); ++i) {
    const auto& e = p.elements[i];
    if (e.tag != "body") continue;
    Pose parent;
    if (auto it = by_index.find(e.parent); it != by_index.end()) parent = it->second;
    const auto pos = numbers(e.attr.at("pos"));
    const auto quat = numbers(e.attr.at("quat"));
    const Vec2 o = parent.apply({pos[0], pos[1]});
    Pose w{o.x, o.y, parent.a + 2 * std::atan2(quat[3], quat[0])};
    by_index[static_cast<int>(i)] = w;
    by_name[e.attr.at("name")] = w;
  }
  return by_name;
}

std::vector<std::filesystem::path> shipped_scenes() {
  std::vector<std::filesystem::path> out;
  for (const auto& e : std::filesystem::recursive_directory_iterator(RDYN_SCENES))
    if (e.path().extension() == ".yaml") out.push_back(e.path());
  return out;
}

TEST(MjcfExport, EveryShippedSceneIsWellFormedWithOneElementPerPart) {
  const auto scenes = shipped_scenes();
  ASSERT_GE(scenes.size(), 3u);
  for (const auto& path : scenes) {
    const Scene s = load_scene(path.string());
    for (bool fold : {false, true}) {
      MjcfOptions o;
      o.fold_geared_bodies = fold;
      const Parsed p = parse(export_mjcf(s, o));
      ASSERT_TRUE(p.ok) << path << ": " << p.error;
      EXPECT_EQ(p.elements.at(0).tag, "mujoco");
      int folded = 0;
      for (bool f : calc_foldable_gears(s)) folded += fold && f;
      EXPECT_EQ(count(p, "body"), static_cast<int>(s.bodies.size()) - folded) << path;
      EXPECT_EQ(count(p, "joint"), static_cast<int>(s.joints.size() + s.gears.size()) - 2 * folded) << path;
      EXPECT_EQ(count(p, "connect"), static_cast<int>(s.loops.size())) << path;
      EXPECT_EQ(count(p, "inertial"), count(p, "body")) << path;
    }
  }
}

TEST(MjcfExport, BicycleFlywheelFoldsIntoTheCrankWithItsGearedInertia) {
  const Scene s = load_scene("bicycle");
  const auto foldable = calc_foldable_gears(s);
  ASSERT_EQ(foldable.size(), 1u);
  EXPECT_TRUE(foldable[0]);
  MjcfOptions o;
  o.fold_geared_bodies = true;
  const Parsed p = parse(export_mjcf(s, o));
  const auto* crank = s.find_body("crank");
  const auto* fly = s.find_body("flywheel");
  const double r = s.gears[0].ratio;
  for (const auto& e : p.elements) {
    if (e.tag != "inertial" || p.elements[e.parent].attr.at("name") != "crank") continue;
    const auto I = numbers(e.attr.at("diaginertia"));
    EXPECT_NEAR(I[2], crank->inertia_kgm2 + r * r * fly->inertia_kgm2, 1e-12);
    EXPECT_NEAR(I[0] + I[1], I[2], 1e-12);  // a planar lamina: Ixx + Iyy = Izz
  }
  EXPECT_NE(p.comments.find("body 'flywheel' folded into the child of joint 'crank'"), std::string::npos)
      << p.comments;
}

// Four-bar closed by circle intersection (independent of the exporter): the written poses put
// every joint's points, and the loop's, on top of each other.
TEST(MjcfExport, BodiesArePlacedSoJointsAndClosedLoopsCoincide) {
  Scene s = load_scene("fourbar");
  const double q = 30 * M_PI / 180;
  const Vec2 A = s.ground_points.at("A"), D = s.ground_points.at("D");
  const double lc = 0.08, lk = 0.28, lr = 0.20;
  const Vec2 B{A.x + lc * std::cos(q), A.y + lc * std::sin(q)};
  const double dx = D.x - B.x, dy = D.y - B.y, d = std::hypot(dx, dy);
  const double a = (lk * lk - lr * lr + d * d) / (2 * d), h = std::sqrt(lk * lk - a * a);
  const Vec2 C{B.x + a * dx / d - h * dy / d, B.y + a * dy / d + h * dx / d};  // upper branch
  const double th_coupler = std::atan2(C.y - B.y, C.x - B.x), th_rocker = std::atan2(C.y - D.y, C.x - D.x);
  MjcfOptions o;
  o.reference_q = {q, th_coupler - q, th_rocker};
  const Parsed p = parse(export_mjcf(s, o));
  ASSERT_TRUE(p.ok) << p.error;
  const auto w = world_poses(p);
  auto at = [&](const std::string& body, Vec2 pt) {
    return body == kGround ? pt : w.at(body).apply(pt);
  };
  for (const auto& j : s.joints) {
    const Vec2 pp = at(j.parent, j.parent_point), pc = at(j.child, j.child_point);
    EXPECT_NEAR(std::hypot(pp.x - pc.x, pp.y - pc.y), 0.0, 1e-12) << j.name;
  }
  const auto& l = s.loops[0];
  const Vec2 pa = at(l.body_a, l.point_a), pb = at(l.body_b, l.point_b);
  EXPECT_NEAR(std::hypot(pa.x - pb.x, pa.y - pb.y), 0.0, 1e-12);
  EXPECT_NEAR(pa.x, C.x, 1e-12);
  EXPECT_NEAR(pa.y, C.y, 1e-12);
  // The hinge refs are the coordinates, so MuJoCo's qpos0 is the scene's q.
  for (const auto& e : p.elements) {
    if (e.tag == "joint" && e.attr.at("name") == "rocker") {
      EXPECT_NEAR(std::stod(e.attr.at("ref")), th_rocker, 1e-15);
    }
  }
}

// The visual capsules of the four-bar (models/scenes/fourbar.yaml): each body is a bar between
// its two joint points, written out here from the scene file, so one capsule per body, as long
// as the bar, ending on those points; visual only (no contact).
TEST(MjcfExport, FourbarBodiesCarryOneCapsuleAlongEachBar) {
  const Scene s = load_scene("fourbar");
  const Parsed p = parse(export_mjcf(s, {}));
  ASSERT_TRUE(p.ok) << p.error;
  std::map<std::string, std::vector<std::vector<double>>> fromto;  // body → its capsules' fromto
  for (const auto& e : p.elements) {
    if (e.tag != "geom" || e.attr.at("type") != "capsule") continue;
    EXPECT_EQ(e.attr.at("contype"), "0");
    EXPECT_EQ(e.attr.at("conaffinity"), "0");
    EXPECT_EQ(e.attr.count("mass"), 0u);
    fromto[p.elements[e.parent].attr.at("name")].push_back(numbers(e.attr.at("fromto")));
  }
  ASSERT_EQ(fromto.size(), 3u);
  // Each bar from its frame origin (the joint to its parent) to the far joint, along x.
  for (const auto& [body, length] : {std::pair<std::string, double>{"crank", 0.08}, {"coupler", 0.28}, {"rocker", 0.20}}) {
    ASSERT_EQ(fromto[body].size(), 1u) << body;
    const auto& c = fromto[body][0];
    ASSERT_EQ(c.size(), 6u);
    EXPECT_NEAR(std::hypot(c[3] - c[0], c[4] - c[1]), length, 1e-15) << body;
    EXPECT_EQ(std::min(std::hypot(c[0], c[1]), std::hypot(c[3], c[4])), 0.0) << body << ": one end at the origin";
    EXPECT_EQ(c[2], 0.0);
    EXPECT_EQ(c[5], 0.0);
  }
  // Ground: a sphere at each pivot (A, D), in the world body.
  int ground_spheres = 0;
  for (const auto& e : p.elements)
    ground_spheres += e.tag == "geom" && e.attr.at("type") == "sphere" && p.elements[e.parent].tag == "worldbody";
  EXPECT_EQ(ground_spheres, 2);
  // Without visual geoms: none at all.
  MjcfOptions bare;
  bare.visual_geoms = false;
  EXPECT_EQ(count(parse(export_mjcf(s, bare)), "geom"), 0);
}

// Every shipped scene: a body with n ≥ 3 distinct points gets n capsules (its closed outline), a
// bar 1, and together their ends are exactly the points the body carries — its named points and
// every joint, loop, spring and point-force attachment on it, listed here from the scene.
TEST(MjcfExport, EveryBodysCapsulesEndOnEveryPointItCarries) {
  for (const auto& path : shipped_scenes()) {
    const Scene s = load_scene(path.string());
    const Parsed p = parse(export_mjcf(s, {}));
    ASSERT_TRUE(p.ok) << path << ": " << p.error;
    for (const auto& b : s.bodies) {
      std::vector<Vec2> carried;
      auto carry = [&](const std::string& body, Vec2 pt) {
        if (body != b.name) return;
        for (const auto& c : carried)
          if (std::hypot(c.x - pt.x, c.y - pt.y) < 1e-12) return;
        carried.push_back(pt);
      };
      for (const auto& [n, pt] : b.points) carry(b.name, pt);
      for (const auto& j : s.joints) carry(j.parent, j.parent_point), carry(j.child, j.child_point);
      for (const auto& l : s.loops) carry(l.body_a, l.point_a), carry(l.body_b, l.point_b);
      for (const auto& sp : s.springs) carry(sp.body_a, sp.point_a), carry(sp.body_b, sp.point_b);
      for (const auto& pf : s.point_forces) carry(pf.body_a, pf.point_a), carry(pf.body_b, pf.point_b);
      std::vector<Vec2> ends;
      int capsules = 0, spheres = 0;
      for (const auto& e : p.elements) {
        if (e.tag != "geom" || p.elements[e.parent].attr.count("name") == 0 ||
            p.elements[e.parent].attr.at("name") != b.name)
          continue;
        EXPECT_EQ(e.attr.at("contype"), "0") << path;
        if (e.attr.at("type") == "sphere") {
          ++spheres;
          continue;
        }
        ++capsules;
        const auto c = numbers(e.attr.at("fromto"));
        ends.push_back({c[0], c[1]}), ends.push_back({c[3], c[4]});
      }
      const size_t n = carried.size();
      if (n < 2) {
        EXPECT_EQ(capsules, 0) << path << " " << b.name;
        EXPECT_EQ(spheres, 1) << path << " " << b.name;
        continue;
      }
      EXPECT_EQ(capsules, n == 2 ? 1 : static_cast<int>(n)) << path << " " << b.name;
      EXPECT_EQ(spheres, 0) << path << " " << b.name;
      // Each carried point ends two capsules of a polygon (one of a bar), and every end is a carried point.
      for (const auto& c : carried) {
        int at = 0;
        for (const auto& e : ends) at += e.x == c.x && e.y == c.y;
        EXPECT_EQ(at, n == 2 ? 1 : 2) << path << " " << b.name << " point " << c.x << ", " << c.y;
      }
      EXPECT_EQ(ends.size(), n == 2 ? 2u : 2 * n);
    }
  }
}

#ifdef RDYN_HAVE_MUJOCO
// MuJoCo's own reading of the export: loaded with and without the visual geoms, the bodies'
// masses, inertias and their frames are identical (the geoms add no mass: inertiafromgeom is
// false), no geom takes part in contacts, and at qpos0 (the reference coordinates) MuJoCo's
// kinematics puts every capsule's ends on the body's points where models::calc_pose puts them.
struct MjModelPtr {
  mjModel* m = nullptr;
  ~MjModelPtr() { if (m) mj_deleteModel(m); }
};

mjModel* load_mjcf(const std::string& xml, const std::string& name) {
  const auto path = std::filesystem::temp_directory_path() / (name + "_" + std::to_string(::getpid()) + ".xml");
  { std::ofstream(path) << xml; }
  char err[1000] = "";
  mjModel* m = mj_loadXML(path.c_str(), nullptr, err, sizeof err);
  std::filesystem::remove(path);
  EXPECT_NE(m, nullptr) << name << ": " << err;
  return m;
}

TEST(MjcfExport, MujocoLoadsTheCapsulesWithoutChangingMassOrInertia) {
  for (const auto& path : shipped_scenes()) {
    const Scene s = load_scene(path.string());
    MjcfOptions with, without;
    without.visual_geoms = false;
    MjModelPtr a{load_mjcf(export_mjcf(s, with), "with")}, b{load_mjcf(export_mjcf(s, without), "without")};
    ASSERT_TRUE(a.m && b.m) << path;
    ASSERT_EQ(a.m->nbody, b.m->nbody) << path;
    EXPECT_EQ(b.m->ngeom, 0) << path;
    EXPECT_GT(a.m->ngeom, 0) << path;
    for (int i = 0; i < a.m->nbody; ++i) {
      EXPECT_EQ(a.m->body_mass[i], b.m->body_mass[i]) << path << " body " << i;
      for (int k = 0; k < 3; ++k) {
        EXPECT_EQ(a.m->body_inertia[3 * i + k], b.m->body_inertia[3 * i + k]) << path << " body " << i;
        EXPECT_EQ(a.m->body_ipos[3 * i + k], b.m->body_ipos[3 * i + k]) << path << " body " << i;
        EXPECT_EQ(a.m->body_pos[3 * i + k], b.m->body_pos[3 * i + k]) << path << " body " << i;
      }
      for (int k = 0; k < 4; ++k) EXPECT_EQ(a.m->body_iquat[4 * i + k], b.m->body_iquat[4 * i + k]) << path;
    }
    for (int g = 0; g < a.m->ngeom; ++g) {
      EXPECT_EQ(a.m->geom_contype[g], 0);
      EXPECT_EQ(a.m->geom_conaffinity[g], 0);
    }
    // Capsule ends in the world at qpos0 (MuJoCo: centre ± half-length along the geom's z axis)
    // against the body's points placed by calc_pose at the same coordinates (the joints' guesses).
    mjData* d = mj_makeData(a.m);
    mj_forward(a.m, d);
    std::vector<double> q;
    for (const auto& j : s.joints) q.push_back(j.guess);
    const auto pose = calc_pose(s, q);
    for (int g = 0; g < a.m->ngeom; ++g) {
      if (a.m->geom_type[g] != mjGEOM_CAPSULE) continue;
      const std::string body = mj_id2name(a.m, mjOBJ_BODY, a.m->geom_bodyid[g]);
      const double h = a.m->geom_size[3 * g + 1];
      for (double sign : {-1.0, 1.0}) {
        const double x = d->geom_xpos[3 * g] + sign * h * d->geom_xmat[9 * g + 2];
        const double y = d->geom_xpos[3 * g + 1] + sign * h * d->geom_xmat[9 * g + 5];
        double nearest = HUGE_VAL;
        for (const auto& pt : calc_body_points(s, body)) {
          const Vec2 w = calc_ground_point(s, pose, body, pt);
          nearest = std::min(nearest, std::hypot(w.x - x, w.y - y));
        }
        EXPECT_LT(nearest, 1e-9) << path << " body " << body;
      }
    }
    mj_deleteData(d);
  }
}
#else
TEST(MjcfExport, MujocoLoadsTheCapsulesWithoutChangingMassOrInertia) { GTEST_SKIP() << "rdyn was built without MuJoCo"; }
#endif

TEST(MjcfExport, FreeTextAndFileNamesAreEscaped) {
  EXPECT_EQ(xml_escape("a<b>&\"c'd"), "a&lt;b&gt;&amp;&quot;c&apos;d");
  EXPECT_EQ(xml_escape(std::string("x\x01y\tz\x7f")), "xy\tz");
  EXPECT_EQ(xml_comment_text("a--b---c-"), "a- -b- - -c- ");
  Scene s = load_scene("fourbar");
  s.description = "ends the comment --> <b>&amp; \x02 and -";
  s.source_file = "dir/a&b\"<c>--d.yaml";
  const std::string xml = export_mjcf(s);
  const Parsed p = parse(xml);
  ASSERT_TRUE(p.ok) << p.error << "\n" << xml;
  EXPECT_NE(p.comments.find("ends the comment - -> <b>&amp;  and -\n"), std::string::npos) << p.comments;
  EXPECT_NE(p.comments.find("dir/a&b\"<c>- -d.yaml"), std::string::npos) << p.comments;
}

TEST(MjcfExport, GearEqualityOffsetIsTheGearsMissAtTheReferenceCoordinates) {
  const Scene s = load_scene("bicycle");
  const int jr = s.joint_index(s.gears[0].driver), jd = s.joint_index(s.gears[0].driven);
  const double r = s.gears[0].ratio;
  MjcfOptions o;  // not folded: the flywheel is geared by a joint equality
  for (const auto& j : s.joints) o.reference_q.push_back(j.guess);
  o.reference_q[jr] += 0.3;
  o.reference_q[jd] += r * 0.3 + 0.01;  // 0.01 rad past the gear: MJCF must pull it back
  const Parsed p = parse(export_mjcf(s, o));
  int gears = 0;
  for (const auto& e : p.elements) {
    if (e.tag != "joint" || !e.attr.count("polycoef")) continue;
    ++gears;
    const auto c = numbers(e.attr.at("polycoef"));
    EXPECT_NEAR(c[0], -0.01, 1e-12);  // y − y0 = a0 + r (x − x0) holds at the gear's own position
    EXPECT_EQ(c[1], r);
    EXPECT_EQ(e.attr.at("joint1"), s.gears[0].driven);
    EXPECT_EQ(e.attr.at("joint2"), s.gears[0].driver);
  }
  EXPECT_EQ(gears, 1);
}

TEST(MjcfExport, OptionsOutOfRangeAreSceneErrors) {
  const Scene s = load_scene("fourbar");
  auto refused = [&](MjcfOptions o) {
    try {
      export_mjcf(s, o);
    } catch (const SceneError& e) {
      return e.field();
    }
    return std::string();
  };
  MjcfOptions o;
  o.reference_q = {0.0};
  EXPECT_EQ(refused(o), "reference_q");
  o.reference_q = {0.0, NAN, 0.0};
  EXPECT_EQ(refused(o), "reference_q");
  o = {};
  o.timestep_s = 0;
  EXPECT_EQ(refused(o), "timestep");
  o = {};
  o.integrator = "implicit";
  EXPECT_EQ(refused(o), "integrator");
  Scene world = s;
  world.bodies[0].name = "world";  // valid in rdyn, MJCF's ground in MuJoCo
  try {
    export_mjcf(world);
    ADD_FAILURE() << "a body named world was exported";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.field(), "bodies.world.name");
  }
}

// A point force is documented among the loads rdyn's runner applies (MJCF has no such load), and
// a geared body it pulls is not folded (its point must exist as a body).
TEST(MjcfExport, PointForceIsDocumentedAndKeepsItsBodyUnfolded) {
  Scene s = load_scene("bicycle");
  PointForce pf;
  pf.name = "glute";
  pf.body_a = "ground";
  pf.point_a = {0.1, 0.5};
  pf.body_b = "flywheel";
  pf.point_b = {0.05, 0};
  pf.value = 12.5;
  pf.active_when = RateGate{"hip_r", +1};
  s.point_forces.push_back(pf);
  EXPECT_FALSE(calc_foldable_gears(s)[0]);
  const Parsed p = parse(export_mjcf(s));
  ASSERT_TRUE(p.ok) << p.error;
  EXPECT_NE(p.comments.find("point_force 'glute': tension 12.5 N along the line between ground"), std::string::npos)
      << p.comments;
  EXPECT_NE(p.comments.find("only while joint 'hip_r' turns positively"), std::string::npos) << p.comments;
}

}  // namespace
}  // namespace rdyn::models

