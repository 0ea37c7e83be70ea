#include "models/scene_yaml.hpp"

#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>

#include "models/bicycle_leg.hpp"

namespace rdyn::models {

namespace {

constexpr double kPi = 3.14159265358979323846;

size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diag = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

std::vector<std::string> split_key_path(const std::string& path);

// v / len, or v itself when it is already a unit vector to rounding (|len − 1| ≤ 4 ulp):
// dividing a normalised vector by its rounded length can move it by an ulp, and a scene
// written by scene_to_yaml must read back bit for bit.
Vec2 unit_vector(const Vec2& v, double len) {
  if (std::abs(len - 1.0) <= 4 * std::numeric_limits<double>::epsilon()) return v;
  return {v.x / len, v.y / len};
}
bool parse_index(const std::string& text, size_t size, size_t& index);

int line_of(const YAML::Node& n) {
  const auto m = n.Mark();
  return m.is_null() ? 0 : m.line + 1;
}

// Limits on the text and its tree, checked before anything reads a value. Scenes are a few
// kilobytes and a few hundred nodes; these bounds are orders of magnitude above that and
// keep any input's memory and time small.
constexpr size_t kMaxSceneBytes = 1 << 20;
// yaml-cpp recurses once per nesting level while parsing (it stops itself at 2000 levels,
// DeepRecursion) and so do the tree walks here: 64 is far more than a scene needs.
constexpr int kMaxDepth = 64;
// Aliases share nodes, so `&a [*b, *b, ...]` chains ("billion laughs") make a small text
// whose tree is exponentially large when walked; an alias to its own ancestor makes a cycle.
// Every walk over the tree is bounded by this many node visits and by kMaxDepth.
constexpr size_t kMaxTreeNodes = 200000;
constexpr size_t kMaxOverrideKeyLength = 1024;

// Walks the tree once: keys are unique scalars, every mapping and list has at most
// limits::kMaxItems entries, every scalar at most limits::kMaxTextLength characters, the
// nesting at most kMaxDepth and the walk (aliases expanded) at most kMaxTreeNodes visits.
void check_yaml_tree(const YAML::Node& node, const std::string& file, const std::string& path,
                     int depth, size_t& visits) {
  auto fail = [&](const YAML::Node& at, const std::string& field, const std::string& msg) {
    // A path through a cycle is as long as the depth limit allows: keep the message readable.
    throw SceneError(file, line_of(at), field.size() > 100 ? field.substr(0, 100) + "…" : field,
                     msg);
  };
  if (++visits > kMaxTreeNodes)
    fail(node, path,
         fmt::format(
             "the YAML tree has more than {} nodes (aliases expanded); a scene needs far fewer",
             kMaxTreeNodes));
  if (depth > kMaxDepth)
    fail(node, path,
         fmt::format("nested more than {} levels deep (or an alias refers to its own ancestor)",
                     kMaxDepth));
  auto child = [&](const std::string& key) { return path.empty() ? key : path + "." + key; };
  if (node.IsScalar()) {
    if (node.Scalar().size() > limits::kMaxTextLength)
      fail(node, path,
           fmt::format("a value of {} characters; at most {}", node.Scalar().size(),
                       limits::kMaxTextLength));
  } else if (node.IsSequence()) {
    if (node.size() > limits::kMaxItems)
      fail(node, path,
           fmt::format("a list of {} items; at most {}", node.size(), limits::kMaxItems));
    for (size_t i = 0; i < node.size(); ++i)
      check_yaml_tree(node[i], file, path + fmt::format("[{}]", i), depth + 1, visits);
  } else if (node.IsMap()) {
    if (node.size() > limits::kMaxItems)
      fail(node, path,
           fmt::format("a mapping of {} keys; at most {}", node.size(), limits::kMaxItems));
    std::map<std::string, int> first_line;  // key → line of its first occurrence
    for (const auto& kv : node) {
      if (!kv.first.IsScalar())
        fail(kv.first, path, "a key must be plain text, not a list or mapping");
      const std::string& key = kv.first.Scalar();
      const std::string shown = key.size() > 64 ? key.substr(0, 64) + "…" : key;
      // yaml-cpp keeps both entries of a repeated key and reads the first: refuse instead.
      const auto [it, inserted] = first_line.emplace(key, line_of(kv.first));
      if (!inserted)
        fail(kv.first, child(shown),
             fmt::format("duplicate key '{}' (first given at line {})", shown, it->second));
      check_yaml_tree(kv.second, file, child(shown), depth + 1, visits);
    }
  }
}

void check_yaml_tree(const YAML::Node& root, const std::string& file) {
  size_t visits = 0;
  check_yaml_tree(root, file, "", 0, visits);
}

// Line of the `---` (or `...`) that ends the first document, the last such line before the
// second document's first node (its mark: the node, not the marker); that line itself when
// none is found.
int calc_document_marker_line(const std::string& text, int second_line) {
  int line = 1, marker = 0;
  for (size_t at = 0; at < text.size() && (second_line <= 0 || line < second_line); ++line) {
    if (text.compare(at, 3, "---") == 0 || text.compare(at, 3, "...") == 0) marker = line;
    const auto nl = text.find('\n', at);
    if (nl == std::string::npos) break;
    at = nl + 1;
  }
  return marker > 0 ? marker : second_line;
}

// Parses scene text with the limits above (size, flow nesting, NUL bytes before parsing; the
// tree after). Throws SceneError.
YAML::Node load_checked_yaml(const std::string& text, const std::string& file) {
  // Refuse anything huge before the YAML parser sees it.
  if (text.size() > kMaxSceneBytes)
    throw SceneError(
        file, 0, "",
        fmt::format("too large for a scene ({} bytes, at most {})", text.size(), kMaxSceneBytes));
  {  // flow nesting, counted conservatively (brackets inside quotes count too)
    int depth = 0, max_depth = 0;
    for (char c : text) {
      if (c == '[' || c == '{')
        max_depth = std::max(max_depth, ++depth);
      else if ((c == ']' || c == '}') && depth > 0)
        --depth;
    }
    if (max_depth > kMaxDepth)
      throw SceneError(
          file, 0, "",
          fmt::format("nested too deeply for a scene (more than {} levels of [ or {{)", kMaxDepth));
  }
  if (text.find('\0') != std::string::npos)
    throw SceneError(file, 0, "", "not a text file (contains NUL bytes)");
  YAML::Node root;
  try {
    // All documents: YAML::Load reads the first and silently drops the rest, so a scene
    // pasted after `---` would be ignored (issue #23).
    const std::vector<YAML::Node> docs = YAML::LoadAll(text);
    if (docs.size() > 1) throw SceneError(file, calc_document_marker_line(text, line_of(docs[1])), "",
                                          "a second YAML document (after '---'); a scene file holds one "
                                          "scene: remove the marker and what follows, or merge the two");
    if (!docs.empty()) root = docs.front();
  } catch (const YAML::Exception& e) {  // ParserException, DeepRecursion (block nesting)
    throw SceneError(file, e.mark.is_null() ? 0 : e.mark.line + 1, "", "malformed YAML: " + e.msg);
  }
  if (!root || root.IsNull()) throw SceneError(file, 0, "", "the scene file is empty");
  if (!root.IsMap())
    throw SceneError(file, line_of(root), "", "a scene must be a YAML mapping of keys");
  check_yaml_tree(root, file);
  return root;
}

// The node a field path names ("bodies[2].mass_kg", "loads.brake.coefficient",
// "gravity.g_m_s2[1]": map keys, list items by index or by name), or the deepest ancestor
// found when the field is not in the tree (a value derived from it, or generated).
YAML::Node locate_field(const YAML::Node& root, const std::string& field) {
  std::vector<std::string> parts;  // "a[2].b" → a, 2, b
  for (const std::string& dotted : split_key_path(field)) {
    const auto open = dotted.find('[');
    parts.push_back(dotted.substr(0, open));
    for (auto i = open; i != std::string::npos; i = dotted.find('[', i + 1))
      parts.push_back(dotted.substr(i + 1, dotted.find(']', i) - i - 1));
  }
  YAML::Node cur;
  cur.reset(root);
  YAML::Node found;  // null: nothing matched
  for (const auto& key : parts) {
    YAML::Node next;
    bool ok = false;
    if (cur.IsMap() && cur[key]) {
      next.reset(cur[key]);
      ok = true;
    } else if (cur.IsSequence()) {
      size_t idx = 0;
      if (parse_index(key, cur.size(), idx)) {
        next.reset(cur[idx]);
        ok = true;
      }
      for (size_t k = 0; k < cur.size() && !ok; ++k)
        if (cur[k].IsMap() && cur[k]["name"] && cur[k]["name"].IsScalar() &&
            cur[k]["name"].Scalar() == key) {
          next.reset(cur[k]);
          ok = true;
        }
    }
    if (!ok) break;
    cur.reset(next);
    found.reset(cur);
  }
  return found;
}

// What a reading needs besides the YAML: the file for messages, and the nodes that `--set`
// overrides created or replaced, so that an error in one of them names the override.
struct Context {
  std::string file;
  std::vector<std::pair<YAML::Node, std::string>> set_by_override;  // node, override key path

