#include "validate/report/mechanism_drawing.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "validate/analysis/mechanism_run.hpp"
#include "validate/io/escape.hpp"

namespace rdyn::validate {

namespace {

constexpr double kSame_m = models::kSamePoint_m;  // two attachments closer than this are one drawn point
constexpr double kLabelGap = 0.015;     // an arrow's label beyond its head, × the drawing's size
constexpr double kFontFraction = 0.03;  // labels' font size, × the drawing's size

int find_point(const std::vector<DrawPoint>& pts, const std::string& body, models::Vec2 p) {
  for (size_t i = 0; i < pts.size(); ++i)
    if (pts[i].body == body && std::abs(pts[i].p.x - p.x) < kSame_m && std::abs(pts[i].p.y - p.y) < kSame_m)
      return static_cast<int>(i);
  return -1;
}

int point_of(const std::vector<DrawPoint>& pts, const std::string& body, models::Vec2 p) {
  const int i = find_point(pts, body, p);
  if (i < 0) throw std::invalid_argument("mechanism drawing: a point of '" + body + "' was not collected");
  return i;
}

// Every frame's ground positions of every drawn point: [frame][2·point + 0/1] [m].
std::vector<std::vector<double>> calc_positions(const models::Scene& s, const std::vector<DrawPoint>& pts,
                                                const MechanismFrames& f) {
  std::vector<std::vector<double>> out;
  out.reserve(f.q_joint.size());
  for (const auto& qj : f.q_joint) {
    const models::Pose pose = models::calc_pose(s, qj);
    std::vector<double> row;
    row.reserve(2 * pts.size());
    for (const auto& dp : pts) {
      const models::Vec2 g = models::calc_ground_point(s, pose, dp.body, dp.p);
      row.push_back(g.x), row.push_back(g.y);
    }
    out.push_back(std::move(row));
  }
  return out;
}

// A body's outline (models::calc_body_outline, the order the MJCF export's capsules follow too)
// as indices into the drawn points.
std::vector<int> body_outline(const models::Scene& s, const std::vector<DrawPoint>& pts, const std::string& body) {
  std::vector<int> idx;
  for (const auto& p : models::calc_body_outline(s, body)) idx.push_back(point_of(pts, body, p));
  return idx;
}

int trace_point(const models::Scene& s, const std::vector<DrawPoint>& pts, const std::string& trace) {
  const auto dot = trace.find('.');
  if (dot == std::string::npos) throw std::invalid_argument("trace '" + trace + "': give body.point");
  const std::string body = trace.substr(0, dot), name = trace.substr(dot + 1);
  const auto* b = s.find_body(body);
  if (!b || !b->points.count(name))
    throw std::invalid_argument("trace '" + trace + "': no point '" + name + "' on a body '" + body + "'");
  return point_of(pts, body, b->points.at(name));
}

// The drawing's elements: the SVG body shared by the static drawing and the page (positions of
// frame `k`; the page's script moves the elements with data-i, data-is, data-i0/data-i1).
struct Layout {
  double minx = 0, maxx = 0, miny = 0, maxy = 0, size = 1;
  double arrow_m_per_N = 0;
};

Layout calc_layout(const std::vector<DrawPoint>& pts, const std::vector<std::vector<double>>& P,
                   const std::vector<ForceArrow>& arrows) {
  Layout L;
  bool first = true;
  for (const auto& row : P)
    for (size_t i = 0; i + 1 < row.size(); i += 2) {
      if (first) L.minx = L.maxx = row[i], L.miny = L.maxy = row[i + 1], first = false;
      L.minx = std::min(L.minx, row[i]), L.maxx = std::max(L.maxx, row[i]);
      L.miny = std::min(L.miny, row[i + 1]), L.maxy = std::max(L.maxy, row[i + 1]);
    }
  L.size = std::max({L.maxx - L.minx, L.maxy - L.miny, 1e-3});
  double fmax = 0;
  for (const auto& a : arrows)
    for (size_t k = 0; k < a.fx_N.size(); ++k) fmax = std::max(fmax, std::hypot(a.fx_N[k], a.fy_N[k]));
  // The largest force of the run is drawn a quarter of the mechanism's size long.
  L.arrow_m_per_N = fmax > 0 ? 0.25 * L.size / fmax : 0.0;
  // Room for every arrow and its label over the run (placed as svg_body places them; a label's
  // width estimated at 0.6 em per character of "name 1234.5 N"), so none leaves the drawing.
  const double font = kFontFraction * L.size, gap = kLabelGap * L.size;
  for (const auto& a : arrows) {
    const int i = point_of(pts, a.body, a.point);
    const double w = 0.6 * font * static_cast<double>(a.name.size() + 9);
    for (size_t k = 0; k < a.fx_N.size() && k < P.size(); ++k) {
      const double fx = a.fx_N[k], fy = a.fy_N[k], fn = std::hypot(fx, fy);
      double x = P[k][2 * i] + L.arrow_m_per_N * fx, y = P[k][2 * i + 1] + L.arrow_m_per_N * fy;
      if (fn > 0) x += gap * fx / fn, y += gap * fy / fn;
      L.minx = std::min(L.minx, fx < 0 ? x - w : x), L.maxx = std::max(L.maxx, fx < 0 ? x : x + w);
      L.miny = std::min(L.miny, fy < 0 ? y - font : y), L.maxy = std::max(L.maxy, fy < 0 ? y : y + font);
    }
  }
  return L;
}

std::string num(double v) { return fmt::format("{}", v); }

std::string svg_body(const models::Scene& s, const MechanismFrames& f, const std::vector<DrawPoint>& pts,
                     const std::vector<std::vector<double>>& P, const Layout& L, size_t k) {
  const auto& row = P[k];
  auto X = [&](int i) { return row[2 * i]; };
  auto Y = [&](int i) { return row[2 * i + 1]; };
  auto at = [&](int i) { return fmt::format("data-i=\"{}\" data-x=\"{}\" data-y=\"{}\"", i, num(X(i)), num(Y(i))); };
  const double r = 0.012 * L.size;
  const double pad = 0.12 * L.size;
  std::string o = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"mechanism\" viewBox=\"{} {} {} {}\" "
      "data-scene=\"{}\" data-t=\"{}\" data-frame=\"{}\">\n",
      num(L.minx - pad), num(-L.maxy - pad), num(L.maxx - L.minx + 2 * pad), num(L.maxy - L.miny + 2 * pad + 0.08 * L.size),
      html_escape(s.name), num(f.t_s[k]), k);
  o += "<defs><marker id=\"head\" viewBox=\"0 0 10 10\" refX=\"9\" refY=\"5\" markerWidth=\"6\" markerHeight=\"6\" "
       "orient=\"auto-start-reverse\"><path d=\"M0,0 L10,5 L0,10 z\" fill=\"#c0392b\"/></marker></defs>\n";
  o += "<style>.mechanism line,.mechanism polyline,.mechanism polygon,.mechanism circle,.mechanism path"
       "{vector-effect:non-scaling-stroke}</style>\n";
  // Traces: the path of each chosen point over the whole run (static).
  o += "<g class=\"traces\" fill=\"none\" stroke=\"#8e44ad\" stroke-width=\"1\" stroke-dasharray=\"4 3\">\n";
  for (const auto& tr : f.traces) {
    const int i = trace_point(s, pts, tr);
    std::string path;
    for (const auto& rr : P) path += num(rr[2 * i]) + "," + num(-rr[2 * i + 1]) + " ";
    o += fmt::format("<polyline data-trace=\"{}\" points=\"{}\"/>\n", html_escape(tr), path);
  }
  o += "</g>\n<g class=\"ground\" stroke=\"#555\" stroke-width=\"1.5\" fill=\"#bbb\">\n";
  // Ground pivots: a triangle under each ground point a revolute joint or a loop hangs from;
  // a prismatic joint's rail as a line along its axis.
  for (const auto& j : s.joints) {
    if (j.parent != models::kGround) continue;
    const int i = point_of(pts, models::kGround, j.parent_point);
    if (j.type == models::JointType::Revolute) {
      o += fmt::format("<path data-ground-pivot=\"{}\" {} d=\"M{},{} l{},{} l{},0 z\"/>\n", html_escape(j.name), at(i),
                       num(X(i)), num(-Y(i)), num(-r * 1.6), num(2.6 * r), num(3.2 * r));
    } else {
      const double len = L.size;
      o += fmt::format("<line data-rail=\"{}\" {} x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke-dasharray=\"6 3\"/>\n",
                       html_escape(j.name), at(i), num(X(i) - len * j.axis.x), num(-(Y(i) - len * j.axis.y)),
                       num(X(i) + len * j.axis.x), num(-(Y(i) + len * j.axis.y)));
    }
  }
  for (const auto& l : s.loops)
    for (const auto& [b, p] : {std::pair{l.body_a, l.point_a}, std::pair{l.body_b, l.point_b}})
      if (b == models::kGround) {
        const int i = point_of(pts, models::kGround, p);
        o += fmt::format("<path data-ground-pivot=\"{}\" {} d=\"M{},{} l{},{} l{},0 z\"/>\n", html_escape(l.name), at(i),
                         num(X(i)), num(-Y(i)), num(-r * 1.6), num(2.6 * r), num(3.2 * r));
      }
  o += "</g>\n<g class=\"lines\" fill=\"none\" stroke-width=\"1.5\">\n";
  auto seg = [&](const char* kind, const std::string& name, int a, int b, const char* style) {
    o += fmt::format("<line data-{}=\"{}\" data-i0=\"{}\" data-i1=\"{}\" x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" {}/>\n",
                     kind, html_escape(name), a, b, num(X(a)), num(-Y(a)), num(X(b)), num(-Y(b)), style);
  };
  for (const auto& sp : s.springs)
    seg("spring", sp.name, point_of(pts, sp.body_a, sp.point_a), point_of(pts, sp.body_b, sp.point_b),
        "stroke=\"#27ae60\" stroke-dasharray=\"2 2\"");
  for (const auto& pf : s.point_forces)
    seg("point-force", pf.name, point_of(pts, pf.body_a, pf.point_a), point_of(pts, pf.body_b, pf.point_b),
        "stroke=\"#d35400\"");
  auto joint_pt = [&](const models::Joint& j) { return point_of(pts, j.child, j.child_point); };
  for (const auto& g : s.gears) {
    const auto *a = s.find_joint(g.driver), *b = s.find_joint(g.driven);
    if (a && b) seg("gear", g.name, joint_pt(*a), joint_pt(*b), "stroke=\"#7f8c8d\" stroke-dasharray=\"8 4\"");
  }
  // A prismatic joint between bodies as the stroke from its parent point to its child point (a
  // cylinder's length); one on ground already has its rail.
  for (const auto& j : s.joints)
    if (j.type == models::JointType::Prismatic && j.parent != models::kGround)
      seg("slide", j.name, point_of(pts, j.parent, j.parent_point), joint_pt(j), "stroke=\"#2c3e50\" stroke-width=\"6\"");
  o += "</g>\n<g class=\"bodies\" stroke=\"#2c3e50\" stroke-width=\"3\" stroke-linejoin=\"round\">\n";
  for (const auto& b : s.bodies) {
    const auto idx = body_outline(s, pts, b.name);
    std::string list, path;
    for (int i : idx) list += (list.empty() ? "" : " ") + std::to_string(i), path += num(X(i)) + "," + num(-Y(i)) + " ";
    if (idx.size() == 1) {  // a body with one point (a cylinder's barrel): a disc there
      o += fmt::format("<circle data-body=\"{}\" {} cx=\"{}\" cy=\"{}\" r=\"{}\" fill=\"#5dade2\"/>\n",
                       html_escape(b.name), at(idx[0]), num(X(idx[0])), num(-Y(idx[0])), num(2 * r));
      continue;
    }
    const bool polygon = idx.size() >= 3;
    o += fmt::format("<{} data-body=\"{}\" data-is=\"{}\" points=\"{}\" fill=\"{}\" fill-opacity=\"0.35\"/>\n",
                     polygon ? "polygon" : "polyline", html_escape(b.name), list, path, polygon ? "#5dade2" : "none");
  }
  o += "</g>\n<g class=\"loops\" fill=\"none\" stroke=\"#e67e22\" stroke-width=\"1.5\">\n";
  for (const auto& l : s.loops) {
    const int a = point_of(pts, l.body_a, l.point_a), b = point_of(pts, l.body_b, l.point_b);
    o += fmt::format("<circle data-loop=\"{}\" data-side=\"a\" {} cx=\"{}\" cy=\"{}\" r=\"{}\"/>\n", html_escape(l.name),
                     at(a), num(X(a)), num(-Y(a)), num(1.5 * r));
    o += fmt::format("<circle data-loop=\"{}\" data-side=\"b\" {} cx=\"{}\" cy=\"{}\" r=\"{}\"/>\n", html_escape(l.name),
                     at(b), num(X(b)), num(-Y(b)), num(1.5 * r));
  }
  o += "</g>\n<g class=\"joints\" fill=\"#fff\" stroke=\"#000\" stroke-width=\"1.5\">\n";
  for (const auto& j : s.joints) {
    const int i = joint_pt(j);
    o += fmt::format("<circle data-joint=\"{}\" {} cx=\"{}\" cy=\"{}\" r=\"{}\"{}/>\n", html_escape(j.name), at(i),
                     num(X(i)), num(-Y(i)), num(r), j.name == s.independent ? " fill=\"#f1c40f\"" : "");
  }
  o += "</g>\n<g class=\"arrows\" stroke=\"#c0392b\" stroke-width=\"2\" fill=\"#c0392b\">\n";
  for (size_t a = 0; a < f.arrows.size(); ++a) {
    const auto& A = f.arrows[a];
    const int i = point_of(pts, A.body, A.point);
    const double fx = A.fx_N[k], fy = A.fy_N[k];
    const double x2 = X(i) + L.arrow_m_per_N * fx, y2 = Y(i) + L.arrow_m_per_N * fy;
    o += fmt::format("<line data-arrow=\"{}\" data-i=\"{}\" data-fx=\"{}\" data-fy=\"{}\" x1=\"{}\" y1=\"{}\" x2=\"{}\" "
                     "y2=\"{}\" marker-end=\"url(#head)\"/>\n",
                     a, i, num(fx), num(fy), num(X(i)), num(-Y(i)), num(x2), num(-y2));
    // The label just beyond the arrow's head, on the side it points to (left or right, below or
    // above), so the head does not hide it.
    const double fn = std::hypot(fx, fy), gap = kLabelGap * L.size;
    const double lx = x2 + (fn > 0 ? gap * fx / fn : 0.0), ly = y2 + (fn > 0 ? gap * fy / fn : 0.0);
    o += fmt::format("<text data-arrow-label=\"{}\" data-name=\"{}\" x=\"{}\" y=\"{}\" text-anchor=\"{}\" "
                     "dominant-baseline=\"{}\" font-size=\"{}\" stroke=\"none\">{} {:.1f} N</text>\n",
                     a, html_escape(A.name), num(lx), num(-ly), fx < 0 ? "end" : "start", fy < 0 ? "hanging" : "auto",
                     num(kFontFraction * L.size), html_escape(A.name), fn);
  }
  o += "</g>\n";
  return o;
}

std::string q_text(const models::Scene& s, double q) {
  const auto* j = s.find_joint(s.independent);
  const bool rev = !j || j->type == models::JointType::Revolute;
  const double deg = q * 180 / 3.14159265358979323846;
  if (rev && std::abs(deg) >= 360)  // an unwrapped angle: also within one turn, as a dial reads it
    return fmt::format("{} = {:.2f}° ({:.2f}° in the turn)", s.independent, deg, deg - 360 * std::floor(deg / 360));
  return rev ? fmt::format("{} = {:.2f}°", s.independent, deg)
             : fmt::format("{} = {:.4f} m", s.independent, q);
}

void check_frames(const models::Scene& s, const MechanismFrames& f) {
  const size_t n = f.t_s.size();
  if (n == 0 || f.q.size() != n || f.q_joint.size() != n)
    throw std::invalid_argument("mechanism drawing: frames need t, q and the joint coordinates of each frame");
  for (const auto& a : f.arrows)
    if (a.fx_N.size() != n || a.fy_N.size() != n)
      throw std::invalid_argument("mechanism drawing: arrow '" + a.name + "' has not one force per frame");
  for (size_t k = 0; k < n; ++k)
    if (!std::isfinite(f.t_s[k]) || !std::isfinite(f.q[k]) || (k > 0 && !(f.t_s[k] > f.t_s[k - 1])))
      throw std::invalid_argument("mechanism drawing: frame times must be finite and increasing");
  (void)s;
}

}  // namespace

std::vector<DrawPoint> collect_draw_points(const models::Scene& s) {
  std::vector<DrawPoint> pts;
  for (const auto& b : s.bodies)
    for (const auto& p : models::calc_body_points(s, b.name)) pts.push_back({b.name, p});
  for (const auto& p : models::calc_body_points(s, models::kGround)) pts.push_back({models::kGround, p});
  return pts;
}

std::vector<ForceArrow> force_arrows(const models::Scene& s, const models::TimeSeries& ts,
                                     const std::vector<size_t>& rows) {
  std::vector<ForceArrow> out;
  // Requested constraint forces: a scalar along a direction fixed in the child frame, at the joint.
  for (const auto& req : s.outputs.constraint_forces) {
    const auto it = std::find(ts.force_names.begin(), ts.force_names.end(), req.name);
    const auto* j = s.find_joint(req.joint);
    if (it == ts.force_names.end() || !j) continue;
    const size_t c = static_cast<size_t>(it - ts.force_names.begin());
    ForceArrow a{req.name, j->child, j->child_point, {}, {}};
    for (size_t r : rows) {
      const double th = models::calc_pose(s, joint_coordinates(s, ts, r)).bodies[s.body_index(j->child)].angle_rad;
      const double F = ts.forces[c][r];
      a.fx_N.push_back(F * (std::cos(th) * req.direction.x - std::sin(th) * req.direction.y));
      a.fy_N.push_back(F * (std::sin(th) * req.direction.x + std::cos(th) * req.direction.y));
    }
    out.push_back(std::move(a));
  }
  // Reactions: ground-frame components R_<n>_x, R_<n>_y at the joint (its child point) or at the
  // loop's point on body_b.
  for (const auto& name : s.outputs.reactions) {
    const auto cx = std::find(ts.column_names.begin(), ts.column_names.end(), "R_" + name + "_x");
    const auto cy = std::find(ts.column_names.begin(), ts.column_names.end(), "R_" + name + "_y");
    if (cx == ts.column_names.end() || cy == ts.column_names.end()) continue;
    ForceArrow a{"R_" + name, "", {}, {}, {}};
    if (const auto* j = s.find_joint(name)) {
      a.body = j->child, a.point = j->child_point;
    } else {
      for (const auto& l : s.loops)
        if (l.name == name) a.body = l.body_b, a.point = l.point_b;
    }
    if (a.body.empty()) continue;
    for (size_t r : rows) {
      a.fx_N.push_back(ts.columns[cx - ts.column_names.begin()][r]);
      a.fy_N.push_back(ts.columns[cy - ts.column_names.begin()][r]);
    }
    out.push_back(std::move(a));
  }
  return out;
}