  const std::string* override_of(const YAML::Node& n) const {
    for (const auto& [node, path] : set_by_override)
      if (n.IsDefined() && node.is(n)) return &path;
    return nullptr;
  }
  [[noreturn]] void fail(const YAML::Node& n, const std::string& field,
                         const std::string& msg) const {
    if (const std::string* o = override_of(n))
      throw SceneError(file, 0, "--set " + *o, field + ": " + msg);
    throw SceneError(file, line_of(n), field, msg);
  }
};

// Records where `key` of the scene was given: the node's line, or the --set override that
// set it (Scene::key_overrides), so that refusals found after loading name the right one.
void note_key(Scene& s, const Context& ctx, const std::string& key, const YAML::Node& n) {
  if (const std::string* o = ctx.override_of(n)) {
    s.key_lines.erase(key);
    s.key_overrides[key] = *o;
  } else {
    s.key_lines[key] = line_of(n);
  }
}

// A YAML mapping whose keys are checked against the allowed set; typed getters throw
// SceneError with file, line and dotted field path.
class Fields {
 public:
  Fields(const YAML::Node& node, std::string path, const Context& ctx,
         std::vector<std::string> allowed)
      : node_(node), path_(std::move(path)), ctx_(ctx), allowed_(std::move(allowed)) {
    if (!node_.IsMap()) fail_at(node_, path_, "expected a mapping of keys to values");
    for (const auto& kv : node_) {
      if (!kv.first.IsScalar()) fail_at(kv.first, path_, "a key must be a plain name, not a list or mapping");
      const std::string key = kv.first.as<std::string>();
      if (std::find(allowed_.begin(), allowed_.end(), key) != allowed_.end()) continue;
      std::string best;
      size_t best_d = 4;  // suggest only close matches
      for (const auto& a : allowed_) {
        const size_t d = edit_distance(key, a);
        if (d < best_d) best_d = d, best = a;
      }
      fail_at(ctx_.override_of(kv.second) ? kv.second : kv.first, join(key),
              best.empty() ? "unknown key" : fmt::format("unknown key (did you mean '{}'?)", best));
    }
  }

  bool has(const std::string& k) const { return static_cast<bool>(node_[k]); }
  YAML::Node raw(const std::string& k) const { return node_[k]; }
  std::string join(const std::string& k) const { return path_.empty() ? k : path_ + "." + k; }
  int line() const { return line_of(node_); }

  [[noreturn]] void fail_at(const YAML::Node& n, const std::string& field,
                            const std::string& msg) const {
    ctx_.fail(n, field, msg);
  }
  [[noreturn]] void fail(const std::string& key, const std::string& msg) const {
    fail_at(has(key) ? node_[key] : node_, join(key), msg);
  }

  YAML::Node required(const std::string& k) const {
    if (!has(k)) fail_at(node_, join(k), "missing required field");
    return node_[k];
  }

  double num(const std::string& k) const { return to_num(required(k), join(k)); }
  double num_or(const std::string& k, double def) const { return has(k) ? num(k) : def; }
  // A number given in a unit other than the scene's (degrees, hertz): checked in that unit,
  // so the message quotes what the user typed.
  double num_abs_max(const std::string& k, double def, double max, const char* unit) const {
    const double v = num_or(k, def);
    if (std::abs(v) > max)
      fail(k, fmt::format("must be finite with |value| ≤ {:g} {} (got {:g})", max, unit, v));
    return v;
  }
  double num_in(const std::string& k, double lo, double hi, const char* unit) const {
    const double v = num(k);
    if (v < lo || v > hi)
      fail(k, fmt::format("must be in [{:g}, {:g}] {} (got {:g})", lo, hi, unit, v));
    return v;
  }
  std::string str(const std::string& k) const {
    const YAML::Node n = required(k);
    if (!n.IsScalar()) fail_at(n, join(k), "expected a text value");
    return n.as<std::string>();
  }
  std::string str_or(const std::string& k, const std::string& def) const {
    return has(k) ? str(k) : def;
  }
  // A name (see is_valid_name): checked here, where the line is known.
  std::string name(const std::string& k) const {
    const std::string v = str(k);
    if (!is_valid_name(v)) fail(k, invalid_name_message(v));
    return v;
  }
  bool flag_or(const std::string& k, bool def) const {
    if (!has(k)) return def;
    const YAML::Node n = node_[k];
    bool v = false;
    if (!n.IsScalar() || !YAML::convert<bool>::decode(n, v))
      fail_at(n, join(k), "expected true or false");
    return v;
  }
  Vec2 vec2(const std::string& k) const { return to_vec2(required(k), join(k)); }

  double to_num(const YAML::Node& n, const std::string& field) const {
    if (!n.IsScalar()) fail_at(n, field, "expected a number");
    double v = 0.0;
    const std::string text = n.Scalar();
    if (!YAML::convert<double>::decode(n, v) || text.empty())
      fail_at(n, field, fmt::format("expected a number, got '{}'", text.substr(0, 40)));
    if (!std::isfinite(v))
      fail_at(n, field, fmt::format("must be finite, got '{}'", text.substr(0, 40)));
    // A nonzero literal below the smallest normal double (2.2e-308) would be read as 0 or a
    // denormal that has lost its digits: refuse it instead of silently changing the value.
    if (std::abs(v) < std::numeric_limits<double>::min()) {
      const std::string mantissa = text.substr(0, text.find_first_of("eE"));
      if (mantissa.find_first_of("123456789") != std::string::npos)
        fail_at(n, field,
                fmt::format("'{}' is too small to represent (below 2.2e-308 in magnitude); write 0 if zero is meant",
                            text.substr(0, 40)));
    }
    return v;
  }
  Vec2 to_vec2(const YAML::Node& n, const std::string& field) const {
    if (!n.IsSequence() || n.size() != 2) fail_at(n, field, "expected a pair [x, y]");
    return {to_num(n[0], field + "[0]"), to_num(n[1], field + "[1]")};
  }

  const Context& ctx() const { return ctx_; }
  const std::string& file() const { return ctx_.file; }

 private:
  YAML::Node node_;
  std::string path_;
  const Context& ctx_;
  std::vector<std::string> allowed_;
};

// Reads a list of mappings; each item must have a unique `name` unless `named` is false.
template <typename F>
void for_each_item(const Fields& parent, const std::string& key, F&& f) {
  if (!parent.has(key)) return;
  const YAML::Node seq = parent.raw(key);
  if (!seq.IsSequence()) parent.fail(key, "expected a list");
  for (size_t i = 0; i < seq.size(); ++i) f(seq[i], parent.join(key) + fmt::format("[{}]", i));
}

// Point on a body: [x, y] or the name of one of the body's (or ground's) points.
Vec2 read_point(const Fields& f, const std::string& key, const std::string& body, const Scene& s) {
  const YAML::Node n = f.required(key);
  if (n.IsSequence()) return f.to_vec2(n, f.join(key));
  if (!n.IsScalar()) f.fail(key, "expected [x, y] or the name of a point");
  const std::string name = n.as<std::string>();
  if (body == kGround) {
    auto it = s.ground_points.find(name);
    if (it != s.ground_points.end()) return it->second;
  } else if (const Body* b = s.find_body(body)) {
    auto it = b->points.find(name);
    if (it != b->points.end()) return it->second;
  }
  f.fail(key, fmt::format("body '{}' has no point named '{}'", body, name));
}

// Splits a dotted key path; every part non-empty ("a..b", ".a" and "a." are malformed).
std::vector<std::string> split_key_path(const std::string& path) {
  std::vector<std::string> parts(1);
  for (char c : path) {
    if (c == '.')
      parts.emplace_back();
    else
      parts.back() += c;
  }
  return parts;
}

// A list index: digits only, below `size`.
bool parse_index(const std::string& text, size_t size, size_t& index) {
  if (text.empty() || text.size() > 9 ||
      !std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; }))
    return false;
  index = std::stoul(text);
  return index < size;
}

// Applies one override to the YAML tree; records the nodes it created or set in `touched`
// (so that a later error in them names the override).
void apply_override(YAML::Node root, const Override& o, const std::string& file,
                    std::vector<std::pair<YAML::Node, std::string>>* touched = nullptr) {
  const std::vector<std::string> parts = split_key_path(o.path);
  auto fail = [&](const std::string& msg) { throw SceneError(file, 0, "--set " + o.path, msg); };
  if (std::any_of(parts.begin(), parts.end(), [](auto& p) { return p.empty(); }))
    fail("malformed key path (empty part)");
  YAML::Node cur;
  cur.reset(root);
  for (size_t i = 0; i + 1 < parts.size(); ++i) {
    const std::string& key = parts[i];
    YAML::Node next;
    if (cur.IsSequence()) {
      size_t idx = 0;
      bool found = false;
      if (parse_index(key, cur.size(), idx)) {
        next.reset(cur[idx]);
        found = true;
      } else {
        for (size_t k = 0; k < cur.size() && !found; ++k)
          if (cur[k].IsMap() && cur[k]["name"] && cur[k]["name"].IsScalar() &&
              cur[k]["name"].Scalar() == key) {
            next.reset(cur[k]);
            found = true;
          }
      }
      if (!found)
        fail(fmt::format("no list item '{}' (an index below {} or an item's name)", key,
                         cur.size()));
    } else if (cur.IsMap()) {
      if (!cur[key]) {
        cur[key] = YAML::Node(YAML::NodeType::Map);  // allows setting a generator default
        if (touched) touched->push_back({cur[key], o.path});
      }
      next.reset(cur[key]);
    } else {
      fail(fmt::format("'{}' is not a mapping or list", key));
    }
    cur.reset(next);
  }
  const std::string& last = parts.back();
  if (cur.IsSequence()) {  // e.g. one coordinate of a point: bodies.rocker.points.C.0=0.2
    size_t idx = 0;
    if (!parse_index(last, cur.size(), idx) || !cur[idx].IsScalar())
      fail(fmt::format("no scalar list item '{}' (an index below {})", last, cur.size()));
    cur[idx] = o.value;
    if (touched) touched->push_back({cur[idx], o.path});
    return;
  }
  if (!cur.IsMap()) fail("the parent of the last key is not a mapping");
  if (cur[last] && !cur[last].IsScalar()) fail("only scalar values can be set");
  cur[last] = o.value;
  if (touched) touched->push_back({cur[last], o.path});
}

ResistanceLaw read_law(const Fields& f, const std::string& key) {
  const std::string v = f.str(key);
  if (v == "constant") return ResistanceLaw::Constant;
  if (v == "viscous") return ResistanceLaw::Viscous;
  if (v == "quadratic") return ResistanceLaw::Quadratic;
  f.fail(key, "expected constant, viscous or quadratic");
}

void read_bicycle_leg(const Fields& f, Scene& s) {
  BicycleLegParams p;
  if (f.has("subject")) {
    Fields sub(f.raw("subject"), f.join("subject"), f.ctx(), {"height_m", "mass_kg", "sex"});
    p.height_m = sub.num_or("height_m", p.height_m);
    p.mass_kg = sub.num_or("mass_kg", p.mass_kg);
    p.sex = sub.str_or("sex", p.sex);
  }
  const double legs = f.num_or("legs", p.legs);
  if (legs != 1.0 && legs != 2.0) f.fail("legs", "must be 1 or 2");
  p.legs = static_cast<int>(legs);
  p.crank_length_m = f.num_or("crank_length_m", p.crank_length_m);
  p.crank_mass_kg = f.num_or("crank_mass_kg", p.crank_mass_kg);
  p.seat_tube_angle_deg = f.num_or("seat_tube_angle_deg", p.seat_tube_angle_deg);
  p.knee_flexion_at_extension_deg =
      f.num_or("knee_flexion_at_extension_deg", p.knee_flexion_at_extension_deg);
  p.ankle_angle_deg = f.num_or("ankle_angle_deg", p.ankle_angle_deg);
  p.pedal_stack_m = f.num_or("pedal_stack_m", p.pedal_stack_m);
  p.hip_torque_Nm = f.num_or("hip_torque_Nm", p.hip_torque_Nm);
  if (f.has("flywheel")) {
    Fields fw(f.raw("flywheel"), f.join("flywheel"), f.ctx(),
              {"gear_ratio", "inertia_kgm2", "mass_kg", "bike_mass_kg", "wheel_radius_m",
               "wheel_inertia_kgm2"});
    p.gear_ratio = fw.num_or("gear_ratio", p.gear_ratio);
    if (fw.has("inertia_kgm2")) p.flywheel_inertia_kgm2 = fw.num("inertia_kgm2");
    p.flywheel_mass_kg = fw.num_or("mass_kg", p.flywheel_mass_kg);
    p.bike_mass_kg = fw.num_or("bike_mass_kg", p.bike_mass_kg);
    p.wheel_radius_m = fw.num_or("wheel_radius_m", p.wheel_radius_m);
    p.wheel_inertia_kgm2 = fw.num_or("wheel_inertia_kgm2", p.wheel_inertia_kgm2);
  }
  if (f.has("resistance")) {
    Fields r(f.raw("resistance"), f.join("resistance"), f.ctx(), {"law", "power_W", "cadence_Hz"});
    if (r.has("law")) p.resistance_law = read_law(r, "law");
    p.resistance_power_W = r.num_or("power_W", p.resistance_power_W);
    p.resistance_cadence_Hz = r.num_or("cadence_Hz", p.resistance_cadence_Hz);
  }
  make_bicycle_leg(p, s);
}