MechanismFrames frames_from_run(const models::Scene& s, const models::TimeSeries& ts, std::vector<std::string> traces,
                                size_t max_frames) {
  const size_t n = ts.t.size();
  if (n == 0 || max_frames < 2) throw std::invalid_argument("frames_from_run: an empty run");
  std::vector<size_t> rows;
  const size_t stride = (n + max_frames - 2) / (max_frames - 1);  // ceil((n − 1)/(max − 1)) for n > 1
  for (size_t r = 0; r < n; r += std::max<size_t>(stride, 1)) rows.push_back(r);
  if (rows.back() != n - 1) rows.push_back(n - 1);
  MechanismFrames f;
  for (size_t r : rows) {
    f.t_s.push_back(ts.t[r]);
    f.q.push_back(ts.q[r]);
    f.q_joint.push_back(joint_coordinates(s, ts, r));
  }
  f.arrows = force_arrows(s, ts, rows);
  if (traces.empty())
    for (const auto& l : s.loops)
      for (const auto& [body, p] : {std::pair{l.body_a, l.point_a}, std::pair{l.body_b, l.point_b}})
        if (const auto* b = s.find_body(body))
          for (const auto& [name, bp] : b->points)
            if (std::abs(bp.x - p.x) < kSame_m && std::abs(bp.y - p.y) < kSame_m &&
                std::find(traces.begin(), traces.end(), body + "." + name) == traces.end())
              traces.push_back(body + "." + name);
  f.traces = std::move(traces);
  return f;
}