void read_mechanism(const Fields& top, Scene& s) {
  if (top.has("ground_points")) {
    const YAML::Node gp = top.raw("ground_points");
    if (!gp.IsMap()) top.fail("ground_points", "expected a mapping name: [x, y]");
    for (const auto& kv : gp) {
      if (!kv.first.IsScalar()) top.fail("ground_points", "a point's name must be plain text");
      s.ground_points[kv.first.as<std::string>()] =
          top.to_vec2(kv.second, "ground_points." + kv.first.as<std::string>());
    }
  }
  for_each_item(top, "bodies", [&](const YAML::Node& n, const std::string& path) {
    Fields f(n, path, top.ctx(), {"name", "mass_kg", "com_m", "inertia_kgm2", "points"});
    Body b;
    b.name = f.name("name");
    b.mass_kg = f.num("mass_kg");  // ranges: check_scene
    b.com_m = f.has("com_m") ? f.vec2("com_m") : Vec2{};
    b.inertia_kgm2 = f.num("inertia_kgm2");
    if (s.find_body(b.name) || b.name == kGround)
      f.fail("name", "duplicate body name '" + b.name + "'");
    if (f.has("points")) {
      const YAML::Node pts = f.raw("points");
      if (!pts.IsMap()) f.fail("points", "expected a mapping name: [x, y]");
      for (const auto& kv : pts) {
        if (!kv.first.IsScalar()) f.fail("points", "a point's name must be plain text");
        b.points[kv.first.as<std::string>()] =
            f.to_vec2(kv.second, f.join("points." + kv.first.as<std::string>()));
      }
    }
    s.bodies.push_back(b);
  });
  for_each_item(top, "joints", [&](const YAML::Node& n, const std::string& path) {
    Fields f(n, path, top.ctx(),
             {"name", "type", "parent", "child", "parent_point", "child_point", "axis",
              "offset_deg", "guess_deg", "guess_m", "offset_rad", "guess_rad"});
    Joint j;
    j.name = f.name("name");
    const std::string type = f.str("type");
    if (type == "revolute")
      j.type = JointType::Revolute;
    else if (type == "prismatic")
      j.type = JointType::Prismatic;
    else
      f.fail("type", "expected revolute or prismatic");
    j.parent = f.str("parent");
    j.child = f.str("child");
    if (j.parent != kGround && !s.find_body(j.parent))
      f.fail("parent", "unknown body '" + j.parent + "'");
    if (!s.find_body(j.child)) f.fail("child", "unknown body '" + j.child + "'");
    j.parent_point = f.has("parent_point") ? read_point(f, "parent_point", j.parent, s) : Vec2{};
    j.child_point = f.has("child_point") ? read_point(f, "child_point", j.child, s) : Vec2{};
    if (j.type == JointType::Prismatic) {
      j.axis = f.has("axis") ? f.vec2("axis") : Vec2{1, 0};
      const double len = std::hypot(j.axis.x, j.axis.y);
      if (len < 1e-12) f.fail("axis", "must be a non-zero vector");
      j.axis = unit_vector(j.axis, len);
      if (f.has("offset_deg") || f.has("guess_deg") || f.has("offset_rad") || f.has("guess_rad"))
        f.fail("type", "prismatic joints take guess_m, not angles");
      j.guess = f.num_or("guess_m", 0.0);
    } else {
      if (f.has("axis") || f.has("guess_m"))
        f.fail("type", "revolute joints take guess_deg and no axis");
      // Degrees, or radians (what scene_to_yaml writes: x·π/180 need not round back to the same double).
      const double max_deg = limits::kMaxAngle_rad * 180.0 / kPi;
      auto angle = [&](const std::string& name) {
        if (f.has(name + "_deg") && f.has(name + "_rad"))
          f.fail(name + "_rad", fmt::format("give {0}_deg or {0}_rad, not both", name));
        if (f.has(name + "_rad")) return f.num_abs_max(name + "_rad", 0.0, limits::kMaxAngle_rad, "rad");
        return f.num_abs_max(name + "_deg", 0.0, max_deg, "degrees") * kPi / 180.0;
      };
      j.offset_rad = angle("offset");
      j.guess = angle("guess");
    }
    s.joints.push_back(j);
  });
  for_each_item(top, "loops", [&](const YAML::Node& n, const std::string& path) {
    Fields f(n, path, top.ctx(), {"name", "body_a", "point_a", "body_b", "point_b", "branch"});
    Loop l;
    l.name = f.name("name");
    l.body_a = f.str("body_a");
    l.body_b = f.str("body_b");
    l.point_a = read_point(f, "point_a", l.body_a, s);
    l.point_b = read_point(f, "point_b", l.body_b, s);
    if (f.has("branch")) {  // {joint, sign: positive|negative} (or +1 / -1)
      Fields b(f.raw("branch"), f.join("branch"), top.ctx(), {"joint", "sign"});
      note_key(s, top.ctx(), "loops." + l.name + ".branch", f.raw("branch"));
      BranchSign br{b.str("joint"), +1};
      if (!s.find_joint(br.joint)) b.fail("joint", "unknown joint '" + br.joint + "'");
      if (br.joint == top.str_or("independent", ""))
        b.fail("joint", "the independent coordinate is set by `initial`, not by assembly: name another joint");
      // Only a joint the loop closes over can tell its branches apart: the joints on exactly one
      // of the two tree paths from body_a and body_b down to ground.
      auto path_to_ground = [&](std::string body) {
        std::vector<std::string> joints;
        for (size_t guard = 0; guard <= s.joints.size() && body != "ground"; ++guard) {
          const auto it = std::find_if(s.joints.begin(), s.joints.end(), [&](const Joint& jt) { return jt.child == body; });
          if (it == s.joints.end()) break;
          joints.push_back(it->name);
          body = it->parent;
        }
        return joints;
      };
      const auto pa = path_to_ground(l.body_a), pb = path_to_ground(l.body_b);
      std::vector<std::string> on_loop;
      for (const auto& j : pa)
        if (std::find(pb.begin(), pb.end(), j) == pb.end()) on_loop.push_back(j);
      for (const auto& j : pb)
        if (std::find(pa.begin(), pa.end(), j) == pa.end()) on_loop.push_back(j);
      if (std::find(on_loop.begin(), on_loop.end(), br.joint) == on_loop.end()) {
        std::string list;
        for (const auto& j : on_loop) list += (list.empty() ? "" : ", ") + j;
        b.fail("joint", fmt::format("'{}' is not a joint of loop '{}' (its joints: {}): only a joint the loop closes "
                                    "over can pick its branch",
                                    br.joint, l.name, list));
      }
      const std::string sign = b.str("sign");
      if (sign == "positive" || sign == "+1" || sign == "1") br.sign = +1;
      else if (sign == "negative" || sign == "-1") br.sign = -1;
      else b.fail("sign", "expected positive or negative (or +1, -1)");
      l.branch = br;
    }
    s.loops.push_back(l);
  });
  for_each_item(top, "gears", [&](const YAML::Node& n, const std::string& path) {
    Fields f(n, path, top.ctx(), {"name", "driver", "driven", "ratio"});
    s.gears.push_back({f.name("name"), f.str("driver"), f.str("driven"), f.num("ratio")});
  });
  s.independent = top.str("independent");
}

// independent_range: [min, max] in rad or m (as initial.q), or independent_range_deg for a
// revolute; values checked by check_scene.
void read_independent_range(const Fields& top, Scene& s) {
  const bool deg = top.has("independent_range_deg");
  if (!deg && !top.has("independent_range")) return;
  if (deg && top.has("independent_range"))
    top.fail("independent_range", "give independent_range or independent_range_deg, not both");
  const std::string key = deg ? "independent_range_deg" : "independent_range";
  const Joint* j = s.find_joint(s.independent);
  if (deg && j && j->type == JointType::Prismatic)
    top.fail(key, "a prismatic independent coordinate takes independent_range in metres, not degrees");
  const Vec2 v = top.vec2(key);
  const double k = deg ? kPi / 180.0 : 1.0;
  if (deg) {
    const double max_deg = limits::kMaxAngle_rad * 180.0 / kPi;
    if (std::abs(v.x) > max_deg || std::abs(v.y) > max_deg)
      top.fail(key, fmt::format("must be finite with |value| ≤ {:g} degrees", max_deg));
  }
  if (!(v.x < v.y)) top.fail(key, fmt::format("needs min < max (got [{:g}, {:g}])", v.x, v.y));  // here: the line
  s.independent_range = IndependentRange{v.x * k, v.y * k};
}

// A joint torque's profile: {of: joint, fourier: {a0, a: [...], b: [...]}} or
// {of: joint, table_deg: [[θ_deg, τ], ...]} (models/load_profile.hpp). Counts, finiteness and
// the order of the table's angles are checked here, where the line of each row is known;
// the joint and the load's range by check_scene.
LoadProfile read_profile(const Fields& parent, const std::string& key) {
  Fields p(parent.raw(key), parent.join(key), parent.ctx(), {"of", "fourier", "table_deg", "table_rad"});
  if (int(p.has("fourier")) + int(p.has("table_deg")) + int(p.has("table_rad")) != 1)
    p.fail("fourier",
           "give fourier: {a0, a, b} or table_deg: [[angle_deg, value], ...] (or table_rad), one of them");
  const std::string of = p.str("of");
  auto list = [&](const Fields& f, const std::string& k, size_t max, const char* what) {
    std::vector<double> v;
    if (!f.has(k)) return v;
    const YAML::Node seq = f.raw(k);
    if (!seq.IsSequence()) f.fail(k, "expected a list of numbers");
    if (seq.size() > max) f.fail(k, fmt::format("{} {}; at most {}", seq.size(), what, max));
    for (size_t i = 0; i < seq.size(); ++i) v.push_back(f.to_num(seq[i], f.join(k) + fmt::format("[{}]", i)));
    return v;
  };
  if (p.has("fourier")) {
    Fields f(p.raw("fourier"), p.join("fourier"), parent.ctx(), {"a0", "a", "b"});
    LoadProfile out;
    out.of = of;
    out.a0 = f.num_or("a0", 0.0);
    out.a = list(f, "a", limits::kMaxProfileHarmonics, "cosine coefficients");
    out.b = list(f, "b", limits::kMaxProfileHarmonics, "sine coefficients");
    return out;
  }
  // table_rad (what scene_to_yaml writes): the same rows in radians, checked in degrees.
  const bool rad = p.has("table_rad");
  const std::string table_key = rad ? "table_rad" : "table_deg";
  const YAML::Node rows = p.raw(table_key);
  const std::string field = p.join(table_key);
  if (!rows.IsSequence()) p.fail(table_key, "expected a list of [angle, value] rows");
  if (rows.size() < limits::kMinProfileRows || rows.size() > limits::kMaxProfileRows)
    p.fail(table_key, fmt::format("{} rows; a periodic table takes {} to {}", rows.size(),
                                    limits::kMinProfileRows, limits::kMaxProfileRows));
  std::vector<double> theta, value;
  for (size_t i = 0; i < rows.size(); ++i) {
    const std::string fi = field + fmt::format("[{}]", i);
    const Vec2 typed = p.to_vec2(rows[i], fi);
    const Vec2 row{rad ? typed.x * 180.0 / kPi : typed.x, typed.y};  // angle in degrees
    if (std::abs(row.x) > 360.0)
      p.fail_at(rows[i], fi + "[0]", fmt::format("angle {:g}° outside [−360°, 360°]", row.x));
    if (i > 0 && !(row.x - theta.back() * 180 / kPi >= limits::kMinProfileSpacing_deg))
      p.fail_at(rows[i], fi + "[0]",
                fmt::format("angles must increase by at least {:g}° from row to row (got {:g}° after {:g}°)",
                            limits::kMinProfileSpacing_deg, row.x, theta.back() * 180 / kPi));
    if (i > 0 && !(theta.front() * 180 / kPi + 360.0 - row.x >= limits::kMinProfileSpacing_deg))
      p.fail_at(rows[i], fi + "[0]",
                fmt::format("the table covers one turn: angles must stay below the first + 360° (got {:g}° "
                            "after a first angle of {:g}°)",
                            row.x, theta.front() * 180 / kPi));
    theta.push_back(rad ? typed.x : row.x * kPi / 180.0);
    value.push_back(row.y);
  }
  return make_table_profile(of, std::move(theta), std::move(value));
}

// A load's rate gate: active_when: {joint, rate: positive|negative} (the joint: check_scene).
RateGate read_rate_gate(const Fields& f) {
  Fields g(f.raw("active_when"), f.join("active_when"), f.ctx(), {"joint", "rate"});
  const std::string rate = g.str("rate");
  if (rate != "positive" && rate != "negative") g.fail("rate", "expected positive or negative");
  return RateGate{g.str("joint"), rate == "positive" ? +1 : -1};
}

struct PendingDissipation {
  size_t index;
  double power_W, cadence_Hz;
  int line;
};

// A load's value key must carry its joint's unit: a torque on a revolute joint, a force on a
// prismatic one. Both keys fill the same value, so a force_N on a revolute joint was read as
// N·m without a word (issue #23); refused here, where the key's line is known. An unknown
// joint is left to check_scene, which names it.
void check_unit_key(const Fields& f, const Scene& s, const std::string& joint, const std::string& torque_key,
                    const std::string& force_key) {
  const Joint* j = s.find_joint(joint);
  if (!j) return;
  const bool prismatic = j->type == JointType::Prismatic;
  const std::string& wrong = prismatic ? torque_key : force_key;
  if (f.has(wrong))
    f.fail(wrong, fmt::format("joint '{}' is {} ({}): give {} instead of {}", joint,
                              prismatic ? "prismatic" : "revolute",
                              prismatic ? "forces in N, speeds in m/s" : "torques in N·m, speeds in rad/s",
                              prismatic ? force_key : torque_key, wrong));
}

void read_loads(const Fields& top, Scene& s, std::vector<PendingDissipation>& pending) {
  std::set<std::string> names;
  for_each_item(top, "loads", [&](const YAML::Node& n, const std::string& path) {
    if (!n.IsMap() || !n["type"])
      throw SceneError(top.file(), line_of(n), path + ".type", "missing required field");
    if (!n["type"].IsScalar()) top.ctx().fail(n["type"], path + ".type", "expected a load type");
    const std::string type = n["type"].as<std::string>();
    if (n["name"] && (!n["name"].IsScalar() || !is_valid_name(n["name"].Scalar())))
      top.ctx().fail(
          n["name"], path + ".name",
          invalid_name_message(n["name"].IsScalar() ? n["name"].Scalar() : "(not text)"));
    const std::string name = n["name"] ? n["name"].Scalar() : fmt::format("load{}", names.size());
    if (!names.insert(name).second)
      throw SceneError(top.file(), line_of(n), path + ".name",
                       "duplicate load name '" + name + "'");
    s.key_lines["loads." + name] = line_of(n);  // refusals after loading (optimize's design) name the load's line
    if (type == "joint_torque") {
      Fields f(n, path, top.ctx(),
               {"type", "name", "joint", "torque_Nm", "force_N", "active_when", "profile"});
      JointTorque t{name, f.str("joint"), 0.0, std::nullopt, std::nullopt};
      if (f.has("torque_Nm") && f.has("force_N"))
        f.fail("torque_Nm", "give torque_Nm (revolute) or force_N (prismatic), not both");
      check_unit_key(f, s, t.joint, "torque_Nm", "force_N");
      // With a profile the value is an amplitude multiplier, 1 unless given.
      if (f.has("profile")) t.profile = read_profile(f, "profile");
      if (!f.has("profile") && !f.has("torque_Nm") && !f.has("force_N"))
        f.fail("torque_Nm", "give torque_Nm (revolute) or force_N (prismatic)");
      t.value = f.has("torque_Nm") ? f.num("torque_Nm") : f.num_or("force_N", 1.0);
      if (f.has("active_when")) t.active_when = read_rate_gate(f);
      s.joint_torques.push_back(t);
    } else if (type == "resistance") {
      Fields f(n, path, top.ctx(), {"type", "name", "body", "law", "coefficient", "dissipates"});
      Resistance r{name, f.str("body"), read_law(f, "law"), 0.0};
      if (f.has("coefficient") == f.has("dissipates"))
        f.fail("coefficient", "give either coefficient or dissipates: {power_W, cadence_Hz}");
      if (f.has("coefficient")) {
        r.coefficient = f.num("coefficient");
      } else {
        Fields d(f.raw("dissipates"), f.join("dissipates"), top.ctx(), {"power_W", "cadence_Hz"});
        const double power_W = d.num_in("power_W", 0.0, limits::kMaxPower_W, "W");
        const double cadence_Hz = d.num("cadence_Hz");
        if (!(cadence_Hz > 0.0 && cadence_Hz <= limits::kMaxCadence_Hz))
          d.fail("cadence_Hz", fmt::format("must be in (0, {:g}] Hz (got {:g})",
                                           limits::kMaxCadence_Hz, cadence_Hz));
        pending.push_back({s.resistances.size(), power_W, cadence_Hz, d.line()});
      }
      s.resistances.push_back(r);
    } else if (type == "spring") {
      Fields f(n, path, top.ctx(),
               {"type", "name", "body_a", "point_a", "body_b", "point_b", "stiffness_N_per_m",
                "rest_length_m"});
      Spring sp;
      sp.name = name;
      sp.body_a = f.str("body_a");
      sp.body_b = f.str("body_b");
      sp.point_a = read_point(f, "point_a", sp.body_a, s);
      sp.point_b = read_point(f, "point_b", sp.body_b, s);
      note_key(s, top.ctx(), "loads." + sp.name + ".point_b", f.raw("point_b"));  // checked at assembly
      sp.stiffness_N_per_m = f.num("stiffness_N_per_m");
      sp.rest_length_m = f.num("rest_length_m");
      s.springs.push_back(sp);
    } else if (type == "point_force") {
      // A muscle-like tension between two points; force_N is an amplitude with a profile.
      Fields f(n, path, top.ctx(),
               {"type", "name", "body_a", "point_a", "body_b", "point_b", "force_N", "active_when", "profile"});
      PointForce pf;
      pf.name = name;
      pf.body_a = f.str("body_a");
      pf.body_b = f.str("body_b");
      for (const auto& [key, body] : {std::pair{"body_a", pf.body_a}, std::pair{"body_b", pf.body_b}})
        if (body != kGround && !s.find_body(body)) f.fail(key, "unknown body '" + body + "'");
      pf.point_a = read_point(f, "point_a", pf.body_a, s);
      pf.point_b = read_point(f, "point_b", pf.body_b, s);
      note_key(s, top.ctx(), "loads." + pf.name + ".point_b", f.raw("point_b"));  // checked at assembly
      if (f.has("profile")) pf.profile = read_profile(f, "profile");
      if (!f.has("profile") && !f.has("force_N")) f.fail("force_N", "give force_N (the tension, positive pulls the points together)");
      pf.value = f.num_or("force_N", 1.0);
      if (f.has("active_when")) pf.active_when = read_rate_gate(f);
      s.point_forces.push_back(pf);
    } else if (type == "motor") {
      Fields f(n, path, top.ctx(),
               {"type", "name", "joint", "stall_torque_Nm", "stall_force_N", "no_load_speed_rad_s",
                "no_load_speed_m_s"});
      Motor m{name, f.str("joint"), 0.0, 0.0};
      using Keys = std::pair<std::string, std::string>;  // revolute's key, prismatic's key
      for (const auto& [torque_key, force_key] :
           {Keys{"stall_torque_Nm", "stall_force_N"}, Keys{"no_load_speed_rad_s", "no_load_speed_m_s"}}) {
        if (f.has(torque_key) && f.has(force_key))
          f.fail(torque_key, fmt::format("give {} (revolute) or {} (prismatic), not both", torque_key, force_key));
        check_unit_key(f, s, m.joint, torque_key, force_key);
      }
      m.stall_torque = f.has("stall_force_N") ? f.num("stall_force_N") : f.num("stall_torque_Nm");
      m.no_load_speed =
          f.has("no_load_speed_m_s") ? f.num("no_load_speed_m_s") : f.num("no_load_speed_rad_s");
      s.motors.push_back(m);
    } else {
      throw SceneError(
          top.file(), line_of(n["type"]), path + ".type",
          "unknown load type '" + type + "' (joint_torque, resistance, spring, motor, point_force)");
    }
  });
}