std::string mechanism_svg(const models::Scene& s, const MechanismFrames& f, size_t frame, const std::string& note) {
  check_frames(s, f);
  if (frame >= f.t_s.size()) throw std::invalid_argument("mechanism drawing: no such frame");
  const auto pts = collect_draw_points(s);
  const auto P = calc_positions(s, pts, f);
  const Layout L = calc_layout(pts, P, f.arrows);
  std::string o = svg_body(s, f, pts, P, L, frame);
  const double fs = kFontFraction * L.size;
  o += fmt::format("<text class=\"q\" x=\"{}\" y=\"{}\" font-size=\"{}\">{}</text>\n", num(L.minx - 0.1 * L.size),
                   num(-L.miny + 0.06 * L.size), num(fs), html_escape(q_text(s, f.q[frame])));
  if (!note.empty())
    o += fmt::format("<text class=\"note\" data-range=\"\" x=\"{}\" y=\"{}\" font-size=\"{}\">{}</text>\n",
                     num(L.minx - 0.1 * L.size), num(-L.miny + 0.1 * L.size), num(fs), html_escape(note));
  o += "</svg>\n";
  return o;
}

std::string animation_section(const models::Scene& s, const MechanismFrames& f, const std::string& title) {
  check_frames(s, f);
  const auto pts = collect_draw_points(s);
  const auto P = calc_positions(s, pts, f);
  const Layout L = calc_layout(pts, P, f.arrows);
  nlohmann::json J;
  J["t"] = f.t_s;
  J["p"] = P;
  std::vector<std::string> qs;
  for (double q : f.q) qs.push_back(q_text(s, q));
  J["q"] = qs;
  std::vector<std::vector<double>> F(f.t_s.size());
  for (size_t k = 0; k < f.t_s.size(); ++k)
    for (const auto& a : f.arrows) F[k].push_back(a.fx_N[k]), F[k].push_back(a.fy_N[k]);
  J["f"] = F;
  J["scale"] = L.arrow_m_per_N;
  J["gap"] = kLabelGap * L.size;
  std::vector<std::string> names;
  for (const auto& a : f.arrows) names.push_back(a.name);
  J["names"] = names;
  // The JSON holds numbers, the scene's names and rdyn's q labels; '<' is escaped so that no
  // "</script>" can end the block early.
  std::string safe;
  for (char c : J.dump()) safe += c == '<' ? std::string("\\u003c") : std::string(1, c);
  std::string h = "<div class=\"animation\" data-t=\"" + num(f.t_s[0]) + "\" data-frame=\"0\">\n";
  if (!title.empty()) h += "<h3>" + html_escape(title) + "</h3>\n";
  h += "<div class=\"controls\"><button class=\"play\">play</button><input class=\"slider\" type=\"range\" min=\"0\" "
       "max=\"" + std::to_string(f.t_s.size() - 1) + "\" step=\"1\" value=\"0\"><label>speed <select class=\"speed\">"
       "<option>0.1</option><option>0.25</option><option>0.5</option><option selected>1</option><option>2</option>"
       "</select></label><span class=\"time\">t = " + fmt::format("{:.3f}", f.t_s[0]) + " s</span><span class=\"q\">" +
       html_escape(q_text(s, f.q[0])) + "</span></div>\n";
  h += svg_body(s, f, pts, P, L, 0) + "</svg>\n";
  h += "<p class=\"legend\">Arrows: forces at their joints, " +
       fmt::format("{:.3g}", L.arrow_m_per_N > 0 ? 1.0 / L.arrow_m_per_N : 0.0) +
       " N per metre of drawing; dashed purple: traced points' paths; yellow: the independent joint.</p>\n";
  h += "<script class=\"frames\" type=\"application/json\">" + safe + "</script>\n";
  h += R"JS(<script>
"use strict";
// Moves this animation's elements to the positions a frame holds (computed by rdyn; no
// kinematics here). `#t=T` shows the frame nearest T in every animation of the page.
(function (root) {
const F = JSON.parse(root.querySelector("script.frames").textContent);
const N = F.t.length, svg = root.querySelector("svg.mechanism"), ui = c => root.querySelector(".controls ." + c);
let k = 0, playing = false, tnow = F.t[0], last = null;
function nearest(t) {
  if (!(t > F.t[0])) return 0;
  if (t >= F.t[N - 1]) return N - 1;
  let lo = 0, hi = N - 1;
  while (hi - lo > 1) { const m = (lo + hi) >> 1; if (F.t[m] <= t) lo = m; else hi = m; }
  return t - F.t[lo] <= F.t[hi] - t ? lo : hi;
}
function set(e, a, v) { e.setAttribute(a, String(v)); }
function show(i) {
  k = i;
  const P = F.p[i];
  for (const e of svg.querySelectorAll("[data-i]")) {
    const j = +e.dataset.i, x = P[2 * j], y = P[2 * j + 1];
    if (e.hasAttribute("data-arrow")) {
      const a = +e.dataset.arrow, fx = F.f[i][2 * a], fy = F.f[i][2 * a + 1];
      const x2 = x + F.scale * fx, y2 = y + F.scale * fy;
      set(e, "x1", x); set(e, "y1", -y); set(e, "x2", x2); set(e, "y2", -y2);
      set(e, "data-fx", fx); set(e, "data-fy", fy);
      const l = svg.querySelector('[data-arrow-label="' + a + '"]'), fn = Math.hypot(fx, fy);
      set(l, "x", x2 + (fn > 0 ? F.gap * fx / fn : 0)); set(l, "y", -(y2 + (fn > 0 ? F.gap * fy / fn : 0)));
      set(l, "text-anchor", fx < 0 ? "end" : "start"); set(l, "dominant-baseline", fy < 0 ? "hanging" : "auto");
      l.textContent = F.names[a] + " " + Math.hypot(fx, fy).toFixed(1) + " N";
      continue;
    }
    set(e, "data-x", x); set(e, "data-y", y);
    if (e.tagName === "circle") { set(e, "cx", x); set(e, "cy", -y); }
    else if (e.tagName === "path") {
      const d = e.getAttribute("d"); set(e, "d", "M" + x + "," + (-y) + d.slice(d.indexOf(" ")));
    }
  }
  for (const e of svg.querySelectorAll("[data-is]"))
    set(e, "points", e.dataset.is.split(" ").map(s => { const j = +s; return P[2 * j] + "," + (-P[2 * j + 1]); }).join(" "));
  for (const e of svg.querySelectorAll("[data-i0]")) {
    const a = +e.dataset.i0, b = +e.dataset.i1;
    set(e, "x1", P[2 * a]); set(e, "y1", -P[2 * a + 1]); set(e, "x2", P[2 * b]); set(e, "y2", -P[2 * b + 1]);
  }
  for (const e of [root, svg]) { e.dataset.t = String(F.t[i]); e.dataset.frame = String(i); }
  if (root.parentElement === document.body && document.querySelectorAll("div.animation").length === 1) {
    document.body.dataset.t = String(F.t[i]); document.body.dataset.frame = String(i);
  }
  ui("slider").value = String(i);
  ui("time").textContent = "t = " + F.t[i].toFixed(3) + " s";
  ui("q").textContent = F.q[i];
}
function fromHash() {
  const m = /^#t=(.+)$/.exec(location.hash);
  if (!m) return false;
  const t = parseFloat(m[1]);
  if (!Number.isFinite(t)) return false;
  playing = false; ui("play").textContent = "play";
  tnow = F.t[nearest(t)]; show(nearest(t));
  return true;
}
function tick(ms) {
  if (!playing) return;
  if (last !== null) {
    tnow += (ms - last) / 1000 * parseFloat(ui("speed").value);
    if (tnow > F.t[N - 1]) tnow = F.t[0];
  }
  last = ms; show(nearest(tnow));
  requestAnimationFrame(tick);
}
ui("play").addEventListener("click", () => {
  playing = !playing; last = null;
  ui("play").textContent = playing ? "pause" : "play";
  if (playing) requestAnimationFrame(tick);
});
ui("slider").addEventListener("input", e => { playing = false; tnow = F.t[+e.target.value]; show(+e.target.value); });
window.addEventListener("hashchange", fromHash);
if (!fromHash()) show(0);
})(document.currentScript.parentElement);
</script>
</div>
)JS";
  return h;
}

std::string animation_css() {
  return "svg.mechanism{width:100%;max-height:80vh;background:#fff;border:1px solid #ccc}"
         ".animation .controls{margin:.5em 0}.animation .controls>*{margin-right:.8em}"
         ".animation .slider{width:40%}";
}

std::string animation_html(const models::Scene& s, const MechanismFrames& f, const std::string& title) {
  check_frames(s, f);
  return "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>" + html_escape(title) +
         "</title>\n<style>body{font-family:sans-serif;margin:1em}" + animation_css() + "</style></head>\n<body data-t=\"" +
         num(f.t_s[0]) + "\" data-frame=\"0\">\n<h1>" + html_escape(title) + "</h1>\n" + animation_section(s, f, "") +
         "</body></html>\n";
}

}  // namespace rdyn::validate