// The `optimize` block (rdyn optimize): every name known, every number in range, here where
// the line is known.
void read_optimize(const Fields& f, Scene& s) {
  OptimizeSpec o;
  std::vector<YAML::Node> same_nodes;
  for_each_item(f, "loads", [&](const YAML::Node& n, const std::string& path) {
    Fields l(n, path, f.ctx(), {"load", "same_as", "shift_deg", "shift_rad"});
    OptimizeLoad d;
    d.load = l.name("load");
    // That the load exists is checked when optimizing (validate/analysis/optimize.cpp, resolve_design),
    // at this line: a scene whose drive is switched off (a generator's hip_torque_Nm: 0, "no
    // drive") makes no such torque, and simulate, extract or inspect of it must not be refused
    // for a block only `rdyn optimize` reads (issue #23).
    note_key(s, f.ctx(), fmt::format("optimize.loads[{}].load", o.loads.size()), n["load"]);
    for (const auto& e : o.loads)
      if (e.load == d.load) l.fail("load", "'" + d.load + "' is listed twice");
    if (l.has("same_as")) {
      d.same_as = l.name("same_as");
      if (d.same_as == d.load) l.fail("same_as", "a load cannot take its own shape");
    }
    for (const char* k : {"shift_deg", "shift_rad"})
      if (l.has(k) && !l.has("same_as")) l.fail(k, "a shift needs same_as");
    if (l.has("shift_deg") && l.has("shift_rad")) l.fail("shift_rad", "give shift_deg or shift_rad, not both");
    // shift_rad: how rdyn writes it back (degrees do not reach every radian value exactly).
    d.shift_rad = l.has("shift_rad") ? l.num_abs_max("shift_rad", 0.0, 2 * kPi, "rad")
                                     : l.num_abs_max("shift_deg", 0.0, 360.0, "degrees") * kPi / 180.0;
    o.loads.push_back(d);
    same_nodes.push_back(n);
  });
  if (f.has("loads") && o.loads.empty()) f.fail("loads", "list at least one design load, or leave the key out");
  // Where the design is written: the refusals that need the whole design (calibration scales
  // every joint torque together) come after loading.
  s.key_lines["optimize"] = f.line();
  if (f.has("loads")) note_key(s, f.ctx(), "optimize.loads", f.raw("loads"));
  for (size_t i = 0; i < o.loads.size(); ++i) {
    const auto& d = o.loads[i];
    if (d.same_as.empty()) continue;
    const auto it = std::find_if(o.loads.begin(), o.loads.end(), [&](const OptimizeLoad& e) { return e.load == d.same_as; });
    const std::string path = f.join("loads") + fmt::format("[{}].same_as", i);
    if (it == o.loads.end())
      f.fail_at(same_nodes[i]["same_as"], path, "'" + d.same_as + "' is not a design load listed in optimize.loads");
    if (!it->same_as.empty())
      f.fail_at(same_nodes[i]["same_as"], path,
                "'" + d.same_as + "' takes its shape from '" + it->same_as + "': name that load instead");
  }
  if (f.has("of")) {
    o.of = f.name("of");
    const Joint* j = s.find_joint(o.of);
    if (!j) f.fail("of", "unknown joint '" + o.of + "'");
    if (j->type != JointType::Revolute) f.fail("of", "a profile reads a revolute joint's angle");
  }
  if (f.has("force")) {
    o.force = f.name("force");
    const auto& cf = s.outputs.constraint_forces;
    if (std::none_of(cf.begin(), cf.end(), [&](const ConstraintForceRequest& c) { return c.name == o.force; }))
      f.fail("force", "no requested constraint force named '" + o.force + "' (outputs.constraint_forces)");
  }
  if (f.has("harmonics")) {
    const double h = f.num_in("harmonics", 1, kMaxOptimizeHarmonics, "");
    if (h != std::floor(h)) f.fail("harmonics", fmt::format("must be a whole number (got {:g})", h));
    o.harmonics = static_cast<int>(h);
  }
  if (f.has("max_load")) {
    o.max_load = f.num("max_load");
    if (!(o.max_load > 0 && o.max_load <= limits::kMaxForce))
      f.fail("max_load", fmt::format("must be in (0, {:g}] N·m or N (got {:g})", limits::kMaxForce, o.max_load));
  }
  o.nonnegative = f.flag_or("nonnegative", true);
  o.objective = f.str_or("objective", "peak");
  if (o.objective != "peak" && o.objective != "pnorm") f.fail("objective", "expected peak or pnorm");
  if (f.has("p")) {
    o.p = f.num_in("p", 2, 64, "");
    if (o.objective != "pnorm") f.fail("p", "an exponent needs objective: pnorm");
  }
  s.optimize = o;
}

// initial: read before the mechanism, because the generator places the mechanism at q0.
void read_initial(const Fields& top, const Context& ctx, Scene& s) {
  if (!top.has("initial")) return;
  Fields f(top.raw("initial"), "initial", ctx, {"q", "q_deg", "qdot", "cadence_Hz"});
  s.key_lines["initial"] = f.line();
  if (f.has("q") && f.has("q_deg")) f.fail("q", "give q or q_deg, not both");
  if (f.has("qdot") && f.has("cadence_Hz")) f.fail("qdot", "give qdot or cadence_Hz, not both");
  // Ranges in SI are check_scene's; the converted units are checked here, where the
  // message can quote them (the generator places the mechanism at q before that).
  s.initial.q = f.has("q_deg") ? f.num_abs_max("q_deg", 0.0, limits::kMaxAngle_rad * 180.0 / kPi,
                                               "degrees") *
                                     kPi / 180.0
                               : f.num_abs_max("q", 0.0, limits::kMaxAngle_rad, "rad or m");
  s.initial.qdot =
      f.has("cadence_Hz")
          ? f.num_abs_max("cadence_Hz", 0.0, limits::kMaxRate / (2.0 * kPi), "Hz") * 2.0 * kPi
          : f.num_or("qdot", 0.0);
}

// The mechanism: generated from bicycle_leg, or the scene's own bodies, joints, loops and gears.
void read_mechanism_or_leg(const Fields& top, const Context& ctx, Scene& s) {
  if (top.has("bicycle_leg")) {
    for (const char* k : {"bodies", "joints", "loops", "gears", "independent", "ground_points"})
      if (top.has(k))
        top.fail(k, "a bicycle_leg scene generates its own mechanism; remove this key");
    Fields f(top.raw("bicycle_leg"), "bicycle_leg", ctx,
             {"subject", "legs", "crank_length_m", "crank_mass_kg", "seat_tube_angle_deg",
              "knee_flexion_at_extension_deg", "ankle_angle_deg", "pedal_stack_m", "hip_torque_Nm",
              "flywheel", "resistance"});
    read_bicycle_leg(f, s);
  } else {
    read_mechanism(top, s);
  }
}

// A resistance given by `dissipates` (power at a cadence) becomes a coefficient once the
// mechanism and its gears are known: P = c·ωⁿ at the body's speed.
void resolve_dissipations(const Context& ctx, const std::vector<PendingDissipation>& pending,
                          Scene& s) {
  for (const auto& p : pending) {
    Resistance& r = s.resistances[p.index];
    if (!s.find_body(r.body))
      throw SceneError(ctx.file, p.line, "loads." + r.name + ".body",
                       "unknown body '" + r.body + "'");
    const auto ratio = fixed_speed_ratio(s, r.body);
    if (!ratio)
      throw SceneError(ctx.file, p.line, "loads." + r.name + ".dissipates",
                       "'dissipates' needs a body turning at a fixed ratio to the independent "
                       "coordinate (its child, or geared to it); give a coefficient instead");
    const double omega = std::abs(*ratio) * 2.0 * kPi * p.cadence_Hz;
    r.coefficient = p.power_W / std::pow(omega, dissipation_exponent(r.law));  // P = c·ωⁿ
  }
}

void read_gravity(const Fields& top, const Context& ctx, Scene& s) {
  if (!top.has("gravity")) return;
  Fields f(top.raw("gravity"), "gravity", ctx, {"enabled", "g_m_s2"});
  s.gravity.enabled = f.flag_or("enabled", true);
  if (f.has("g_m_s2")) s.gravity.g_m_s2 = f.vec2("g_m_s2");
}

// outputs.constraint_forces: name, joint and a direction (a vector, or a named point of the
// joint's child), stored as a unit vector.
void read_constraint_force_requests(const Fields& f, const Context& ctx, Scene& s) {
  for_each_item(f, "constraint_forces", [&](const YAML::Node& n, const std::string& path) {
    Fields c(n, path, ctx, {"name", "joint", "direction"});
    ConstraintForceRequest r{c.name("name"), c.str("joint"), {}};
    const Joint* j = s.find_joint(r.joint);
    if (!j) c.fail("joint", "unknown joint '" + r.joint + "'");
    const YAML::Node d = c.required("direction");
    if (d.IsScalar()) {  // toward a named point of the child, from the joint
      const Vec2 to = read_point(c, "direction", j->child, s);
      r.direction = {to.x - j->child_point.x, to.y - j->child_point.y};
    } else {
      r.direction = c.vec2("direction");
    }
    const double len = std::hypot(r.direction.x, r.direction.y);
    if (len < 1e-12) c.fail("direction", "must be a non-zero vector");
    r.direction = unit_vector(r.direction, len);
    for (const auto& other : s.outputs.constraint_forces)
      if (other.name == r.name) c.fail("name", "duplicate constraint force name");
    s.outputs.constraint_forces.push_back(r);
  });
}

void read_output_bodies(const Fields& f, Scene& s) {
  if (!f.has("bodies")) return;
  const YAML::Node b = f.raw("bodies");
  if (!b.IsSequence()) f.fail("bodies", "expected a list of body names");
  for (size_t i = 0; i < b.size(); ++i) {
    // A body name, not a mapping or a list (yaml-cpp would only say "bad conversion").
    if (!b[i].IsScalar()) f.fail_at(b[i], fmt::format("outputs.bodies[{}]", i), "expected a body name");
    s.outputs.bodies.push_back(b[i].as<std::string>());
  }
}

// `all` or a list of names; each name known (joints; for reactions, joints or loops).
std::vector<std::string> read_names_or_all(const Fields& f, const Scene& s, const std::string& key,
                                           bool loops_too) {
  std::vector<std::string> out;
  const YAML::Node n = f.raw(key);
  const std::string what = loops_too ? "joint or loop" : "joint";
  if (n.IsScalar() && n.Scalar() == "all") {
    for (const auto& j : s.joints) out.push_back(j.name);
    if (loops_too)
      for (const auto& l : s.loops) out.push_back(l.name);
  } else if (n.IsSequence()) {
    for (const auto& item : n) {
      const std::string name = item.IsScalar() ? item.Scalar() : "";
      const bool loop = loops_too && std::any_of(s.loops.begin(), s.loops.end(),
                                                 [&](const Loop& l) { return l.name == name; });
      if (!s.find_joint(name) && !loop)
        f.fail_at(item, f.join(key), "unknown " + what + " '" + name.substr(0, 64) + "'");
      if (std::find(out.begin(), out.end(), name) != out.end())
        f.fail_at(item, f.join(key), "'" + name + "' is listed twice");
      out.push_back(name);
    }
  } else {
    f.fail(key, "expected all or a list of " + what + " names");
  }
  for (const auto& name : out)  // R_<name> must say which one it is
    if (loops_too && s.find_joint(name) &&
        std::any_of(s.loops.begin(), s.loops.end(), [&](const Loop& l) { return l.name == name; }))
      f.fail(key, "'" + name + "' names both a joint and a loop: rename one");
  return out;
}

void read_outputs(const Fields& top, const Context& ctx, Scene& s) {
  if (!top.has("outputs")) return;
  Fields f(top.raw("outputs"), "outputs", ctx, {"constraint_forces", "bodies", "joints", "reactions", "shaking"});
  read_constraint_force_requests(f, ctx, s);
  read_output_bodies(f, s);
  if (f.has("joints")) s.outputs.joints = read_names_or_all(f, s, "joints", false);
  if (f.has("reactions")) {
    s.outputs.reactions = read_names_or_all(f, s, "reactions", true);
    const YAML::Node r = f.raw("reactions");
    s.outputs.reactions_all = r.IsScalar() && r.Scalar() == "all";
    note_key(s, f.ctx(), "outputs.reactions", f.raw("reactions"));
  }
  s.outputs.shaking = f.flag_or("shaking", false);
}

void read_simulation(const Fields& top, const Context& ctx, Scene& s) {
  if (!top.has("simulation")) return;
  Fields f(top.raw("simulation"), "simulation", ctx,
           {"duration_s", "output_interval_s", "tolerance"});
  s.simulation.duration_s = f.num_or("duration_s", s.simulation.duration_s);
  s.simulation.output_interval_s = f.num_or("output_interval_s", s.simulation.output_interval_s);
  s.simulation.tolerance = f.num_or("tolerance", s.simulation.tolerance);
}

// validation.calibrate: the operating point (cadence, and power or mean-speed mode) and the load
// calibrated to reach it.
void read_calibrate(const Fields& f, const Context& ctx, Scene& s) {
  if (!f.has("calibrate")) return;
  Fields c(f.raw("calibrate"), "validation.calibrate", ctx, {"cadence_Hz", "power_W", "load"});
  s.validation.calibrate_cadence_Hz = c.num("cadence_Hz");
  // power_W absent: mean-speed mode (the resistances stay as given).
  s.validation.calibrate_power_W = c.num_or("power_W", 0.0);
  s.validation.calibrate_load = c.str_or("load", "");  // checked against the loads by calibrate
  if (c.has("load")) note_key(s, ctx, "validation.calibrate.load", c.raw("load"));
  if (c.has("load") && s.validation.calibrate_load.empty())
    c.fail("load", "an empty name names no load: give a joint_torque or motor, or leave the key out");
  // A present block with zeros would silently mean "off": refuse (ranges: check_scene).
  if (!(s.validation.calibrate_cadence_Hz > 0)) c.fail("cadence_Hz", "must be positive");
  if (c.has("power_W") && !(s.validation.calibrate_power_W > 0)) c.fail("power_W", "must be positive");
}

// Published values the report sets beside the calibration's (e.g. the original authors'
// hip torque): plain text, HTML-escaped by the report.
void read_compare(const Fields& f, const Context& ctx, Scene& s) {
  for_each_item(f, "compare", [&](const YAML::Node& n, const std::string& path) {
    Fields c(n, path, ctx, {"quantity", "value", "unit", "source", "explanation"});
    CompareValue cv{c.str("quantity"), c.num("value"), c.str_or("unit", ""), c.str_or("source", ""),
                    c.str_or("explanation", "")};
    if (std::find(kCompareQuantities.begin(), kCompareQuantities.end(), cv.quantity) ==
        kCompareQuantities.end())
      c.fail("quantity", "expected drive_torque_Nm, peak_force_N, speed_fluctuation or mean_power_W");
    if (!std::isfinite(cv.value)) c.fail("value", "must be a finite number");
    if (!f.has("calibrate"))
      c.fail("quantity", "compared values are calibration results: add validation.calibrate");
    s.validation.compare.push_back(cv);
  });
}

void read_validation(const Fields& top, const Context& ctx, Scene& s) {
  if (!top.has("validation")) return;
  Fields f(top.raw("validation"), "validation", ctx,
           {"duration_s", "thresholds", "calibrate", "note", "reference_tolerance",
            "reference_integrator", "compare"});
  s.validation.duration_s = f.num_or("duration_s", 0.0);
  s.validation.reference_tolerance = f.num_or("reference_tolerance", 1e-10);
  s.validation.reference_integrator = f.str_or("reference_integrator", "rkmerson");
  const auto& ri = s.validation.reference_integrator;
  if (ri != "rkmerson" && ri != "rk3" && ri != "cpodes")
    f.fail("reference_integrator", "expected rkmerson, rk3 or cpodes");
  s.validation.note = f.str_or("note", "");
  for_each_item(f, "thresholds", [&](const YAML::Node& n, const std::string& path) {
    Fields t(n, path, ctx, {"quantity", "grid_deg", "interpolation", "max_error"});
    Threshold th{t.str("quantity"), t.num_or("grid_deg", 10.0), t.str_or("interpolation", ""),
                 t.num("max_error")};
    // quantity, grid_deg, max_error: check_scene.
    s.validation.thresholds.push_back(th);
  });
  read_calibrate(f, ctx, s);
  read_compare(f, ctx, s);
}

// Reads the YAML tree into `s` (names and shapes checked here, values by check_scene), section
// by section in the order the sections depend on each other: the first error found is reported.
void read_scene(const YAML::Node& root, const Context& ctx, Scene& s) {
  Fields top(
      root, "", ctx,
      {"name", "description", "bicycle_leg", "ground_points", "bodies", "joints", "loops", "gears",
       "independent", "independent_range", "independent_range_deg", "loads", "gravity", "outputs", "initial",
       "simulation", "validation", "optimize"});
  s.name = top.name("name");
  s.description = top.str_or("description", "");
  read_initial(top, ctx, s);
  read_mechanism_or_leg(top, ctx, s);
  read_independent_range(top, s);
  for (const char* k : {"independent_range", "independent_range_deg"})
    if (top.has(k)) note_key(s, ctx, k, top.raw(k));
  std::vector<PendingDissipation> pending;
  read_loads(top, s, pending);
  resolve_dissipations(ctx, pending, s);
  read_gravity(top, ctx, s);
  read_outputs(top, ctx, s);
  read_simulation(top, ctx, s);
  read_validation(top, ctx, s);
  if (top.has("optimize")) read_optimize(Fields(top.raw("optimize"), "optimize", ctx,
                                                {"loads", "of", "force", "harmonics", "max_load", "nonnegative",
                                                 "objective", "p"}),
                                         s);
}

}  // namespace

Override parse_override(const std::string& text) {
  const auto eq = text.find('=');
  const std::string shown = text.substr(0, 80) + (text.size() > 80 ? "…" : "");
  if (eq == std::string::npos)
    throw SceneError("", 0, "--set " + shown, "expected key.path=value (no '=')");
  if (eq == 0) throw SceneError("", 0, "--set " + shown, "expected key.path=value (empty key)");
  Override o{text.substr(0, eq), text.substr(eq + 1)};
  if (o.path.size() > kMaxOverrideKeyLength)
    throw SceneError("", 0, "--set " + shown,
                     fmt::format("key path longer than {} characters", kMaxOverrideKeyLength));
  if (o.value.size() > limits::kMaxTextLength)
    throw SceneError("", 0, "--set " + shown,
                     fmt::format("value longer than {} characters", limits::kMaxTextLength));
  const auto parts = split_key_path(o.path);
  if (std::any_of(parts.begin(), parts.end(), [](const std::string& p) { return p.empty(); }))
    throw SceneError("", 0, "--set " + shown, "malformed key path (an empty part between dots)");
  return o;
}

namespace {
// The shipped scenes of an installed rdyn: <exe dir>/RDYN_INSTALLED_SCENES_REL (CMake computes
// it from the install layout, ../share/rdyn/scenes), so an install prefix can be moved.
// Empty when the executable's path is unknown. A build-tree executable has no such folder.
std::string installed_scenes_dir() {
  char exe[4096];
  const ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
  if (n <= 0) return "";
  const std::string path(exe, static_cast<size_t>(n));
  const auto slash = path.rfind('/');
  if (slash == std::string::npos) return "";
  return path.substr(0, slash + 1) + RDYN_INSTALLED_SCENES_REL;
}
}  // namespace

std::string resolve_scene_path(const std::string& name_or_path) {
  struct stat st {};
  if (stat(name_or_path.c_str(), &st) == 0) {
    if (S_ISDIR(st.st_mode)) throw SceneError(name_or_path, 0, "", "is a folder, not a scene file");
    return name_or_path;
  }
  const bool plain_name = name_or_path.find('/') == std::string::npos &&
                          name_or_path.find('.') == std::string::npos && !name_or_path.empty();
  if (plain_name) {
    std::vector<std::string> dirs;
    if (const char* env = std::getenv("RDYN_SCENES_DIR")) dirs.push_back(env);
    if (std::string installed = installed_scenes_dir(); !installed.empty()) dirs.push_back(installed);
    dirs.push_back(RDYN_SCENES_DIR);  // the source folder (build tree)
    for (const auto& d : dirs) {
      const std::string p = d + "/" + name_or_path + ".yaml";
      if (stat(p.c_str(), &st) == 0) return p;
    }
  }
  throw SceneError(name_or_path, 0, "", "no such scene file (nor a shipped scene of that name)");
}

Scene parse_scene(const std::string& text, const std::string& file,
                  const std::vector<Override>& overrides) {
  YAML::Node root = load_checked_yaml(text, file);
  Context ctx{file, {}};
  for (const auto& o : overrides) apply_override(root, o, file, &ctx.set_by_override);
  // The overrides may have added nodes: check the tree they left (duplicates cannot arise,
  // but depth and size can grow with created mappings).
  if (!overrides.empty()) check_yaml_tree(root, file);

  Scene s;
  s.source_file = file;
  try {
    read_scene(root, ctx, s);
    check_scene(s);
  } catch (const YAML::Exception& e) {
    throw SceneError(file, e.mark.is_null() ? 0 : e.mark.line + 1, "", e.msg);
  } catch (const SceneError& e) {
    // check_scene and the generator know the field, not the line: find it in the tree.
    if (e.line() > 0 || e.field().empty() || e.field().rfind("--set", 0) == 0) throw;
    const YAML::Node n = locate_field(root, e.field());
    ctx.fail(n, e.field(), e.message());
  }
  return s;
}

std::string non_regular_file_kind(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0 || S_ISREG(st.st_mode)) return "";
  if (S_ISFIFO(st.st_mode)) return "a FIFO";
  if (S_ISDIR(st.st_mode)) return "a folder";
  if (S_ISCHR(st.st_mode)) return "a character device";
  if (S_ISBLK(st.st_mode)) return "a block device";
  if (S_ISSOCK(st.st_mode)) return "a socket";
  return "not a file";
}

std::string read_scene_text(const std::string& name_or_path) {
  const std::string path = resolve_scene_path(name_or_path);
  if (const std::string kind = non_regular_file_kind(path); !kind.empty())
    throw SceneError(path, 0, "", "not a regular file (" + kind + "): give a scene file (a FIFO would block, a "
                                  "device never ends)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SceneError(path, 0, "", "cannot open for reading");
  // Read at most one byte more than a scene may have: /dev/zero or a huge file cannot
  // exhaust memory (parse_scene refuses the oversized text with its size limit).
  std::string text(kMaxSceneBytes + 1, '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<size_t>(std::max<std::streamsize>(0, in.gcount())));
  return text;
}

Scene load_scene(const std::string& name_or_path, const std::vector<Override>& overrides) {
  return parse_scene(read_scene_text(name_or_path), resolve_scene_path(name_or_path), overrides);
}

namespace {
// Node at a dotted path (map keys; list items by index or name), or an invalid node.
bool find_path(YAML::Node root, const std::string& path, YAML::Node& parent, std::string& last) {
  std::vector<std::string> parts;
  std::stringstream ss(path);
  for (std::string p; std::getline(ss, p, '.');) parts.push_back(p);
  if (parts.empty()) return false;
  YAML::Node cur;
  cur.reset(root);
  for (size_t i = 0; i + 1 < parts.size(); ++i) {
    YAML::Node next;
    bool found = false;
    if (cur.IsMap() && cur[parts[i]]) {
      next.reset(cur[parts[i]]);
      found = true;
    } else if (cur.IsSequence()) {
      for (size_t k = 0; k < cur.size() && !found; ++k)
        if (cur[k].IsMap() && cur[k]["name"] && cur[k]["name"].Scalar() == parts[i])
          next.reset(cur[k]), found = true;
    }
    if (!found) return false;
    cur.reset(next);
  }
  parent.reset(cur);
  last = parts.back();
  return cur.IsMap() && static_cast<bool>(cur[last]);
}
}  // namespace

bool scene_yaml_has(const std::string& text, const std::string& path) {
  try {
    YAML::Node root = load_checked_yaml(text, ""), parent;
    std::string last;
    return find_path(root, path, parent, last);
  } catch (const YAML::Exception&) {
    return false;
  } catch (const SceneError&) {
    return false;
  }
}

std::string rewrite_scene_yaml(const std::string& text, const std::string& file,
                               const std::vector<Override>& overrides,
                               const std::vector<std::string>& remove) {
  YAML::Node root = load_checked_yaml(text, file);
  for (const auto& path : remove) {
    YAML::Node parent;
    std::string last;
    if (find_path(root, path, parent, last)) parent.remove(last);
  }
  for (const auto& o : overrides) apply_override(root, o, file);
  YAML::Emitter out;
  out << root;
  return std::string(out.c_str()) + "\n";
}

}  // namespace rdyn::models
